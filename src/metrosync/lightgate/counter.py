"""The logger's counter → ticks since the first record: wraps and restarts.

Contract: `check_bits` validates a counter width argument; `unwrap` undoes the
overflows of one stretch of counter values; `unwrap_segments` joins stretches
separated by restarts of the logger, each placed after the wall-clock gap marked
before it. Errors are `TimestampError`s naming the file and line.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, TimestampError

#: Counter widths accepted, bits.
COUNTER_BITS_RANGE = (8, 62)


def check_bits(counter_bits) -> int | str | None:
    if counter_bits is None or counter_bits == "auto":
        return counter_bits
    lo, hi = COUNTER_BITS_RANGE
    if (
        isinstance(counter_bits, bool)
        or not isinstance(counter_bits, int | np.integer)
        or not (lo <= counter_bits <= hi)
    ):
        raise ParameterError(
            f"`counter_bits` must be 'auto', None or an integer in [{lo}, {hi}], "
            f"got {counter_bits!r}."
        )
    return int(counter_bits)


def unwrap(raw: list[int], numbers: np.ndarray, bits, source) -> tuple[np.ndarray, int | None, int]:
    """Ticks since the first record, undoing counter overflows."""
    top = max(raw)
    if top >= 1 << COUNTER_BITS_RANGE[1]:
        line = int(numbers[raw.index(top)])
        raise TimestampError(f"{source}: line {line}: timestamp {top} is out of range.")
    v = np.array(raw, dtype=np.int64)
    back = np.flatnonzero(np.diff(v) < 0) + 1
    if isinstance(bits, int) and top >= 1 << bits:
        line = int(numbers[raw.index(top)])
        raise TimestampError(
            f"{source}: line {line}: timestamp {top} does not fit the {bits}-bit counter "
            f"(`counter_bits` = {bits}); give the logger's real width or 'auto'."
        )
    if back.size == 0:
        return v - v[0], (bits if isinstance(bits, int) else None), 0
    if bits is None:
        i = int(back[0])
        raise TimestampError(
            f"{source}: line {int(numbers[i])}: time goes back from {raw[i - 1]} to {raw[i]} "
            f"ticks, but `counter_bits` is None (a counter that never wraps). Give the "
            f"counter width, or 'auto'."
        )
    width = bits if isinstance(bits, int) else max(top.bit_length(), COUNTER_BITS_RANGE[0])
    modulus = 1 << width
    drops = v[back - 1] - v[back]
    bad = drops <= modulus // 2
    if np.any(bad):
        i = int(back[np.argmax(bad)])
        raise TimestampError(
            f"{source}: line {int(numbers[i])}: time goes back from {raw[i - 1]} to {raw[i]} "
            f"ticks, which is no wrap of a {width}-bit counter (a wrap jumps back by about "
            f"{modulus}). The log is out of order or corrupted there."
        )
    steps = np.zeros(v.size, dtype=np.int64)
    steps[back] = modulus
    return v - v[0] + np.cumsum(steps), width, int(back.size)


def unwrap_segments(raw, numbers, bits, source, starts, gaps, tick):
    """Ticks since the first record across restarts of the logger.

    Each stretch between restarts is unwrapped on its own; the first record after a
    restart comes the marked gap (s) after the last record before it.
    """
    if not starts:
        return unwrap(raw, numbers, bits, source)
    out, widths, wraps, offset = [], [], 0, 0
    for lo, hi, gap in zip([0, *starts], [*starts, len(raw)], [0.0, *gaps], strict=True):
        if math.isnan(gap):
            raise TimestampError(
                f"{source}: line {int(numbers[lo])}: the logger restarted (a new header before "
                f"this line), and the capture does not say how long it was away. Split the "
                f"capture there, or record with `metrosync record --reconnect`, which marks "
                f"the gap."
            )
        ticks, width, n = unwrap(raw[lo:hi], numbers[lo:hi], bits, source)
        if lo:
            offset = out[-1][-1] + round(gap / tick)
        out.append(ticks + offset)
        widths.append(width)
        wraps += n
    known = [w for w in widths if w is not None]
    return np.concatenate(out), (max(known) if known else None), wraps

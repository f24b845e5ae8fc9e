"""Reading the light-gate logger's captures (paper §2).

Contract: `read_log` turns one capture into a `GateLog`: the gate states of every
record, their times in seconds from the first record, which level of each gate
means "interrupted", and an account of every line that was not a record.

The format is one line per change of any gate, ``b1-b2-…-bk T``: k ≤ 8 gate levels
(0/1) and the logger's counter T in ticks (64 µs by default). Captures made through
a terminal program are messy, so the reader

* accepts CRLF, CR or LF line ends, blank lines, terminal banners and other text,
  and partial records at the very start or end of the capture (a capture cut in
  the middle of a line). Each such line is *skipped and counted* with its 1-based
  line number and a reason; ``strict=True`` turns the first one into an error;
* unwraps a counter that overflows (time jumping back by about one counter period),
  with the counter width given or detected as the fewest bits that hold every
  value seen;
* detects each gate's polarity instead of assuming it: a beam is interrupted for a
  short moment per pass, so the interrupted level is the one whose spells are
  shorter (median spell length).

It refuses, with a `LogFormatError` subclass, an empty capture (`EmptyLogError`), a
number of gates that changes mid-file (`ChannelCountError`) and timestamps that no
wrap explains (`TimestampError`). Every line is accounted for:
``n_lines == records + len(skipped)``.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import (
    ChannelCountError,
    EmptyLogError,
    ParameterError,
    StrictModeError,
    TimestampError,
)

#: The logger follows at most this many gates.
MAX_GATES = 8
#: The logger's clock tick, s (paper §2).
DEFAULT_TICK = 64e-6
#: Counter widths accepted, bits.
COUNTER_BITS_RANGE = (8, 62)

_RECORD = re.compile(r"^[ \t]*([01](?:-[01])*)[ \t]+(\d{1,19})[ \t]*$")
_LINE_END = re.compile(r"\r\n|\r|\n")


@dataclass(frozen=True)
class SkippedLine:
    """A line that is not a gate record: 1-based ``line_number``, ``reason``, ``text``."""

    line_number: int
    reason: str
    text: str

    def __str__(self) -> str:
        return f"line {self.line_number}: {self.reason}: {self.text!r}"


@dataclass(frozen=True)
class GateLog:
    """One capture, parsed.

    levels : (R, K) uint8, the raw gate levels of each record.
    ticks : (R,) int64, counter ticks since the first record (unwrapped).
    line_numbers : (R,) int64, 1-based line of each record.
    interrupted_level : (K,) int8, the level that means "beam interrupted";
        -1 for a gate that never changes (its polarity cannot be told).
    tick : seconds per tick.
    counter_bits : counter width used to unwrap, or None when nothing wrapped.
    wraps : how many times the counter wrapped.
    skipped : every line that is not a record.
    n_lines : lines in the capture (a final line end does not start a new line).
    source : file name or ``"<text>"``.
    """

    levels: np.ndarray
    ticks: np.ndarray
    line_numbers: np.ndarray
    interrupted_level: np.ndarray
    tick: float
    counter_bits: int | None
    wraps: int
    skipped: tuple[SkippedLine, ...]
    n_lines: int
    source: str = "<text>"

    @property
    def times(self) -> np.ndarray:
        """(R,) seconds since the first record."""
        return self.ticks * self.tick

    @property
    def channels(self) -> int:
        """Number of gates K per record."""
        return self.levels.shape[1]

    @property
    def interrupted(self) -> np.ndarray:
        """(R, K) bool, True while a gate's beam is interrupted."""
        return self.levels == self.interrupted_level[None, :]

    def report(self) -> str:
        """Human-readable account of the reading: records, wraps, polarity, skipped lines."""
        bits = "no wrap" if self.counter_bits is None else f"{self.counter_bits}-bit counter"
        polarity = " ".join("?" if p < 0 else str(int(p)) for p in self.interrupted_level)
        lines = [
            f"{self.source}: {len(self.ticks)} records of {self.channels} gates in "
            f"{self.n_lines} lines, {self.times[-1]:.3f} s, {bits}, {self.wraps} wraps, "
            f"interrupted level per gate: {polarity}",
            f"  skipped {len(self.skipped)} lines",
        ]
        reasons = Counter(s.reason for s in self.skipped)
        for reason, count in sorted(reasons.items()):
            numbers = [s.line_number for s in self.skipped if s.reason == reason]
            shown = ", ".join(map(str, numbers[:12])) + (", ..." if len(numbers) > 12 else "")
            lines.append(f"    {count} x {reason} (lines {shown})")
        return "\n".join(lines)


def read_log(
    source: str | Path,
    *,
    tick: float = DEFAULT_TICK,
    counter_bits: int | str | None = "auto",
    polarity: int | str = "auto",
    strict: bool = False,
) -> GateLog:
    """Read a light-gate capture from a file.

    Parameters
    ----------
    source : path of the capture.
    tick : seconds per counter tick (64 µs for the paper's logger).
    counter_bits : width of the logger's counter in bits, ``"auto"`` to detect it
        from the largest value seen, or None for a counter that never wraps.
    polarity : ``"auto"`` to detect each gate's interrupted level, or 0/1 to force it.
    strict : raise `StrictModeError` at the first line that is not a record.

    Returns
    -------
    GateLog
    """
    path = Path(source)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ParameterError(
            f"cannot read light-gate log {str(path)!r}: {error.strerror}."
        ) from None
    # Serial captures can hold any byte; decoding never fails, bad bytes stay visible.
    text = data.decode("utf-8", errors="replace")
    return parse_log(text, tick=tick, counter_bits=counter_bits, polarity=polarity,
                     strict=strict, source=str(path))  # fmt: skip


def parse_log(
    text: str,
    *,
    tick: float = DEFAULT_TICK,
    counter_bits: int | str | None = "auto",
    polarity: int | str = "auto",
    strict: bool = False,
    source: str = "<text>",
) -> GateLog:
    """Parse the text of a capture; see `read_log` for the parameters."""
    if not (isinstance(tick, int | float) and math.isfinite(tick) and tick > 0):
        raise ParameterError(f"`tick` must be a time > 0 s, got {tick!r}.")
    bits = _check_bits(counter_bits)
    if polarity not in ("auto", 0, 1):
        raise ParameterError(f"`polarity` must be 'auto', 0 or 1, got {polarity!r}.")
    lines = _LINE_END.split(text)
    terminated = True
    if lines and lines[-1] == "":
        lines.pop()  # the final line end does not open a new line
    elif lines:
        terminated = False
    if not lines:
        raise EmptyLogError(f"{source}: the light-gate log is empty (no lines).")

    skipped: list[SkippedLine] = []
    records: list[tuple[int, str, int]] = []  # (line number, levels, ticks)
    for number, line in enumerate(lines, start=1):
        match = _RECORD.match(line)
        if match is None:
            reason = "blank line" if not line.strip() else _why_not_record(line)
            _skip(skipped, number, reason, line, strict, source)
            continue
        gates = match.group(1).replace("-", "")
        if len(gates) > MAX_GATES:
            _skip(skipped, number, f"more than {MAX_GATES} gates", line, strict, source)
            continue
        records.append((number, gates, int(match.group(2))))
    if not records:
        raise EmptyLogError(
            f"{source}: no gate record in {len(lines)} lines (a record looks like "
            f"'0-1-0-0 1450'); {len(skipped)} lines skipped."
        )
    records = _drop_partial_ends(records, skipped, lines, strict, source)
    records = _drop_partial_last_tick(records, skipped, lines, terminated, strict, source)

    numbers = np.array([r[0] for r in records], dtype=np.int64)
    levels = np.array([[int(c) for c in r[1]] for r in records], dtype=np.uint8)
    raw = [r[2] for r in records]
    ticks, used_bits, wraps = _unwrap(raw, numbers, bits, source)
    level = _polarity(levels, ticks) if polarity == "auto" else np.full(levels.shape[1], polarity)
    return GateLog(
        levels=levels,
        ticks=ticks,
        line_numbers=numbers,
        interrupted_level=level.astype(np.int8),
        tick=float(tick),
        counter_bits=used_bits,
        wraps=wraps,
        skipped=tuple(sorted(skipped, key=lambda s: s.line_number)),
        n_lines=len(lines),
        source=source,
    )


def _check_bits(counter_bits) -> int | str | None:
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


def _why_not_record(line: str) -> str:
    stripped = line.strip()
    if re.fullmatch(r"[01](?:-[01])*-?", stripped) or re.fullmatch(r"[01](?:-[01])*[ \t]+", line):
        return "partial record (no timestamp)"
    if re.match(r"^[01](?:-[01])*[ \t]+\d", stripped):
        return "malformed record"
    return "not a gate record"


def _skip(skipped, number, reason, line, strict, source) -> None:
    entry = SkippedLine(number, reason, line[:80])
    if strict:
        raise StrictModeError(
            f"{source}: line {number}: {reason}: {line[:80]!r} (strict reading; "
            f"read without strict to skip and count such lines)."
        )
    skipped.append(entry)


def _drop_partial_ends(records, skipped, lines, strict, source):
    """Keep the records of the usual gate count; odd counts may only be cut-off ends."""
    counts = Counter(len(r[1]) for r in records)
    k = counts.most_common(1)[0][0]
    out = list(records)
    # A capture may start or stop in the middle of a line: a record with too few
    # gates at either end is a fragment, not a change of wiring.
    for end in (0, -1):
        if out and len(out[end][1]) != k:
            number = out[end][0]
            reason = f"partial record ({len(out[end][1])} gates, expected {k})"
            _skip(skipped, number, reason, lines[number - 1], strict, source)
            out.pop(end)
    for number, gates, _ in out:
        if len(gates) != k:
            raise ChannelCountError(
                f"{source}: line {number}: {len(gates)} gates, but the log has {k} gates per "
                f"record elsewhere; the gate count must not change within a log. Split the "
                f"capture where the wiring changed."
            )
    if not out:
        raise EmptyLogError(f"{source}: no complete gate record (only fragments).")
    return out


def _drop_partial_last_tick(records, skipped, lines, terminated, strict, source):
    """An unterminated last line whose time runs backwards is a cut-off timestamp.

    A cut timestamp can look like a counter wrap; a wrap that falls exactly on a cut
    final line is the rarer event, and losing that one record costs nothing.
    """
    if terminated or len(records) < 2 or records[-1][0] != len(lines):
        return records
    if records[-1][2] >= records[-2][2]:
        return records
    number = records[-1][0]
    _skip(skipped, number, "partial record (cut-off timestamp)", lines[number - 1], strict, source)
    return records[:-1]


def _unwrap(
    raw: list[int], numbers: np.ndarray, bits, source
) -> tuple[np.ndarray, int | None, int]:
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


def _polarity(levels: np.ndarray, ticks: np.ndarray) -> np.ndarray:
    """Per gate, the level whose complete spells are shorter (median), or -1."""
    out = np.full(levels.shape[1], -1, dtype=np.int8)
    for k in range(levels.shape[1]):
        col = levels[:, k].astype(np.int8)
        change = np.flatnonzero(np.diff(col) != 0) + 1
        if change.size == 0:
            continue
        if change.size == 1:
            # One change only: the level held at the end is held longest, by assumption.
            out[k] = col[0] if ticks[change[0]] < ticks[-1] - ticks[change[0]] else col[-1]
            continue
        lengths = np.diff(ticks[change])
        spell_levels = col[change[:-1]]
        med = []
        for value in (0, 1):
            sel = lengths[spell_levels == value]
            med.append(np.median(sel) if sel.size else np.inf)
        if med[0] == med[1]:
            # Tie (e.g. one spell each): fall back on total time held.
            total = [np.sum(lengths[spell_levels == value]) for value in (0, 1)]
            out[k] = int(np.argmin(total))
        else:
            out[k] = int(np.argmin(med))
    return out

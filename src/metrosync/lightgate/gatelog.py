"""A parsed capture: `GateLog`, and `SkippedLine` for each line that is not a record.

Contract: frozen records of what `reader` found; `GateLog.report` is the account of
the reading that `analyze` prints.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from .._words import plural
from .messages import LoggerHeader


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
    header : the logger's start-up line (the first one), or None.
    records_lost : records the logger reported lost (its buffer overflowed); each would
        have shown a change of one or more gates.
    restarts : line of the first record after each restart of the logger.
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
    header: LoggerHeader | None = None
    records_lost: int = 0
    restarts: tuple[int, ...] = ()

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
            f"{self.source}: {plural(len(self.ticks), 'record')} of "
            f"{plural(self.channels, 'gate')} in {plural(self.n_lines, 'line')}, "
            f"{self.times[-1]:.3f} s, {bits}, {plural(self.wraps, 'wrap')}, "
            f"interrupted level per gate: {polarity}",
        ]
        if self.header is not None:
            h = self.header
            lines.append(f"  logger: gate-logger {h.version}, {plural(h.channels, 'gate')}, "
                         f"{h.tick * 1e6:g} us tick, {h.counter_bits}-bit counter")  # fmt: skip
        if self.records_lost:
            lost = plural(self.records_lost, "record")
            lines.append(f"  LOST {lost}: the logger's buffer overflowed")
        if self.restarts:
            shown = ", ".join(map(str, self.restarts))
            lines.append(
                f"  the logger restarted {plural(len(self.restarts), 'time')} (records resume "
                f"at lines {shown}); the time across each gap is the recording computer's clock"
            )
        lines.append(f"  skipped {plural(len(self.skipped), 'line')}")
        reasons = Counter(s.reason for s in self.skipped)
        for reason, count in sorted(reasons.items()):
            numbers = [s.line_number for s in self.skipped if s.reason == reason]
            shown = ", ".join(map(str, numbers[:12])) + (", ..." if len(numbers) > 12 else "")
            lines.append(f"    {count} x {reason} (lines {shown})")
        return "\n".join(lines)

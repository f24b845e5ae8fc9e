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

* reads the lines the gate-logger firmware and `metrosync record` add (`messages`):
  the logger's start-up header (its tick must agree with ``tick``, and its counter
  width is used when ``counter_bits="auto"``), its overflow lines (``records_lost``),
  and a restart of the logger (a header after the first record, where its counter
  began again; a header sent on request is not one): the records after it continue
  the time line after the wall-clock gap that `record` marked before it. These lines
  are listed in ``skipped`` too (with their reason), but ``strict`` does not refuse
  them.

It refuses, with a `LogFormatError` subclass, an empty capture (`EmptyLogError`), a
number of gates that changes mid-file or differs from the header's
(`ChannelCountError`), timestamps that no wrap explains and a restart with no marked
gap (`TimestampError`). Every line is accounted for: ``n_lines == records + len(skipped)``.

`split_lines`, `classify` and `assemble` are the steps of `parse_log`; `follow` reads
a growing capture with them, line by line, and gets the same `GateLog`.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._input_files import check_input_file
from .._words import plural
from ..errors import (
    ChannelCountError,
    EmptyLogError,
    ParameterError,
    StrictModeError,
)
from .counter import check_bits, unwrap_segments
from .gatelog import GateLog, SkippedLine
from .messages import Gap, LoggerHeader, Note, Overflow, parse_message

#: The logger follows at most this many gates.
MAX_GATES = 8
#: The logger's clock tick, s (paper §2).
DEFAULT_TICK = 64e-6

_RECORD = re.compile(r"^[ \t]*([01](?:-[01])*)[ \t]+(\d{1,19})[ \t]*$")
_LINE_END = re.compile(r"\r\n|\r|\n")


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
    path = check_input_file(source, "light-gate log", allow_empty=True)
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
    _check_reading(tick, counter_bits, polarity)
    lines, terminated = split_lines(text)
    if not lines:
        raise EmptyLogError(f"{source}: the light-gate log is empty (no lines).")
    return assemble([classify(line) for line in lines], terminated, tick=tick,
                    counter_bits=counter_bits, polarity=polarity, strict=strict,
                    source=source)  # fmt: skip


@dataclass(frozen=True, slots=True)
class Line:
    """One line of a capture, classified: a record (``gates``, ``value``) or not (``reason``)."""

    text: str
    gates: str | None = None
    value: int | None = None
    reason: str | None = None
    message: LoggerHeader | Overflow | Gap | Note | None = None


_REASONS = {LoggerHeader: "logger header", Overflow: "logger overflow", Gap: "recording gap",
            Note: "note of metrosync record"}  # fmt: skip


def split_lines(text: str) -> tuple[list[str], bool]:
    """The lines of a capture, and whether the last one ended with a line end."""
    lines = _LINE_END.split(text)
    if lines and lines[-1] == "":
        lines.pop()  # the final line end does not open a new line
        return lines, True
    return lines, not lines


def classify(line: str) -> Line:
    """What one line is: a gate record, a message of the logger or `record`, or other text."""
    match = _RECORD.match(line)
    if match is not None:
        gates = match.group(1).replace("-", "")
        if len(gates) > MAX_GATES:
            return Line(line, reason=f"more than {MAX_GATES} gates")
        return Line(line, gates=gates, value=int(match.group(2)))
    message = parse_message(line)
    if message is not None:
        return Line(line, reason=_REASONS[type(message)], message=message)
    return Line(line, reason="blank line" if not line.strip() else _why_not_record(line))


def assemble(
    lines: list[Line],
    terminated: bool,
    *,
    tick: float = DEFAULT_TICK,
    counter_bits: int | str | None = "auto",
    polarity: int | str = "auto",
    strict: bool = False,
    source: str = "<text>",
) -> GateLog:
    """The `GateLog` of classified lines (see `parse_log` for the options)."""
    bits = _check_reading(tick, counter_bits, polarity)
    if not lines:
        raise EmptyLogError(f"{source}: the light-gate log is empty (no lines).")
    texts = [line.text for line in lines]
    skipped: list[SkippedLine] = []
    # (line number, levels, ticks, gap before it: None, or seconds, NaN if unknown)
    records: list[tuple[int, str, int, float | None]] = []
    header, lost, restart, gap = None, 0, False, None
    for number, line in enumerate(lines, start=1):
        if line.gates is None:
            message = line.message
            _skip(skipped, number, line.reason, line.text, strict and message is None, source)
            if isinstance(message, LoggerHeader):
                header = header or message
                # A header after a record is a restart, unless `record` asked for it.
                restart = restart or (bool(records) and not message.requested)
            elif isinstance(message, Overflow):
                lost += message.count
            elif isinstance(message, Gap):
                gap = message.seconds
            continue
        before = (math.nan if gap is None else gap) if restart else None
        records.append((number, line.gates, line.value, before))
        restart, gap = False, None  # a gap without a restart: the counter went on
    if not records:
        raise EmptyLogError(
            f"{source}: no gate record in {plural(len(lines), 'line')} (a record looks like "
            f"'0-1-0-0 1450'); {plural(len(skipped), 'line')} skipped."
        )
    records = _drop_partial_ends(records, skipped, texts, strict, source)
    records = _drop_partial_last_tick(records, skipped, texts, terminated, strict, source)
    if header is not None:
        bits = _agree_with_header(header, records, tick, bits, source)

    numbers = np.array([r[0] for r in records], dtype=np.int64)
    k = len(records[0][1])
    levels = (np.frombuffer("".join(r[1] for r in records).encode("ascii"), dtype=np.uint8)
              - ord("0")).reshape(len(records), k)  # fmt: skip
    raw = [r[2] for r in records]
    starts = [i for i, r in enumerate(records) if r[3] is not None and i > 0]
    ticks, used_bits, wraps = unwrap_segments(raw, numbers, bits, source, starts,
                                               [records[i][3] for i in starts], tick)  # fmt: skip
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
        header=header,
        records_lost=lost,
        restarts=tuple(int(numbers[i]) for i in starts),
    )


def _check_reading(tick, counter_bits, polarity):
    if not (isinstance(tick, int | float) and math.isfinite(tick) and tick > 0):
        raise ParameterError(f"`tick` must be a time > 0 s, got {tick!r}.")
    bits = check_bits(counter_bits)
    if polarity not in ("auto", 0, 1):
        raise ParameterError(f"`polarity` must be 'auto', 0 or 1, got {polarity!r}.")
    return bits


def _agree_with_header(header: LoggerHeader, records, tick, bits, source):
    """The header's counter width when none is given; a conflict with it is an error."""
    if abs(header.tick - tick) > 1e-9 * tick:
        raise ParameterError(
            f"{source}: `tick` is {tick:g} s but the logger's header says {header.tick:g} s; "
            f"give tick={header.tick:g} (CLI: --tick {header.tick:g})."
        )
    if isinstance(bits, int) and bits != header.counter_bits:
        raise ParameterError(
            f"{source}: `counter_bits` is {bits} but the logger's header says "
            f"{header.counter_bits}; give 'auto' to use the header's."
        )
    k = len(records[0][1])
    if k != header.channels:
        raise ChannelCountError(
            f"{source}: line {records[0][0]}: {plural(k, 'gate')}, but the logger's header says "
            f"{header.channels}; the capture mixes loggers. Split it where the logger changed."
        )
    return header.counter_bits if bits == "auto" else bits


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
            reason = f"partial record ({plural(len(out[end][1]), 'gate')}, expected {k})"
            _skip(skipped, number, reason, lines[number - 1], strict, source)
            out.pop(end)
    for number, gates, *_ in out:
        if len(gates) != k:
            raise ChannelCountError(
                f"{source}: line {number}: {plural(len(gates), 'gate')}, but the log has {k} per "
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

"""Lines in a capture that are not gate records but say something: the logger's and `record`'s.

Contract: `parse_message` recognises one line and returns a `LoggerHeader`, an
`Overflow`, a `Gap` or a `Note`, or None for any other line; `format_gap` and
`format_note` write the lines `parse_message` reads back as a `Gap` and a `Note`.
Each message starts with ``#``, so a terminal program shows it and the record
pattern never matches it.

* The header, sent by the gate-logger firmware at start-up (after a reset)::

      # metrosync gate-logger 1.1 channels=8 tick_us=64 counter_bits=32 baud=115200 holdoff_ticks=4

  and again, ending ``requested=1``, when it receives `HEADER_REQUEST` (firmware 1.1).
  Keys may come in any order; unknown keys are kept in ``extra``, so a later firmware
  may add some. A header after the first record means the logger restarted and its
  counter began again, unless it was requested.
* The overflow line, where the logger's buffer was full and gate changes were lost::

      # overflow: 12 records lost

* The gap line, written by ``metrosync record --reconnect`` where the port vanished and
  came back: the wall-clock time from the last line before the loss to the first line
  after it::

      # metrosync record: gap of 12.345 s (port /dev/ttyACM0 vanished and came back)

* Any other line of ``metrosync record``, a note for the reader of the capture (a line
  cut off when the port vanished, no logger header seen)::

      # metrosync record: no logger header seen ...
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from ..errors import LogFormatError

_HEADER = re.compile(r"^\s*#\s*metrosync gate-logger\s+(\S+)((?:\s+\w+=\S*)*)\s*$")
_OVERFLOW = re.compile(r"^\s*#\s*overflow:\s*(\d+) records? lost\s*$")
_GAP = re.compile(r"^\s*#\s*metrosync record: gap of ([0-9.]+(?:e[+-]?\d+)?) s\b.*$")
_NOTE = re.compile(r"^\s*#\s*metrosync record: (.*?)\s*$")
_NEEDED = ("channels", "tick_us", "counter_bits")
#: The byte that asks the gate-logger firmware (1.1 and later) for its header again.
HEADER_REQUEST = b"?"


@dataclass(frozen=True)
class LoggerHeader:
    """The logger's start-up line (SI units).

    version : firmware version.   channels : gates per record.
    tick : seconds per counter tick.   counter_bits : the counter's width.
    baud : the serial rate, or None if not given.
    extra : other ``key=value`` pairs, as text.
    requested : sent on request (`HEADER_REQUEST`), not at a start-up: the counter
        went on.
    """

    version: str
    channels: int
    tick: float
    counter_bits: int
    baud: int | None = None
    extra: dict[str, str] = field(default_factory=dict)
    requested: bool = False


@dataclass(frozen=True)
class Overflow:
    """The logger lost ``count`` records here (its buffer was full)."""

    count: int


@dataclass(frozen=True)
class Gap:
    """The recording stopped for ``seconds`` of wall-clock time here (port lost)."""

    seconds: float


@dataclass(frozen=True)
class Note:
    """``metrosync record`` says ``text`` here; it does not change the time line."""

    text: str


def parse_message(line: str) -> LoggerHeader | Overflow | Gap | Note | None:
    """The message a line carries, or None when it is not one.

    Raises `LogFormatError` for a header that names the logger but lacks a needed key
    or has a value that is not a number.
    """
    if "#" not in line:
        return None
    if m := _OVERFLOW.match(line):
        return Overflow(int(m[1]))
    if m := _GAP.match(line):
        seconds = float(m[1])
        if math.isfinite(seconds):
            return Gap(seconds)
    if m := _NOTE.match(line):
        return Note(m[1])
    if m := _HEADER.match(line):
        return _header(m[1], dict(pair.split("=", 1) for pair in m[2].split()), line)
    return None


def _header(version: str, pairs: dict[str, str], line: str) -> LoggerHeader:
    missing = [k for k in _NEEDED if k not in pairs]
    try:
        if missing:
            raise ValueError(f"no {', '.join(missing)}")
        channels = int(pairs.pop("channels"))
        tick = float(pairs.pop("tick_us")) * 1e-6
        bits = int(pairs.pop("counter_bits"))
        baud = int(pairs.pop("baud")) if "baud" in pairs else None
        requested = pairs.pop("requested", "0") == "1"
        if not (1 <= channels <= 8 and tick > 0 and math.isfinite(tick) and 8 <= bits <= 62):
            raise ValueError("a value out of range")
    except ValueError as error:
        raise LogFormatError(
            f"the logger's header {line.strip()!r} cannot be read ({error}); it needs "
            f"channels=1..8, tick_us>0 and counter_bits=8..62. Delete the line to read the "
            f"capture without it."
        ) from None
    return LoggerHeader(version, channels, tick, bits, baud, pairs, requested)


def format_note(text: str) -> str:
    """A note line of `record` (no line end)."""
    return f"# metrosync record: {text}"


def format_gap(seconds: float, port: str) -> str:
    """The gap line `record` writes (no line end)."""
    return f"# metrosync record: gap of {seconds:.3f} s (port {port} vanished and came back)"

"""Recording the logger's serial stream to a capture file, line for line, safely.

Contract: `record(port, out, ...)` reads the serial port (pyserial) and writes each
line to ``out`` as it arrives, the line end made ``\\n`` and nothing else changed, so
the file reads like a MINICOM capture. Each line is flushed at once and the file is
synced to disk at least once a second: a pulled cable or a killed process loses at
most the last second. It returns a `RecordSummary` when ``duration`` is over, on
Ctrl-C (KeyboardInterrupt: the file is completed, then the summary returned), or when
the port vanishes. With ``reconnect`` it waits for a vanished port to come back and
writes a gap line (`messages.format_gap`) before the first line after it: the
wall-clock time from the last line before the loss to that line, which the reader
uses to continue the time line of a logger that restarted.

The capture is written in place, not atomically: it must grow while it is recorded.
An existing file is refused unless ``overwrite``.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .._words import plural
from ..errors import ParameterError
from .messages import format_gap

#: Longest wait between two syncs of the capture to disk, s.
SYNC_EVERY = 1.0
#: Pause between attempts to reopen a vanished port, s.
RETRY_EVERY = 0.5
_LINE_END = re.compile(rb"\r\n|\r(?!$)|\n")


@dataclass(frozen=True)
class RecordSummary:
    """How a recording went: ``lines`` written, ``seconds`` recorded, ``gaps`` marked,
    ``ended`` ("duration", "interrupted" or "port vanished"), ``out`` the file."""

    out: Path
    lines: int
    seconds: float
    gaps: int
    ended: str

    def __str__(self) -> str:
        gaps = f", {plural(self.gaps, 'gap')} marked" if self.gaps else ""
        return (f"recorded {plural(self.lines, 'line')} in {self.seconds:.1f} s to "
                f"{self.out}{gaps} ({self.ended})")  # fmt: skip


class CaptureFile:
    """The capture being written: each line flushed, synced at least every `SYNC_EVERY` s."""

    def __init__(self, path: Path, *, overwrite: bool = False):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._f = open(self.path, "wb" if overwrite else "xb")  # noqa: SIM115
        except FileExistsError:
            raise ParameterError(
                f"`out` {str(self.path)!r} exists; choose another name, or give "
                f"`overwrite` (CLI: --overwrite) to replace it."
            ) from None
        self._synced = time.monotonic()
        self.lines = 0

    def write(self, data: bytes, *, line: bool = True) -> None:
        self._f.write(data + b"\n" if line else data)
        self._f.flush()
        self.lines += line
        if time.monotonic() - self._synced >= SYNC_EVERY:
            self.sync()

    def sync(self) -> None:
        self._f.flush()
        os.fsync(self._f.fileno())
        self._synced = time.monotonic()

    def close(self) -> None:
        if not self._f.closed:
            self.sync()
            self._f.close()


def open_port(port: str, baud: int):
    """The serial port, or a `ParameterError` that says how to find the right one."""
    import serial

    try:
        return serial.Serial(port, baudrate=baud, timeout=0.05)
    except (serial.SerialException, OSError, ValueError) as error:
        raise ParameterError(
            f"cannot open the serial port `port` {port!r} at {baud} baud: {error}. List the "
            f"ports with `python -m serial.tools.list_ports`."
        ) from None


def record(
    port: str,
    out: str | Path,
    *,
    baud: int = 115200,
    duration: float | None = None,
    reconnect: bool = False,
    overwrite: bool = False,
    on_line: Callable[[str], None] | None = None,
    on_tick: Callable[[float], None] | None = None,
) -> RecordSummary:
    """Record the logger's lines from ``port`` into ``out`` (see the module docstring).

    Parameters
    ----------
    port : serial device, e.g. ``/dev/ttyACM0`` (any path pyserial opens, a pty too).
    out : capture file to write.
    baud : serial rate; the gate-logger firmware sends at 115200.
    duration : stop after this many seconds (None: until Ctrl-C or the port vanishes).
    reconnect : wait for a vanished port and go on, marking the gap.
    overwrite : replace an existing ``out``.
    on_line : called with each line written (text, with its line end).
    on_tick : called at least 10 times a second with the seconds since the last line.
    """
    import serial

    if not (isinstance(baud, int) and baud > 0):
        raise ParameterError(f"`baud` must be a whole number > 0, got {baud!r}.")
    if duration is not None and not (duration > 0 and duration < float("inf")):
        raise ParameterError(f"`duration` must be a time > 0 s, got {duration!r}.")
    conn = open_port(port, baud)
    capture = CaptureFile(Path(out), overwrite=overwrite)
    start = last_line = time.monotonic()
    pending, gaps, lost_at, ended = b"", 0, None, "duration"
    try:
        while duration is None or time.monotonic() - start < duration:
            if conn is None:  # the port vanished: wait for it
                time.sleep(RETRY_EVERY)
                conn = _reopen(port, baud)
                if on_tick:
                    on_tick(time.monotonic() - last_line)
                continue
            try:
                data = conn.read(conn.in_waiting or 1)
            except (serial.SerialException, OSError):
                conn.close()
                conn = None
                if pending:
                    # Kept, but as a note: a record cut short could read as a wrong time.
                    note = b"# metrosync record: cut off when the port vanished: " + pending
                    capture.write(note)
                    pending = b""
                    if on_line:
                        on_line(note.decode("utf-8", errors="replace") + "\n")
                if not reconnect:
                    ended = "port vanished"
                    break
                lost_at = last_line
                continue
            pending += data
            *lines, pending = _LINE_END.split(pending)
            for line in lines:
                now = time.monotonic()
                if lost_at is not None:
                    gap = format_gap(now - lost_at, port)
                    capture.write(gap.encode())
                    gaps += 1
                    lost_at = None
                    if on_line:
                        on_line(gap + "\n")
                capture.write(line)
                last_line = now
                if on_line:
                    on_line(line.decode("utf-8", errors="replace") + "\n")
            if on_tick:
                on_tick(time.monotonic() - last_line)
    except KeyboardInterrupt:
        ended = "interrupted"
    finally:
        if pending:
            capture.write(pending, line=False)
            if on_line:
                on_line(pending.decode("utf-8", errors="replace"))
        capture.close()
        if conn is not None:
            conn.close()
    return RecordSummary(Path(out), capture.lines, time.monotonic() - start, gaps, ended)


def _reopen(port: str, baud: int):
    import serial

    try:
        return serial.Serial(port, baudrate=baud, timeout=0.05)
    except (serial.SerialException, OSError):
        return None

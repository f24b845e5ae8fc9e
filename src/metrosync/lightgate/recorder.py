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

The logger's header. Opening the port flushes what the board sent before, so only a
board that resets when its port opens (an Arduino Uno, a Nano with a USB-serial chip)
sends its start-up header into the capture. When no header has come `HEADER_WAIT` s
after the start, `record` sends `messages.HEADER_REQUEST`, which the gate-logger
firmware 1.1 answers with its header (``requested=1``: not a restart). When none has
come `REQUEST_WAIT` s later, or when the recording ends first, a note says so in the
capture (`NO_HEADER`, `NO_HEADER_YET`): the reader then takes the gate count from the
records, and the counter width from the largest value seen. The first line of such a
capture may be a fragment of a line; the reader skips and counts it.

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
from ..errors import MetrosyncError, ParameterError
from .messages import HEADER_REQUEST, LoggerHeader, format_gap, format_note, parse_message

#: Longest wait between two syncs of the capture to disk, s.
SYNC_EVERY = 1.0
#: Pause between attempts to reopen a vanished port, s.
RETRY_EVERY = 0.5
#: Seconds after the start to wait for a start-up header before asking for one: a
#: board that resets when the port opens runs its bootloader first, for a second or so.
HEADER_WAIT = 2.0
#: Seconds to wait for the header asked for (its line takes 10 ms at 115200 baud).
REQUEST_WAIT = 1.0
#: The note written when no header came, after a request for it or before one.
NO_HEADER = (
    "no logger header seen after a request for it: the board did not reset when its port "
    "was opened, and its firmware does not answer '?' (gate-logger before 1.1, or another "
    "logger); the gate count and the counter width come from the records"
)
NO_HEADER_YET = (
    "no logger header seen in the {seconds:.1f} s recorded (it is asked for after "
    "{wait:g} s); the gate count and the counter width come from the records"
)
_LINE_END = re.compile(rb"\r\n|\r(?!$)|\n")


@dataclass(frozen=True)
class RecordSummary:
    """How a recording went: ``lines`` written, ``seconds`` recorded, ``gaps`` marked,
    ``ended`` ("duration", "interrupted" or "port vanished"), ``out`` the file,
    ``header``: how the logger's header came ("at start", "on request" or "not seen")."""

    out: Path
    lines: int
    seconds: float
    gaps: int
    ended: str
    header: str = "at start"

    def __str__(self) -> str:
        gaps = f", {plural(self.gaps, 'gap')} marked" if self.gaps else ""
        header = ", no logger header seen" if self.header == "not seen" else ""
        return (f"recorded {plural(self.lines, 'line')} in {self.seconds:.1f} s to "
                f"{self.out}{gaps}{header} ({self.ended})")  # fmt: skip


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


class HeaderWatch:
    """Looks for the logger's header in the first lines, and asks for it when late."""

    def __init__(self, start: float):
        self.start = start
        self.state = "waiting"  # then "at start", "on request" or "not seen"
        self.asked_at: float | None = None

    def saw(self, line: bytes) -> None:
        if self.state != "waiting" or b"#" not in line:
            return
        try:
            message = parse_message(line.decode("utf-8", errors="replace"))
        except MetrosyncError:
            return  # a header the reader will refuse, with its reason
        if isinstance(message, LoggerHeader):
            self.state = "on request" if self.asked_at is not None else "at start"

    def due(self, now: float, conn) -> str | None:
        """Ask for the header when it is late; the note to write when it did not come."""
        if self.state != "waiting":
            return None
        if self.asked_at is None and now - self.start >= HEADER_WAIT:
            self.asked_at = now
            try:
                conn.write(HEADER_REQUEST)
            except Exception:  # noqa: BLE001 - a vanished port shows at the next read
                pass
        elif self.asked_at is not None and now - self.asked_at >= REQUEST_WAIT:
            return self.give_up(now)
        return None

    def give_up(self, now: float) -> str | None:
        """The note for a recording that ends (or waited long enough) without a header."""
        if self.state != "waiting":
            return None
        self.state = "not seen"
        if self.asked_at is not None:
            return format_note(NO_HEADER)
        return format_note(NO_HEADER_YET.format(seconds=now - self.start, wait=HEADER_WAIT))


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
    header = HeaderWatch(start)

    def write_note(text: str | None) -> None:
        if text is not None:
            capture.write(text.encode())
            if on_line:
                on_line(text + "\n")

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
                header.saw(line)
                last_line = now
                if on_line:
                    on_line(line.decode("utf-8", errors="replace") + "\n")
            write_note(header.due(time.monotonic(), conn))
            if on_tick:
                on_tick(time.monotonic() - last_line)
    except KeyboardInterrupt:
        ended = "interrupted"
    finally:
        if pending:
            # A final line without its end stays the capture's last bytes: a note after
            # it would join it.
            capture.write(pending, line=False)
            if on_line:
                on_line(pending.decode("utf-8", errors="replace"))
            header.give_up(time.monotonic())  # said in the summary only
        else:
            write_note(header.give_up(time.monotonic()))
        capture.close()
        if conn is not None:
            conn.close()
    return RecordSummary(Path(out), capture.lines, time.monotonic() - start, gaps, ended,
                         header.state)  # fmt: skip


def _reopen(port: str, baud: int):
    import serial

    try:
        return serial.Serial(port, baudrate=baud, timeout=0.05)
    except (serial.SerialException, OSError):
        return None

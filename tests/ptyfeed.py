"""Pseudo-terminals standing in for the logger's serial port, and `metrosync` in a subprocess.

`Pty` opens a pseudo-terminal (raw, so nothing is echoed or translated before the
reader configures it) and can publish its reader end under a fixed path (a symlink),
so that a test can unplug it and plug a new one in at the same name. `Command` runs
``metrosync ...`` as a process and keeps each line it prints with the time it came.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import tty
from pathlib import Path


class Pty:
    """A pseudo-terminal: write to ``master``; a program opens ``path``."""

    def __init__(self, link: Path | None = None):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.name = os.ttyname(self.slave)
        self.path = Path(self.name)
        if link is not None:
            tmp = Path(f"{link}.new")
            tmp.unlink(missing_ok=True)
            tmp.symlink_to(self.name)
            tmp.replace(link)
            self.path = Path(link)

    def write(self, text: str) -> None:
        data = text.encode()
        while data:
            data = data[os.write(self.master, data) :]

    def unplug(self) -> None:
        """The cable is pulled: the reader's next read fails, and the name is gone."""
        for fd in (self.master, self.slave):
            try:
                os.close(fd)
            except OSError:
                pass  # closed already
        self.master = self.slave = -1
        if self.path != Path(self.name):
            self.path.unlink(missing_ok=True)


class Command:
    """``metrosync ARGS`` in a process; ``lines`` holds (monotonic time, line) as printed."""

    def __init__(self, *args: str, cwd: Path | None = None):
        main = "import sys; from metrosync.cli import main; sys.exit(main(sys.argv[1:]))"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", main, *map(str, args)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
        )  # fmt: skip
        self.lines: list[tuple[float, str]] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.lines.append((time.monotonic(), line.rstrip("\n")))

    def interrupt(self, timeout: float = 60) -> tuple[int, str]:
        """Ctrl-C; returns (exit status, stderr)."""
        self.proc.send_signal(signal.SIGINT)
        return self.wait(timeout)

    def wait(self, timeout: float = 60) -> tuple[int, str]:
        code = self.proc.wait(timeout)
        self._reader.join(5)
        err = self.proc.stderr.read()
        self.proc.stdout.close()
        self.proc.stderr.close()
        return code, err

    def kill(self) -> None:
        """End the process if it still runs, and close its pipes."""
        if self.proc.poll() is None:
            self.proc.kill()
        if not self.proc.stderr.closed:
            self.wait()

    def has_open(self, device: str) -> bool:
        """Whether the process holds ``device`` open (Linux: its /proc entry)."""
        folder = Path(f"/proc/{self.proc.pid}/fd")
        try:
            return any(os.path.realpath(fd) == device for fd in folder.iterdir())
        except OSError:
            return False  # it ended, or a descriptor closed while we looked

    @property
    def text(self) -> str:
        return "\n".join(line for _, line in self.lines)


def wait_until(condition, timeout: float = 30, every: float = 0.01):
    """Poll ``condition()`` until it is true; fails the test after ``timeout`` s."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(every)
    raise AssertionError(f"timed out after {timeout} s waiting for {condition}")

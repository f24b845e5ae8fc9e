"""Replaying a capture into a serial line at the pace it was recorded: a logger without hardware.

Contract: `replay(text, fd, speed=...)` writes the lines of a capture (for example a
virtual gate's, `virtual.format_log`) to a file descriptor, such as the master end of
a pseudo-terminal that ``metrosync record`` reads, each line when its timestamp is
due: record k at ``t_k / speed`` s after the first, lines that are not records at
once. Lines go out with CR LF ends, as the gate-logger firmware sends them. It
returns the wall-clock (``time.monotonic``) time each line was written, so a caller
can measure how long a line takes to reach a capture.
"""

from __future__ import annotations

import os
import time

from ..errors import ParameterError
from .reader import DEFAULT_TICK, parse_log, split_lines


def replay(text: str, fd: int, *, speed: float = 1.0, tick: float = DEFAULT_TICK) -> list[float]:
    """Write the capture ``text`` to ``fd`` in real time divided by ``speed``.

    Returns the monotonic time at which each line was written.
    """
    if not (speed > 0 and speed < float("inf")):
        raise ParameterError(f"`speed` must be > 0, got {speed!r}.")
    lines, _ = split_lines(text)
    log = parse_log(text, tick=tick)
    due = {int(n): float(t) / speed for n, t in zip(log.line_numbers, log.times, strict=True)}
    start = time.monotonic()
    sent = []
    for number, line in enumerate(lines, start=1):
        wait = start + due.get(number, 0.0) - time.monotonic()
        if number in due and wait > 0:
            time.sleep(wait)
        data = (line + "\r\n").encode()
        while data:
            data = data[os.write(fd, data) :]
        sent.append(time.monotonic())
    return sent

"""Chunks of compiled work short enough for Ctrl-C and progress to act promptly.

Python handles a signal only between bytecodes, so a Ctrl-C that arrives while a
compiled kernel runs takes effect when the kernel returns. The driver therefore calls
a kernel for a bounded number of steps at a time, and `Pacer` sizes those chunks from
the throughput measured on the previous ones so that each takes about
`TARGET_SECONDS`: ~0.25 s on any machine and problem size, instead of a fixed number
of steps that is instant for one problem and minutes for another.

The first chunk is small (`FIRST_SECONDS` at a pessimistic rate) because it may also
load or compile the kernel; sizes then grow by at most `GROWTH` per chunk towards the
target, and shrink at once when a chunk overran it. The chunking never changes the
result: the kernels carry their whole state from one call to the next.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from . import interrupts

#: Wall time aimed at per compiled call, s.
TARGET_SECONDS = 0.25
#: Wall time of the first call at the pessimistic rate, s.
FIRST_SECONDS = 0.02
#: Largest factor by which a chunk grows over the previous one.
GROWTH = 4.0


class Pacer:
    """Sizes of successive chunks of ``total`` steps (see the module docstring).

    seconds_per_step : a pessimistic estimate of one step's wall time, s, used for
        the first chunk only.
    target : wall time aimed at per chunk, s.   clock : the clock that times them.
    """

    def __init__(
        self,
        total: int,
        seconds_per_step: float,
        *,
        target: float | None = None,
        clock: Callable[[], float] = time.perf_counter,
    ):
        self.total = int(total)
        self.done = 0
        self.target = TARGET_SECONDS if target is None else float(target)
        self.clock = clock
        self._size = max(1, int(FIRST_SECONDS / max(seconds_per_step, 1e-12)))

    def __iter__(self):
        """Yield (first step, step count) of each chunk; time the caller's work on it."""
        while self.done < self.total:
            interrupts.check()
            count = min(self._size, self.total - self.done)
            started = self.clock()
            yield self.done, count
            self._record(count, self.clock() - started)
            self.done += count

    def _record(self, count: int, seconds: float) -> None:
        if seconds <= 0:
            self._size = int(min(self._size * GROWTH, 2**62))
            return
        ideal = count * self.target / seconds
        self._size = max(1, round(min(ideal, self._size * GROWTH)))

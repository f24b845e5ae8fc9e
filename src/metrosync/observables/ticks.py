"""Tick rate: how often a metronome actually ticks, from its simulated zero crossings.

A metronome ticks twice a period, so its tick rate in ticks per minute is
120 / T for a period T between consecutive upward zero crossings. It differs from
the nominal BPM it was tuned to: the tuning inverts the small-amplitude frequency,
and a pendulum swinging at the default ≈ 0.77 rad is slower (a "192 BPM" metronome
ticks about 184.6 times a minute), and the coupling through the disk shifts it too.

The rate is measured over a final stretch of the run (`tail_span`), from the first
to the last upward crossing in it: (K − 1) periods in (t_K − t_1).

* `tick_rate` takes crossing times per metronome (the reference integrator keeps
  them all);
* `CrossingTally` counts the crossings of the fixed-step kernels without touching
  them: advanced in segments shorter than half the shortest period, a metronome
  crosses upward at most once per segment, so each new value of the state's
  ``last_up`` (time of the last upward crossing) is one crossing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Periods of the slowest metronome over which the tick rate is measured.
TICK_PERIODS = 20
#: Ticks per period.
TICKS_PER_PERIOD = 2


def tail_span(window: float, longest_period: float) -> float:
    """Length (s) of the final stretch that the tick rate is measured over: the
    equilibrium window, at most `TICK_PERIODS` periods of the slowest metronome."""
    return min(float(window), TICK_PERIODS * float(longest_period))


def rate_per_minute(first, last, count):
    """Ticks per minute from the first and last crossing times and their count;
    NaN where fewer than two crossings were seen. Arrays broadcast together."""
    first, last, count = np.broadcast_arrays(
        np.asarray(first, float), np.asarray(last, float), np.asarray(count)
    )
    out = np.full(first.shape, np.nan)
    ok = (count >= 2) & (last > first)
    out[ok] = TICKS_PER_PERIOD * 60.0 * (count[ok] - 1) / (last[ok] - first[ok])
    return out


def tick_rate(crossings: Sequence[Sequence[float]], since: float) -> np.ndarray:
    """Ticks per minute of each metronome from its upward-crossing times.

    crossings : N sequences of increasing times, s.   since : start of the stretch, s.
    Returns (N,); NaN for a metronome with fewer than two crossings from ``since``.
    """
    first, last, count = [], [], []
    for times in crossings:
        t = np.asarray(times, dtype=float)
        t = t[t >= since]
        count.append(t.size)
        first.append(t[0] if t.size else math.nan)
        last.append(t[-1] if t.size else math.nan)
    return rate_per_minute(first, last, count)


class CrossingTally:
    """First and last upward crossing and their count, per (run, metronome), from
    snapshots of a fixed-step state's ``last_up`` (B, N).

    Call `see` after each segment; a segment must be shorter than half the shortest
    period, so that no metronome crosses upward twice in it.
    """

    def __init__(self, last_up: np.ndarray) -> None:
        self._previous = np.array(last_up, dtype=float)
        self.first = np.full(self._previous.shape, np.nan)
        self.last = np.full(self._previous.shape, np.nan)
        self.count = np.zeros(self._previous.shape, dtype=np.int64)

    def see(self, last_up: np.ndarray) -> None:
        """Book the crossings that happened since the previous snapshot."""
        new = (last_up != self._previous) & (last_up >= 0)
        self.first = np.where(new & (self.count == 0), last_up, self.first)
        self.last = np.where(new, last_up, self.last)
        self.count += new
        self._previous = np.array(last_up, dtype=float)

    def rate(self) -> np.ndarray:
        """(B, N) ticks per minute; NaN where fewer than two crossings were seen."""
        return rate_per_minute(self.first, self.last, self.count)

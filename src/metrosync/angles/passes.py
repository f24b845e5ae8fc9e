"""A pendulum's sampled angle → its passes through the vertical, kept as a light gate keeps them.

The model: the table samples a pendulum's angle θ(t) (or a coordinate that crosses its
rest value when θ does, see `columns`) at its times, regular or not. The bob passes
the vertical, where a light gate at the bottom of the swing would see it, when
θ − θ_rest changes sign. A pass upward (θ − θ_rest rising through 0) is kept, one per
period, as the light gate keeps one direction, and from the kept passes on follows
the light gate's analysis (`metrosync.observables.crossings`): phases rising by 2π
between kept passes, r(t), frequencies, jitter, σ.

* θ_rest is the median of θ over the table. A steady swing spends half of each period
  on either side of its centre, so the median is the centre, whether the swing grows,
  decays or stays; unlike the midpoint of the extremes it is not moved by one wild
  sample (a mark misplaced in Tracker), and an encoder's zero, wherever it was set at
  power-on, drops out with it. It is a sample's value, so it can miss the centre by
  half the angle the bob moves between samples at the bottom: that delays every
  upward pass by the same time, which frequencies, jitter and r do not feel (nor is
  a tick/tock asymmetry measured: about the median, the two half-swings are equal by
  construction). A pendulum held still off-centre for a long stretch before its
  release would move it: leave that stretch out of the table.
* A crossing is timed at sub-sample precision by `zero_crossings`, the method `track`
  uses for a video's angles: the root of a cubic fitted by least squares to the six
  samples around the sign change (linear between the two samples where fewer are
  known), so that an encoder's steps (0.36° for 1000 lines) and pixel noise average
  out over the samples.
* Hysteresis: a pass counts only once θ − θ_rest has been below −h since the last one
  (above +h for a downward pass), h = `HYSTERESIS` × the 90th percentile of
  |θ − θ_rest|, as `track` does, so that noise near the vertical gives one pass.
* No crossing is placed across a blank cell or across a gap in time of more than
  `MAX_GAP` median sample steps (frames Tracker skipped, samples a logger lost): the
  period grid bridges the passes missed there (``passes_bridged``), as the light gate
  bridges a missed pass.

`passes` refuses, with an `AngleTableError` naming the table and its line, a time that
does not increase, fewer than `MIN_SAMPLES` samples, fewer than `MIN_PASSES` kept
passes, and passes that keep no period: more than `MAX_IRREGULAR` of the intervals
between them off a whole number of median periods by over a quarter period
(``intervals_irregular``, as the light gate counts them). Noise about a point that
does not swing (Tracker's track of the pivot, a bob at rest) puts half of them
there; a pendulum, even one whose passes go missing, almost none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._words import plural
from ..observables import crossings as ph
from .columns import Swing
from .table import AngleTableError

#: h as a fraction of the 90th percentile of |θ − θ_rest| (as `track` has it).
HYSTERESIS = 0.15
#: A step between samples longer than this many median steps is a gap.
MAX_GAP = 3.0
#: Largest share of irregular intervals between passes of something that swings.
MAX_IRREGULAR = 0.25
#: Fewest samples of a pendulum, and fewest kept passes (two periods) for a phase.
MIN_SAMPLES, MIN_PASSES = 10, 3


@dataclass(frozen=True)
class Passes:
    """One pendulum's passes through the vertical.

    swing : the sampled coordinate they come from.
    kept : (P,) upward passes, s on the table's clock; cycles : (P−1,) periods between
        them (1, or k where k − 1 passes were missed and bridged).
    rest : θ_rest, in the swing's unit.
    amplitude : median over periods of half the peak-to-peak swing, in its unit.
    gaps : gaps in time (longer than `MAX_GAP` steps) across which no pass was placed.
    irregular : intervals between kept passes more than 1/4 period off a whole number.
    samples : samples with a time and a value.
    step : median time between samples, s.
    """

    swing: Swing
    kept: np.ndarray
    cycles: np.ndarray
    rest: float
    amplitude: float
    gaps: int
    irregular: int
    samples: int
    step: float

    @property
    def bridged(self) -> int:
        """Passes missed and bridged: the sum of ``cycles − 1``."""
        return int(np.sum(self.cycles - 1))


def passes(swing: Swing, source: str) -> Passes:
    """The passes of ``swing`` (a pendulum of the table ``source``); see the module docstring."""
    keep = np.isfinite(swing.time)
    t, value, lines = swing.time[keep], swing.value[keep], swing.lines[keep]
    samples = int(np.count_nonzero(np.isfinite(value)))
    if samples < MIN_SAMPLES:
        raise AngleTableError(
            f"{source}: {swing.name} has {plural(samples, 'sample')} with a time and a "
            f"value, too few for a swing (at least {MIN_SAMPLES}; a few periods of "
            f"samples are needed)."
        )
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        i = int(back[0])
        raise AngleTableError(
            f"{source}: line {lines[i + 1]}: time {t[i + 1]:g} s follows {t[i]:g} s (line "
            f"{lines[i]}): the time column must increase. Rows out of order, or two logs in "
            f"one file? Sort it, or split it where the time starts again."
        )
    step = float(np.median(np.diff(t)))
    t, value, gaps = _split_at_gaps(t, value, step)
    rest = float(np.nanmedian(value))
    u = value - rest
    h = HYSTERESIS * float(np.nanpercentile(np.abs(u), 90))
    up = ph.zero_crossings(t, u, hysteresis=h)
    kept, cycles = ph.passes_on_period_grid(up)
    if kept.size < MIN_PASSES:
        span = float(t[-1] - t[0])
        raise AngleTableError(
            f"{source}: {swing.name} ({swing.source}) passes its rest value "
            f"{rest:.4g} upward {plural(kept.size, 'time')} in {span:.3g} s, too few for a "
            f"period and a phase (at least {MIN_PASSES}). Does it swing, and is that its "
            f"angle? Leave it out with `channels` (CLI: --channels), or name its column."
        )
    ratio = np.diff(kept) / np.median(np.diff(kept))
    irregular = int(np.count_nonzero(np.abs(ratio - np.rint(ratio)) > 0.25))
    if irregular > MAX_IRREGULAR * ratio.size:
        raise AngleTableError(
            f"{source}: {swing.name} ({swing.source}) keeps no period: {irregular} of "
            f"{ratio.size} intervals between its passes are over a quarter period off a whole "
            f"number of periods. Is it a pendulum (not the pivot, not a bob at rest)? Leave "
            f"it out with `channels` (CLI: --channels), or name its column."
        )
    amps = ph.swing_amplitudes(t, u, kept)
    amplitude = float(np.nanmedian(amps)) if np.isfinite(amps).any() else float("nan")
    return Passes(swing, kept, cycles, rest, amplitude, gaps, irregular, samples, step)


def _split_at_gaps(t: np.ndarray, value: np.ndarray, step: float):
    """``t`` and ``value`` with a NaN sample in each gap longer than `MAX_GAP` steps, so
    that `zero_crossings` places no crossing across it; and the number of gaps."""
    gap = np.flatnonzero(np.diff(t) > MAX_GAP * step)
    if gap.size == 0:
        return t, value, 0
    middle = 0.5 * (t[gap] + t[gap + 1])
    return np.insert(t, gap + 1, middle), np.insert(value, gap + 1, np.nan), int(gap.size)

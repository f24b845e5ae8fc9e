"""The beat period of a tick train, without knowing which metronome made which tick.

Contract: `beat_period(times, bpm=None)` returns T, the typical time between two ticks
of one metronome (60 / BPM, a metronome's BPM counting its ticks), and
`swing_matches(times, T)` pairs each tick with the tick one full swing (2T) later.

How. Every metronome's next tick comes one beat later, whatever the others do, while
the ticks of independent metronomes fall at any distance from each other. So among
all differences between tick times up to 2.4 s, the share of ticks that have a
successor near a lag L (within ±10 %, which also covers an uneven tick and tock)
stands out above the level expected of unrelated ticks at L = T and its multiples.
The shortest such lag (at least half the best excess) is the beat. The beat is then
refined from full swings: first the lag near 2L that most ticks have a successor at
(±1 %), then twice the median of the differences between each tick and its nearest
tick within ±3 % of 2T, halved; a full swing holds one tick and one tock, so an uneven
beat does not bias it. Given ``bpm`` (the metronomes' setting), only lags within ±15 %
of 60/bpm are considered.

Limit: two groups of metronomes ticking exactly half a beat apart sound like one
group at twice the tempo; give ``bpm`` to settle it.
"""

from __future__ import annotations

import numpy as np

from .._words import plural
from ..errors import AnalysisError

#: Tempi searched without a hint, BPM.
BPM_RANGE = (30.0, 300.0)
#: Relative half-width of a lag's bin in the coarse search.
LAG_TOLERANCE = 0.10
#: Relative tolerance of a full swing once the beat is known to about 1 %.
SWING_TOLERANCE = 0.03
#: With a hint, lags within this relative distance of 60/bpm.
HINT_RANGE = 0.15
#: Fewest ticks that can give a tempo.
MIN_TICKS = 8


def beat_period(times: np.ndarray, bpm: float | None = None) -> float:
    """T (s), the beat period of the tick train ``times`` (K,), sorted."""
    times = np.asarray(times, dtype=float)
    if times.size < MIN_TICKS:
        raise AnalysisError(
            f"found only {plural(times.size, 'tick')}; at least {MIN_TICKS} are needed for a "
            f"tempo. Is this a metronome recording? Try a lower `sensitivity` or another `band`."
        )
    if bpm is None:
        lo, hi = 60.0 / BPM_RANGE[1], 60.0 / BPM_RANGE[0]
    else:
        lo, hi = 60.0 / bpm * (1 - HINT_RANGE), 60.0 / bpm * (1 + HINT_RANGE)
    coarse = _coarse_lag(times, lo, hi, pick_shortest=bpm is None)
    period = _best_swing(times, coarse) / 2
    for _ in range(2):
        matched = swing_matches(times, period)
        if matched.size < MIN_TICKS // 2:
            break
        period = float(np.median(matched)) / 2
    return period


def _coarse_lag(times: np.ndarray, lo: float, hi: float, *, pick_shortest: bool) -> float:
    k = times.size
    span = times[-1] - times[0]
    rate = (k - 1) / span if span > 0 else 0.0
    top = hi * (1 + LAG_TOLERANCE)
    # all differences up to `top`; thin the ticks if that would be too many pairs
    step = max(1, int(rate * top * k / 4e6))
    sample = times[::step]
    ends = np.searchsorted(times, sample + top, side="right")
    firsts = np.searchsorted(times, sample, side="right")
    counts = ends - firsts
    owner = np.repeat(np.arange(sample.size), counts)
    offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    diffs = np.sort(times[np.repeat(firsts, counts) + offsets] - sample[owner])
    lags = np.geomspace(lo, hi, max(16, int(np.log(hi / lo) / 0.004)))
    inside = np.searchsorted(diffs, lags * (1 + LAG_TOLERANCE), side="right") - np.searchsorted(
        diffs, lags * (1 - LAG_TOLERANCE), side="left"
    )
    # excess over the share that unrelated ticks at the same rate would put in the bin
    excess = inside / sample.size - rate * 2 * LAG_TOLERANCE * lags
    best = float(excess.max())
    if best <= 0:
        raise AnalysisError(
            f"the {plural(k, 'tick')} show no steady beat between {60 / hi:.0f} and "
            f"{60 / lo:.0f} BPM; "
            f"give the metronomes' setting (`bpm`) or check that the recording holds ticks."
        )
    peaks = np.flatnonzero(
        (excess >= 0.5 * best) & (excess >= np.roll(excess, 1)) & (excess >= np.roll(excess, -1))
    )
    choice = peaks[0] if pick_shortest and peaks.size else int(np.argmax(excess))
    return float(lags[choice])


def _best_swing(times: np.ndarray, beat: float) -> float:
    """The lag within ±10 % of 2·beat that the most ticks have a successor at (±1 %)."""
    lags = 2 * beat * np.linspace(1 - LAG_TOLERANCE, 1 + LAG_TOLERANCE, 201)
    base = times[:: max(1, times.size // 5000), None]  # enough ticks for a histogram
    j_hi = np.searchsorted(times, base + lags * 1.01, side="right")
    j_lo = np.searchsorted(times, base + lags * 0.99, side="left")
    hits = (j_hi > j_lo).sum(axis=0)
    return float(lags[int(np.argmax(hits))])


def swing_matches(times: np.ndarray, period: float) -> np.ndarray:
    """(M,) for each tick with a tick near t + 2·period (±`SWING_TOLERANCE`), the
    difference to the nearest such tick, s."""
    target = times + 2 * period
    j = np.clip(np.searchsorted(times, target), 1, times.size - 1)
    nearest = np.where(np.abs(times[j - 1] - target) < np.abs(times[j] - target), j - 1, j)
    d = times[nearest] - times
    ok = np.abs(d - 2 * period) < SWING_TOLERANCE * 2 * period
    return d[ok]

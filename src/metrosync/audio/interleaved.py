"""One metronome followed as two trains, each with its own kind of beat and the other
kind's later impacts, joined into one.

Contract: `join_interleaved(times, strength, trains)` returns the trains with each such
pair joined.

A tick is several impacts: the first and, 15–35 ms later, fainter ones (`trains`). The
tracker can follow a metronome's ticks and take, on the beats between, the later
impact of each tock: a train at the metronome's own tempo with a steady limp. A second
train then holds the tocks, alone (at half the tempo, or a quarter where others hid
every other one) or with the ticks' later impacts. Neither is wrong to the tracker;
together they are one metronome counted as two, each half followed on the wrong
impact.

Two trains A and B are joined when, on their common beat (the shorter period; the
other within 1 % of it or of a whole multiple of it up to `MAX_MULTIPLE`), their
ticks put together make pairs closer than `trains.MAX_TICK_LENGTH`, each a tick of one
train followed by one of the other, and

* there are pairs for at least `MIN_PAIRED` of the smaller train's ticks;
* the later tick of a pair is `trains.LATER_FAINTER` dB fainter (median over pairs);
* the pairs keep one or two fixed lags (a tick may have two later impacts): at least
  `STEADY_SHARE` of them in modes of robust spread below 2 × `trains.PART_LAG_SPREAD`,
  what `trains.fold_parts` allows a later impact timed in the first one's ring;
* with the later tick of each pair taken out, the ticks left fall on one grid of the
  beat (`ON_GRID` of the gaps within 15 % of a whole number of beats), and each train
  gives at least `MIN_SHARE_KEPT` of them.

The joined train holds the earlier tick of each pair: a tick's onset is its first
impact. Two metronomes locked a few milliseconds apart are left apart: their lag
wanders by more as each one's beat jitters, and the fainter would have to alternate
between them from tick to tock for both to keep ticks of their own.
"""

from __future__ import annotations

import numpy as np

from .trains import LATER_FAINTER, MAX_TICK_LENGTH, PART_LAG_SPREAD, Train, robust_spread

#: Largest multiple of the common beat a train's period may be: a train of every 4th
#: beat holds ticks of one kind only, like one of every 2nd.
MAX_MULTIPLE = 4
#: Least share of the smaller train's ticks paired with a later impact in the other.
MIN_PAIRED = 0.25
#: Least share of the pairs whose lags keep still (in one or two modes).
STEADY_SHARE = 0.8
#: Lags farther apart than this (s) are two modes.
MODE_GAP = 2e-3
#: Least share of the ticks left that lie on the common grid.
ON_GRID = 0.95
#: Least share of the ticks left that each train gives.
MIN_SHARE_KEPT = 0.2


def join_interleaved(times: np.ndarray, strength: np.ndarray, trains: list[Train]) -> list[Train]:
    """The trains, each pair that is one metronome's interleaved halves joined (see the
    module docstring). ``times`` and ``strength`` (dB) are the ticks', sorted by time."""
    trains = list(trains)
    joined = True
    while joined:
        joined = False
        for a in range(len(trains)):
            for b in range(a + 1, len(trains)):
                one = _interleaved(times, strength, trains[a], trains[b])
                if one is not None:
                    trains[a] = one
                    del trains[b]
                    joined = True
                    break
            if joined:
                break
    return trains


def _interleaved(times, strength, ta: Train, tb: Train) -> Train | None:
    beat = min(ta.period, tb.period)
    for period in (ta.period, tb.period):
        k = round(period / beat)
        if not 1 <= k <= MAX_MULTIPLE or abs(period / (k * beat) - 1) > 0.01:
            return None
    index = np.union1d(ta.index, tb.index)  # the ticks are sorted by time
    in_a, in_b = np.isin(index, ta.index), np.isin(index, tb.index)
    t = times[index]
    close = np.flatnonzero(np.diff(t) < MAX_TICK_LENGTH) + 1
    only_a, only_b = in_a & ~in_b, in_b & ~in_a
    cross = (only_a[close - 1] & only_b[close]) | (only_b[close - 1] & only_a[close])
    later = close[cross]
    later = later[~np.isin(later - 1, later)]  # a chain's first tick is its onset
    if later.size < MIN_PAIRED * min(ta.index.size, tb.index.size):
        return None
    if np.median(strength[index[later - 1]] - strength[index[later]]) < LATER_FAINTER:
        return None
    if not _steady(t[later] - t[later - 1]):
        return None
    keep = np.ones(index.size, dtype=bool)
    keep[later] = False
    if min(only_a[keep].mean(), only_b[keep].mean()) < MIN_SHARE_KEPT:
        return None
    index, t = index[keep], t[keep]
    steps = np.diff(t) / beat
    whole = np.rint(steps)
    if np.mean((whole >= 1) & (np.abs(steps - whole) < 0.15)) < ON_GRID:
        return None
    beats = np.concatenate([[0], np.cumsum(np.maximum(whole, 1))]).astype(np.int64)
    # masked only where every train that holds it took it from another metronome
    own = np.concatenate([ta.index[~ta.masked], tb.index[~tb.masked]])
    return Train(index, beats, float((t[-1] - t[0]) / beats[-1]), ~np.isin(index, own))


def _steady(lag: np.ndarray) -> bool:
    """At least `STEADY_SHARE` of ``lag`` in modes (`MODE_GAP` apart) that keep still."""
    lag = np.sort(lag)
    cuts = np.flatnonzero(np.diff(lag) > MODE_GAP) + 1
    still = sum(
        mode.size
        for mode in np.split(lag, cuts)
        if mode.size >= 3 and robust_spread(mode) < 2 * PART_LAG_SPREAD
    )
    return still >= STEADY_SHARE * lag.size

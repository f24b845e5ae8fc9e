"""Metronomes hidden behind each other: the trains that cannot be told apart.

Contract: `hidden_trains(periods, jitters)` takes each train's beat period (s) and
the jitter of its beats (s, `metronome.beat_statistics`), and returns the indices of
the trains that follow no one metronome; `hidden_count(times, span, trains)` says how
many metronomes their ticks hold; `followers(periods, jitters)` returns the indices of
the trains that follow a metronome told apart every few beats.

Two metronomes of nearly one tempo that tick together all along, one hidden behind
the other most of the time, cannot be told apart on one microphone: the tracker
follows their ticks as several trains, each jumping between the two. Such trains
give themselves away by their beat and their tempo:

- a train of one metronome keeps its beat within a millisecond or two; one that
  jumps between two does not (jitter above `MAX_JITTER`);
- two of these unsteady trains hold tempi in a ratio of small whole numbers
  (`LOCK`, up to `RATIO`): each followed every few beats of the same ticks;
- a train whose tempo is a whole multiple, or the same, of such a train's (within
  `LOCK`) follows the same ticks, every beat or every few beats, steady or not;
  and so does a train with no beat at all (jitter above `NO_BEAT` of its beat).

Real metronomes on one disk neither lock at 3:2 nor keep jumping by milliseconds, so
the trains of the metronomes told apart stay; a pair that locks 1:1, however
unsteady, starts nothing. An unsteady train alone whose tempo is a whole fraction of
a steady train's follows that metronome's ticks, or their later impacts, every few
beats among other sounds: it is no metronome at all (`followers`). The metronomes
behind the hidden trains are counted from their ticks: the ticks no kept train holds,
per beat of their own tempo, at least two and at most as many as the hidden trains.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import AnalysisError
from .tempo import beat_period

#: Jitter (s) above which a train's beat is not one metronome's.
MAX_JITTER = 3e-3
#: Jitter as a share of the beat above which a train has no beat at all.
NO_BEAT = 0.05
#: Relative tempo difference within which two trains are locked at a ratio.
LOCK = 5e-3
#: Largest whole number in a locked ratio a/b.
RATIO = 6


def _locked(p: float, q: float, harmonic: bool) -> tuple[int, int] | None:
    """(a, b) with p/q within `LOCK` of a/b, a and b up to `RATIO` (one of them 1
    when ``harmonic``), or None."""
    for a in range(1, RATIO + 1):
        for b in range(1, RATIO + 1):
            if math.gcd(a, b) != 1 or (harmonic and min(a, b) != 1):
                continue
            if abs(p / q * b / a - 1) <= LOCK:
                return a, b
    return None


def hidden_trains(periods, jitters) -> list[int]:
    """Indices (sorted) of the trains that follow ticks of metronomes that cannot be
    told apart (see the module docstring); empty when every train is one metronome."""
    periods = np.asarray(periods, dtype=float)
    jitters = np.nan_to_num(np.asarray(jitters, dtype=float), nan=0.0)
    unsteady = jitters > MAX_JITTER
    group: set[int] = set()
    for i in np.flatnonzero(unsteady).tolist():
        for j in np.flatnonzero(unsteady).tolist():
            ab = _locked(periods[i], periods[j], harmonic=False) if i < j else None
            if ab is not None and ab != (1, 1):
                group |= {int(i), int(j)}
    if not group:
        return []
    grew = True
    while grew:
        grew = False
        for i in range(periods.size):
            if i in group:
                continue
            joins = jitters[i] > NO_BEAT * periods[i] or any(
                _locked(periods[i], periods[j], harmonic=True) for j in group
            )
            if joins:
                group.add(i)
                grew = True
    return sorted(group)


def followers(periods, jitters) -> list[int]:
    """Indices (sorted) of the unsteady trains (jitter above `MAX_JITTER`) whose beat is
    a whole multiple (2 to `RATIO`, within `LOCK`) of a steady train's: they follow
    that metronome's ticks, or their later impacts, every few beats among a few other
    sounds (corpus seed 4/363: a train at a quarter of a metronome's tempo, seven of
    its ten ticks 33 ms after that metronome's, and a jitter of 27 ms), and are no
    metronome of their own."""
    periods = np.asarray(periods, dtype=float)
    jitters = np.nan_to_num(np.asarray(jitters, dtype=float), nan=0.0)
    steady = np.flatnonzero(jitters <= MAX_JITTER)
    out = []
    for i in np.flatnonzero(jitters > MAX_JITTER).tolist():
        ratios = (_locked(periods[i], periods[j], harmonic=True) for j in steady)
        if any(ab is not None and ab[0] > 1 and ab[1] == 1 for ab in ratios):
            out.append(int(i))
    return out


def hidden_count(times: np.ndarray, span: float, hidden: int) -> tuple[int, float, float]:
    """(metronomes, beat period s, ticks per beat) behind ``hidden`` trains from the
    ticks no kept train holds (``times``, sorted) over ``span`` s: their ticks per beat
    of their own tempo, rounded, at least 2 and at most ``hidden``."""
    try:
        period = beat_period(times)
    except AnalysisError:
        return 2, math.nan, math.nan
    per_beat = times.size * period / max(span, period)
    return int(np.clip(round(per_beat), 2, max(2, hidden))), float(period), float(per_beat)

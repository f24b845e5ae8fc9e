"""The onsets of a recording explained as metronomes and clutter.

The model. A recording's onsets are the impacts of M metronomes' ticks, each metronome
a timing model with its learned tick (`structure`), plus clutter. M and the metronomes
are found by matching pursuit: the periodicity search (`periodicity`) proposes tempi
among the onsets not yet explained; the metronome at the likeliest tempo is followed
(`structure.follow`); it is kept if it explains enough of the recording to be a
metronome (its main impact heard in `MIN_HEARD` of its beats, over at least `MIN_BEATS`
beats), its onsets are set aside, and the search runs again on the rest, until no
tempo is left above the false-alarm threshold. Then each metronome is followed again
with the others' onsets set aside (the onsets go to whichever metronome explains them
best), so that the order in which they were found does not decide who holds a tick.

A harmonic (twice a tempo) is rejected by the model itself: half its beats hold no
impact of their kind. A precursor or a bounce at the tempo of a metronome is that
metronome's impact (`structure`), not a metronome of its own.

Contract: `decompose(times)` returns the `Heard` metronomes, slowest first, and (K,)
the owner of each onset (−1: clutter).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import AnalysisError
from .periodicity import BPM_RANGE, candidate_tempi
from .structure import Followed, follow, normal_density

#: Share of its beats a metronome's main impact must be heard in.
MIN_HEARD = 0.5
#: Fewest beats a metronome must span to be one.
MIN_BEATS = 16
#: Most metronomes sought (a bound on the search, not an assumption of the model).
MAX_METRONOMES = 8
#: Share of a metronome's ticks that another explains, beyond which it is no metronome.
REDUNDANT = 0.5
#: Passes of refollowing every metronome with the others' onsets set aside.
PASSES = 2


@dataclass(frozen=True)
class Heard:
    """One metronome of the recording: its `Followed` model, fitted on the onsets
    ``pool`` (indices into the recording's onsets), and the indices of its ticks."""

    followed: Followed
    pool: np.ndarray

    @property
    def ticks(self) -> np.ndarray:
        """Indices (into the recording's onsets) of the onsets that time its ticks."""
        return self.pool[self.followed.main]

    @property
    def beats(self) -> np.ndarray:
        """The beat number of each of `ticks`."""
        return self.followed.beat[self.followed.main]


def decompose(times, strengths=None, bpm_range=BPM_RANGE) -> tuple[list[Heard], np.ndarray]:
    """Metronomes that explain the sorted onset ``times`` (s), with their ``strengths``
    (dB, optional: they tell a strike from a bounce as regular as it), and each onset's
    owner."""
    t = np.asarray(times, dtype=float)
    level = None if strengths is None else np.asarray(strengths, dtype=float)
    owner = np.full(t.size, -1)
    metronomes: list[Heard] = []
    starts: list[float] = []  # the tempo each was first followed from, which worked
    while len(metronomes) < MAX_METRONOMES:
        free = np.flatnonzero(owner < 0)
        kept = _likeliest(t, level, free, bpm_range)
        if kept is None:
            break
        start, heard = kept
        owner[heard.pool[heard.followed.impact >= 0]] = len(metronomes)
        metronomes.append(heard)
        starts.append(start)
    mains = None
    for _ in range(PASSES):
        metronomes, owner = _refollow(t, level, starts, metronomes, mains)
        kept = _without_redundant(metronomes, t.size)
        starts = [starts[m] for m in kept]
        metronomes = [metronomes[m] for m in kept]
        mains = np.full(t.size, -1)
        for m, h in enumerate(metronomes):
            mains[h.ticks] = m
    order = np.argsort([m.followed.timing.period for m in metronomes])[::-1]
    relabel = np.full(len(metronomes) + 1, -1)
    relabel[order] = np.arange(order.size)
    return [metronomes[i] for i in order], np.where(owner >= 0, relabel[owner], -1)


def _without_redundant(heard: list[Heard], k: int) -> list[int]:
    """The indices of ``heard`` less each metronome whose ticks are mostly another's impacts: it
    explains nothing the other does not (a harmonic that a limp or a rival's onsets
    made look like a tempo), and a penalised likelihood keeps no such component.
    The metronomes with the fewest ticks are judged first."""
    order = sorted(range(len(heard)), key=lambda m: heard[m].ticks.size)
    kept = set(order)
    for m in order:
        others = np.zeros(k, dtype=bool)
        for o in kept - {m}:
            h = heard[o]
            others[h.pool[h.followed.impact >= 0]] = True
        if others[heard[m].ticks].mean() > REDUNDANT:
            kept.discard(m)
    return sorted(kept)


def _likeliest(t: np.ndarray, level, free: np.ndarray, bpm_range):
    """(the tempo it was followed from, the `Heard`) of the first candidate among the
    onsets ``free`` that is a metronome, strongest first; None when none is."""
    if free.size < MIN_BEATS:
        return None
    for candidate in candidate_tempi(t[free], bpm_range=bpm_range):
        followed = _metronome(t[free], candidate.bpm, _part(level, free))
        if followed is not None:
            return candidate.bpm, Heard(followed, free)
    return None


def _part(level, index):
    return None if level is None else level[index]


def _metronome(t: np.ndarray, bpm: float, level=None) -> Followed | None:
    """The metronome followed from ``bpm`` among onsets ``t``, if it is one."""
    try:
        followed = follow(t, bpm, level)
    except AnalysisError:
        return None
    beats = followed.beat[followed.main]
    if beats.size < 2:
        return None
    span = int(beats.max() - beats.min()) + 1
    if span < MIN_BEATS or beats.size < MIN_HEARD * span:
        return None
    return followed


def _refollow(t: np.ndarray, level, starts: list[float], before: list[Heard], mains=None):
    """Each metronome followed again, from the tempo it was first followed from, on every
    onset but the other metronomes' ticks (``mains``: (K,) the metronome whose tick each
    onset is, −1 for none), keeping its last model where that fails; an onset two
    metronomes explain goes to the one whose learned tick makes it likelier
    (`_density`)."""
    heard: list[Heard] = []
    density = np.zeros((len(starts), t.size))
    mains = np.full(t.size, -1) if mains is None else mains
    for m, bpm in enumerate(starts):
        pool = np.flatnonzero((mains < 0) | (mains == m))
        followed = _metronome(t[pool], bpm, _part(level, pool))
        one = before[m] if followed is None else Heard(followed, pool)
        density[m, one.pool] = _density(t[one.pool], one.followed)
        heard.append(one)
    if not heard:
        return [], np.full(t.size, -1)
    owner = np.where(density.max(axis=0) > 0, np.argmax(density, axis=0), -1)
    for m, one in enumerate(heard):  # a tick is its metronome's, however far off its beat
        ticks = one.ticks
        owner[ticks[owner[ticks] < 0]] = m
    return heard, owner


def _density(t: np.ndarray, followed: Followed) -> np.ndarray:
    """(K,) the density (1/s) of each onset under the impact that explains it, weighted
    by how often that impact is heard: presence × N(offset; o_j, s_j²); 0 for clutter."""
    out = np.zeros(t.size)
    beat = followed.beat
    for kind, structure in enumerate(followed.structure):
        for j, impact in enumerate(structure.impacts):
            mine = (followed.impact == j) & (np.mod(beat, 2) == kind) & (beat >= 0)
            if mine.any():
                offset = t[mine] - followed.timing.predict(beat[mine])
                out[mine] = impact.presence * normal_density(offset, impact.offset, impact.spread)
    return out

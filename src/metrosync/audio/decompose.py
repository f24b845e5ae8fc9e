"""The onsets of a recording explained as metronomes and clutter.

The model. A recording's onsets are the impacts of M metronomes' ticks, each metronome
a timing model with its learned tick (`structure`), plus clutter. M and the metronomes
are found by matching pursuit: the periodicity search (`periodicity`) proposes tempi
among the onsets not yet explained; the metronome at the likeliest tempo is followed
(`structure.follow`); it is kept if it explains enough of the recording to be a
metronome (its main impact heard in `MODEL.heard_share` of its beats, over at least
`MODEL.min_beats` beats), its onsets are set aside, and the search runs again on the rest, until no
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

from dataclasses import dataclass, replace

import numpy as np

from ..errors import AnalysisError
from .periodicity import candidate_tempi
from .settings import MODEL
from .sounds import Sounds, learn_sounds
from .structure import Followed, explained_by, follow
from .tempo import HINT_RANGE

#: Most metronomes sought (a bound on the search, not an assumption of the model).
MAX_METRONOMES = 8
#: Share of a metronome's ticks that another explains, beyond which it is no metronome.
REDUNDANT = 0.5
#: A metronome followed at twice the tempo found that hears more than this many times
#: its ticks is the metronome, the one found its half tempo (which hears half of them).
HALF_TEMPO = 1.5
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


def decompose(times, strengths=None, bpm_range=MODEL.bpm_range, channel_levels=None,
              features=None) -> tuple[list[Heard], np.ndarray]:  # fmt: skip
    """Metronomes that explain the sorted onset ``times`` (s), with their ``strengths``
    (dB, optional: they tell a strike from a bounce as regular as it), and each onset's
    owner. ``channel_levels`` (K, C), dB, each onset's level at each microphone
    (optional): the impacts of one tick come from one place (`elsewhere`).
    ``features`` (K, D), each onset's sound (`voices.Features.matrix`, optional): an
    onset that sounds like another metronome is not followed as this one's (`sounds`)."""
    t = np.asarray(times, dtype=float)
    level = None if strengths is None else np.asarray(strengths, dtype=float)
    place = _placement(channel_levels)
    owner = np.full(t.size, -1)
    metronomes: list[Heard] = []
    starts: list[float] = []  # the tempo each was first followed from, which worked
    while len(metronomes) < MAX_METRONOMES:
        free = np.flatnonzero(owner < 0)
        kept = _likeliest(t, level, free, bpm_range)
        if kept is None:
            break
        start, heard = kept
        # an impact heard from another place is another metronome's tick, left for the
        # search to find as one
        mine = (heard.followed.impact >= 0) & ~elsewhere(heard, place)
        owner[heard.pool[mine]] = len(metronomes)
        metronomes.append(heard)
        starts.append(start)
    # each refollowed on all but the others' ticks as the pursuit found them: on every
    # onset, two metronomes of one tempo would both lock on the one found first
    mains = _mains_of(metronomes, t.size)
    for _ in range(PASSES):
        sounds = None
        if features is not None:
            ticks, kinds = [h.ticks for h in metronomes], [np.mod(h.beats, 2) for h in metronomes]
            sounds = learn_sounds(features, ticks, kinds, t)
        metronomes, owner, tempi = _refollow(t, level, starts, metronomes, mains, bpm_range,
                                             sounds)  # fmt: skip
        kept = _without_redundant(metronomes, t.size)
        tempi = [tempi[m] for m in kept]
        metronomes = [metronomes[m] for m in kept]
        now = _mains_of(metronomes, t.size)
        settled = tempi == starts and np.array_equal(now, mains)
        starts, mains = tempi, now
        if settled:
            break  # the same ticks set aside: another pass would follow the same
    metronomes, owner = one_tick_an_onset(t, metronomes, owner)
    order = np.argsort([m.followed.timing.period for m in metronomes])[::-1]
    relabel = np.full(len(metronomes) + 1, -1)
    relabel[order] = np.arange(order.size)
    return [metronomes[i] for i in order], np.where(owner >= 0, relabel[owner], -1)


def one_tick_an_onset(t: np.ndarray, heard: list[Heard], owner: np.ndarray):
    """(``heard`` with every metronome's fitted model explaining all the onsets
    (`structure.explained_by`), each onset that times a metronome's beat left to it
    only where that metronome is the likeliest to have made it (`belonging`), and each
    onset's owner again): one onset is one impact, and where it is another's, this
    metronome's tick on that beat was hidden behind it (not heard)."""
    if not heard:
        return heard, owner
    every = np.arange(t.size)
    heard = [Heard(explained_by(t, h.followed), every) for h in heard]
    likeliest = np.argmax(belonging(t, heard, owner), axis=0)
    heard = [
        Heard(replace(h.followed, main=h.followed.main & (likeliest == m)), every)
        for m, h in enumerate(heard)
    ]
    kept = [h for h in heard if _is_metronome(h.followed)]
    if len(kept) < len(heard):  # one left with too few ticks of its own is none
        return one_tick_an_onset(t, kept, owner)
    explained = np.any([h.followed.impact >= 0 for h in heard], axis=0)
    return heard, np.where(explained, likeliest, -1)


def _mains_of(heard: list[Heard], k: int) -> np.ndarray:
    """(K,) the metronome whose tick each onset is (−1: none)."""
    mains = np.full(k, -1)
    for m, h in enumerate(heard):
        mains[h.ticks] = m
    return mains


def belonging(times, heard: list[Heard], owner: np.ndarray) -> np.ndarray:
    """(M, K) the probability that each onset is metronome m's (an impact of its tick),
    from the model's intensities: λ_m(t) / (Σ_m' λ_m'(t) + λ_c), where the clutter's
    intensity λ_c is its onsets (``owner`` −1) per second of the recording, spread
    evenly. The rest of each column is the probability that the onset is clutter."""
    t = np.asarray(times, dtype=float)
    if not heard or not t.size:
        return np.zeros((len(heard), t.size))
    rate = np.stack([h.followed.intensity(t) for h in heard])
    span = max(float(t[-1] - t[0]), 1.0)
    clutter = max(int(np.sum(owner < 0)), 1) / span
    return rate / (rate.sum(axis=0) + clutter)


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


def _placement(channel_levels) -> np.ndarray | None:
    """(K, C) each onset's level at each microphone less its mean over them, dB: where
    it came from, whatever its loudness (None with one microphone)."""
    if channel_levels is None:
        return None
    levels = np.asarray(channel_levels, dtype=float)
    if levels.ndim != 2 or levels.shape[1] < 2:
        return None
    return levels - levels.mean(axis=1, keepdims=True)


def elsewhere(heard: Heard, place: np.ndarray | None) -> np.ndarray:
    """(len(pool),) True for the onsets of an impact of ``heard``'s tick heard from
    another place than its main impact. The impacts of one tick come from one
    metronome, so their levels at the microphones differ alike; two metronomes of one
    tempo locked at a fixed offset are, in timing, one tick of two impacts, and only
    where they are heard from tells them apart. An impact is elsewhere where its mean
    placement differs from the main impact's by more than `MODEL.place_db` and by more than
    four standard errors of the difference."""
    out = np.zeros(heard.pool.size, dtype=bool)
    if place is None:
        return out
    f = heard.followed
    at = place[heard.pool]
    for kind, structure in enumerate(f.structure):
        kind_of = (np.mod(f.beat, 2) == kind) & (f.beat >= 0)
        main = at[kind_of & (f.impact == structure.main)]
        for j in range(len(structure.impacts)):
            if j == structure.main:
                continue
            mine = kind_of & (f.impact == j)
            other = at[mine]
            if other.shape[0] < 4 or main.shape[0] < 4:
                continue
            gap = np.abs(other.mean(axis=0) - main.mean(axis=0))
            error = np.sqrt(other.var(axis=0) / other.shape[0] + main.var(axis=0) / main.shape[0])
            if np.any((gap > MODEL.place_db) & (gap > 4 * error)):
                out |= mine
    return out


def _likeliest(t: np.ndarray, level, free: np.ndarray, bpm_range):
    """(the tempo it was followed from, the `Heard`) of the first candidate among the
    onsets ``free`` that is a metronome, strongest first; None when none is."""
    if free.size < MODEL.min_beats:
        return None
    for candidate in candidate_tempi(t[free], bpm_range=bpm_range):
        followed = _metronome(t[free], candidate.bpm, _part(level, free))
        if followed is None:
            continue
        bpm, followed = _at_its_tempo(
            t[free], candidate.bpm, followed, _part(level, free), bpm_range
        )
        return bpm, Heard(followed, free)
    return None


def _at_its_tempo(t: np.ndarray, bpm: float, followed: Followed, level, bpm_range=MODEL.bpm_range):
    """(the tempo, the metronome): ``followed`` at ``bpm``, or, where it is a metronome
    at half its tempo, the one at twice ``bpm``. At half its tempo a metronome is a
    metronome too, on every other beat, its other ticks left over; followed at twice
    the tempo it hears twice the ticks, where a metronome at its own tempo followed at
    twice hears no more (`HALF_TEMPO`)."""
    while 2.0 * bpm <= bpm_range[1]:
        # from its timing at half the tempo, not afresh: other metronomes' ticks can
        # hide one kind's for the first stretch a fresh timing is fitted on
        faster = _metronome(t, 2.0 * bpm, level, start=followed.timing.doubled())
        if faster is None or faster.main.sum() <= HALF_TEMPO * followed.main.sum():
            break
        bpm, followed = 2.0 * bpm, faster  # and a quarter of its tempo is half of half
    return bpm, followed


def _part(level, index):
    return None if level is None else level[index]


def _metronome(t: np.ndarray, bpm: float, level=None, start=None, refind=False
               ) -> Followed | None:  # fmt: skip
    """The metronome followed from ``bpm`` (or the timing ``start``) among onsets ``t``,
    if it is one (``refind`` as `follow` takes it)."""
    try:
        followed = follow(t, bpm, level, start=start, refind=refind)
    except AnalysisError:
        return None
    return followed if _is_metronome(followed) else None


def _is_metronome(followed: Followed) -> bool:
    """Its main impact heard in `MODEL.heard_share` of its beats, over `MODEL.min_beats`
    at least."""
    beats = followed.beat[followed.main]
    if beats.size < 2:
        return False
    span = int(beats.max() - beats.min()) + 1
    return span >= MODEL.min_beats and beats.size >= MODEL.heard_share * span


def _refollow(t: np.ndarray, level, starts: list[float], before: list[Heard], mains,
              bpm_range=MODEL.bpm_range, sounds: Sounds | None = None):  # fmt: skip
    """(the metronomes, each onset's owner, the tempo each was followed from): each
    metronome followed again, from the tempo it was first followed from (or twice it
    within ``bpm_range``, `_at_its_tempo`), on every onset but the other metronomes'
    ticks (``mains``: (K,) the metronome whose tick each onset is, −1 for none), keeping
    its last model where that fails; an onset two metronomes explain goes to the one
    whose learned tick makes it likelier (`_density`). With their ``sounds`` learned,
    an onset that sounds like another metronome is not this one's, and one that sounds
    like this one is, whoever's tick the pursuit made it."""
    heard: list[Heard] = []
    tempi = list(starts)
    density = np.zeros((len(starts), t.size))
    for m, bpm in enumerate(starts):
        free = (mains < 0) | (mains == m)
        refind = False
        if sounds is not None:
            twins = _twins(t, before, sounds, m)
            free = (free | np.isin(mains, twins) | sounds.mine(m)) & ~sounds.others(m)
            refind = bool(twins) or sounds.told_apart(m, [h.ticks for h in before])
        pool = np.flatnonzero(free)
        followed = _metronome(t[pool], bpm, _part(level, pool), refind=refind)
        if followed is not None:
            tempi[m], followed = _at_its_tempo(
                t[pool], bpm, followed, _part(level, pool), bpm_range
            )
        one = before[m] if followed is None else Heard(followed, pool)
        density[m, one.pool] = _density(t[one.pool], one.followed)
        heard.append(one)
    if not heard:
        return [], np.full(t.size, -1), tempi
    owner = np.where(density.max(axis=0) > 0, np.argmax(density, axis=0), -1)
    for m, one in enumerate(heard):  # a tick is its metronome's, however far off its beat
        ticks = one.ticks
        owner[ticks[owner[ticks] < 0]] = m
    return heard, owner, tempi


def _twins(t: np.ndarray, heard: list[Heard], sounds: Sounds, m: int) -> list[int]:
    """The metronomes that may be m itself, lost for a while and found again as
    another: of its sound (not told apart from it, `Sounds.others`), near its tempo
    (`HINT_RANGE`), heard only before its first tick or after its last."""
    mine = heard[m].ticks
    out = []
    for j, other in enumerate(heard):
        if j == m or not other.ticks.size or not mine.size:
            continue
        alike = (np.mean(sounds.others(m)[other.ticks]) < 0.5
                 and np.mean(sounds.others(j)[mine]) < 0.5)  # fmt: skip
        near = abs(other.followed.timing.bpm / heard[m].followed.timing.bpm - 1) <= HINT_RANGE
        apart = t[other.ticks].min() > t[mine].max() or t[other.ticks].max() < t[mine].min()
        if alike and near and apart:
            out.append(j)
    return out


def _density(t: np.ndarray, followed: Followed) -> np.ndarray:
    """(K,) the density (1/s) of each onset under the impact that explains it, weighted
    by how often that impact is heard (`Structure.log_density`); 0 for clutter."""
    out = np.zeros(t.size)
    beat = followed.beat
    for kind, structure in enumerate(followed.structure):
        for j in range(len(structure.impacts)):
            mine = (followed.impact == j) & (np.mod(beat, 2) == kind) & (beat >= 0)
            if mine.any():
                offset = t[mine] - followed.timing.predict(beat[mine])
                out[mine] = np.exp(structure.log_density(j, offset))
    return out

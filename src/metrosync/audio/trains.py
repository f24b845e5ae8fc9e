"""From impacts to metronomes: impacts grouped into ticks, ticks followed as trains.

Contract:

* `group_impacts(times, voices)` → (first (K,) bool, gap (V,)): True for the impact
  that starts a tick; the later impacts of one tick are folded into it.
* `track(times, own, period)` → `Train`: one metronome's ticks, followed beat by beat
  from a seed through the whole recording.
* `trains_of_voice(times, own, period)` → the `Train` s of one voice: one per
  metronome that sounds like it, told apart by their tempo and phase.
* `join_fragments(times, trains, voices)`: trains that are pieces of one metronome's
  beat (its tick and its tock when they sound different, or every third tick heard in
  one voice and the rest in another) become one.

A tick is one event. A real tick is a main impact and one to three more 15–35 ms
later, ringing for tens of milliseconds. How far a tick reaches is read from the
recording itself: among the impacts of one voice, the differences between each impact
and the later ones up to `MAX_TICK_LENGTH` pile up, above the level unrelated
impacts at the same rate would give, at the lags of the tick's own later impacts.
The last lag bin where they do (at least `MIN_SHARE_LATE` of the impacts) bounds the
tick: an impact of the same voice that follows a tick's first impact within that
gap belongs to it. The tick's time is its first impact, even where the first impact
sounds unlike the later ones and the train was followed on a later one
(`first_impacts`).

Following a train. A seed tick's successor one beat later is the one whose multiples
(2 to 6 beats on) are also heard; the train then goes on beat by beat: the next tick
is predicted one full swing (two beats: a tick and a tock, so an uneven beat does not
matter) after the tick two beats back, or one beat after the last tick, and the
nearest tick of the voice within `SWING_TOLERANCE` (resp. `BEAT_TOLERANCE`) of the
beat is taken. A beat where the voice has none takes the nearest impact of any voice
within `MASKED_TOLERANCE`: one tick can hide another that falls on it. The beat is
updated from each full swing, so that a metronome that slowly speeds up is followed.
After `MAX_MISSING` beats without a tick the train is sought again from a new seed.
Trains are followed backwards from the seed in the same way.

Two metronomes of one sound. The train found first takes its ticks; from what is left
the next train is sought, and so on: two metronomes 4 BPM apart share a sound but not a
beat. A train with fewer than `MIN_COVERAGE` of its beats heard is not a metronome.
A train found first on every few beats of a metronome takes those ticks, and the
metronome's train, found after it, can hold them only as hidden by another's; once
the first is dropped (`drop_shared`: most of its ticks were the other's), they are
the metronome's own again (`own_again`).

Pieces of one metronome. A metronome whose tick and tock sound different is heard as
two voices, each ticking once per swing; ringing and overlaps can split its ticks
among voices in other patterns too. Two trains are one metronome when both periods
are whole multiples (up to `MAX_FRAGMENT`) of one beat T ≥ 0.2 s (within 1 %), and
the second's ticks fall on the first's grid of beats T (circular spread below
2 × `LOCKED_SPREAD` of a beat, within `OFF_GRID` of the grid: a limp, drifting on
it by under `MAX_DRIFT` of a beat over their shared time: two metronomes of nearly
one tempo drift by more), almost never (10 %) within 0.3 T of the first's own ticks
(a tick both hold is one tick, heard on both grids: every 2nd beat and every 3rd
meet on every 6th; but at most half of the second's ticks), and the two leave no
kind of beat of that grid (its number modulo their common cycle) where hardly any
tick is heard, or hidden just behind another's: metronomes at a whole-number ratio of
tempo (4:3) lie on one grid too, and never sound on some of its beats;
or when one takes up the other's beat (the same period, or a whole multiple of it,
within 1 %, its first tick a whole number of beats, at most `MAX_BRIDGED`, within
`OFF_GRID`, after the other's last). Two ticks of the joined pieces within half a beat and
`MAX_TICK_LENGTH` are one (a tick and its later impact); two within half a beat but
farther apart are another metronome's sound on that beat, and the pieces are not
one. Of the pieces that could join a train, the one nearest its grid joins: two
metronomes of one tempo, each heard as a tick and a tock voice, fit either's tock to
either's tick, and a metronome is set in beat within a few per cent. (Two metronomes
locked a whole number of beats apart at whole-number ratios of tempo would be taken
for one; synchronized metronomes tick together, on each other's ticks.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np

#: Longest a tick's later impacts are sought after its first one, s. The analysis's
#: own assumption about a tick (the lags are read from the recording up to it), set
#: for the synthetic voices' later impacts (15-35 ms) and ring (70-90 ms); the coming
#: timing model is to learn a metronome's impacts, before the loud one too.
MAX_TICK_LENGTH = 0.09
LAG_BIN = 2e-3
MIN_SHARE_LATE = 0.05
#: A tick's onset is its first impact at most this much (dB) below its loudest.
ONSET_DROP = 20.0
SWING_TOLERANCE = 0.03
BEAT_TOLERANCE = 0.10
MASKED_TOLERANCE = 4e-3
MAX_MISSING = 6
MIN_COVERAGE = 0.5
LOCKED_SPREAD = 0.04
#: Largest multiple of a metronome's beat that a piece of its train may tick at.
MAX_FRAGMENT = 6
#: Most beats between a train's end and a train that takes up its beat.
MAX_BRIDGED = 64
#: Farthest a piece's ticks lie off the other piece's grid (beats): a limp; and a
#: train that takes up another's beat, off the grid laid from the other's last tick.
OFF_GRID = 0.15
#: Where a train taking up another's beat ranks among joins, as if as far off the
#: grid as it may lie: after every pair of pieces that share a grid.
CONTINUED = OFF_GRID
#: Largest drift (beats) of one piece of a metronome's train on another's grid over
#: the time they share: two metronomes under 1 % apart in tempo drift by more.
MAX_DRIFT = 0.05
#: Largest spread (s) of the lag of a train that is part of another's ticks.
PART_LAG_SPREAD = 0.3e-3
#: ... and of one that comes after it and is this much fainter (dB): a later impact,
#: timed in the first one's ring, less precisely (twice the spread allowed).
LATER_FAINTER = 3.0
#: A train this much fainter (dB) than another, at a fixed lag after it, is its echo
#: or a last faint impact, however long the lag (within the other's beat).
ECHO_FAINTER = 12.0
#: A tick farther than this from its train's beat is not its metronome's, s.
OFF_BEAT = 3e-3
#: Ticks of one kind on each side that put a tick where its beat is.
NEIGHBOURS = 3
#: Fits of a train's beat to the half of its ticks nearest it, at most (`off_the_beat`).
REFITS = 5
#: Ticks more on its beat that a fit begun from a third of a train needs to be taken
#: over the fit begun from all of it (`off_the_beat`): with fewer, the two are as good.
MORE_ON_THE_BEAT = 3
#: Beats searched for a seed's successor, s (300 to 30 BPM).
BEAT_RANGE = (0.2, 2.0)
#: A kind of beat that two pieces of one metronome leave to others is heard at least
#: this share of its places (within this share of a beat), held or not.
HEARD_SILENT = 0.5
SILENT_WINDOW = 0.04
#: ... or where another's tick began up to this long before (s): its impacts and ring
#: can hide one.
HIDING = 0.045


@dataclass(frozen=True)
class Train:
    """One metronome's ticks.

    index : (M,) indices into the tick array, in time order.
    beat : (M,) beat number of each (0 for the first; gaps where beats were missed).
    period : mean beat, s.
    masked : (M,) True where the tick was taken from another voice (hidden by it).
    """

    index: np.ndarray
    beat: np.ndarray
    period: float
    masked: np.ndarray

    @property
    def coverage(self) -> float:
        """Share of the beats from the first tick to the last that were heard."""
        return self.index.size / (self.beat[-1] + 1) if self.index.size else 0.0


def group_impacts(
    times: np.ndarray, voices: np.ndarray, strength: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(first (K,) bool, gap (V,) s): see the module docstring. Impacts of no voice
    (−1) that fall within a tick's gap are folded into it too. With ``strength`` (K,),
    dB, a tick's onset is its first impact within `ONSET_DROP` of its loudest: a
    faint sound just ahead of a tick (a lossy coder's pre-echo) does not time it."""
    times = np.asarray(times, dtype=float)
    k = times.size
    first = np.ones(k, dtype=bool)
    count = int(voices.max()) + 1 if k else 0
    gaps = np.zeros(max(count, 0))
    span = max(times[-1] - times[0], 1e-9) if k else 1.0
    for v in range(count):
        mine = np.flatnonzero(voices == v)
        gap = tick_length(times[mine], span)
        gaps[v] = gap
        if gap <= 0:
            continue
        start = -np.inf
        group: list[int] = []
        for i in [*mine, -1]:
            if i >= 0 and times[i] - start <= gap:
                group.append(i)
                continue
            if strength is not None and len(group) > 1:
                loud = strength[group]
                onset = group[int(np.argmax(loud >= loud.max() - ONSET_DROP))]
                first[group] = False
                first[onset] = True
            elif group:
                first[group[1:]] = False
            if i >= 0:
                start, group = times[i], [i]
    # strays right after a tick of any voice belong to that tick
    if count and (voices < 0).any():
        heads = np.flatnonzero(first & (voices >= 0))
        for i in np.flatnonzero(voices < 0):
            j = np.searchsorted(times[heads], times[i], side="right") - 1
            if j >= 0 and times[i] - times[heads[j]] <= gaps[voices[heads[j]]]:
                first[i] = False
    return first, gaps


def tick_length(times: np.ndarray, span: float) -> float:
    """How far one tick of this voice reaches, s (0: one impact per tick)."""
    k = times.size
    if k < 8:
        return 0.0
    bins = np.arange(0.0, MAX_TICK_LENGTH + LAG_BIN, LAG_BIN)
    ends = np.searchsorted(times, times + MAX_TICK_LENGTH, side="right")
    lags = [times[i + 1 : ends[i]] - times[i] for i in range(k) if ends[i] > i + 1]
    if not lags:
        return 0.0
    counts = np.histogram(np.concatenate(lags), bins)[0]
    expected = k * (k / span) * LAG_BIN
    excess = counts >= np.maximum(MIN_SHARE_LATE * k, expected + 4 * math.sqrt(expected) + 1)
    if not excess.any():
        return 0.0
    return float(bins[np.flatnonzero(excess)[-1] + 1] + LAG_BIN)


def _nearest(times: np.ndarray, pool: np.ndarray, target: float) -> tuple[int, float]:
    """(index into times of the nearest of ``pool`` (sorted indices) to target, distance)."""
    if pool.size == 0:
        return -1, math.inf
    j = np.searchsorted(times[pool], target)
    best, dist = -1, math.inf
    for c in (j - 1, j):
        if 0 <= c < pool.size:
            d = abs(times[pool[c]] - target)
            if d < dist:
                best, dist = int(pool[c]), d
    return best, dist


def _walk(t: np.ndarray, p: int, d: float, beats: int = 6) -> tuple[int, float, float]:
    """(hits, mean error (s) where a swing predicted, beat) of a short walk from t[p]
    with a first beat d: once a full swing has been heard, each tick is predicted one
    swing after the tick two beats back; the beat returned is half the last swing."""
    when = [t[p]]
    hits, err, last, swing = 0, 0.0, 0, 2 * d
    for n in range(1, beats + 1):
        by_swing = n >= 3 and when[n - 2] is not None
        if by_swing:
            target, tol = when[n - 2] + swing, SWING_TOLERANCE * d
        else:
            target, tol = when[last] + (n - last) * 0.5 * swing, BEAT_TOLERANCE * d
        j = int(np.clip(np.searchsorted(t, target), 1, t.size - 1))
        c = j if abs(t[j] - target) < abs(t[j - 1] - target) else j - 1
        e = abs(t[c] - target)
        if e <= tol:
            when.append(t[c])
            hits += 1
            err += e if by_swing else 0.0  # an uneven beat is not an error
            last = n
            if when[n - 2] is not None and n >= 2:
                swing = t[c] - when[n - 2]
        else:
            when.append(None)
    return hits, err / max(hits, 1), 0.5 * swing


def _seed(times, own_idx, start: int, beat_range=BEAT_RANGE):
    """(position in own_idx, beat) of the first tick from ``start`` on with a steady
    successor one beat (in ``beat_range``, s) later, or None."""
    t = times[own_idx]
    lo, hi = beat_range
    for p in range(start, own_idx.size):
        cand = np.flatnonzero((t > t[p] + lo) & (t < t[p] + hi))[:64]
        if cand.size == 0:
            continue
        walks = [_walk(t, p, t[c] - t[p]) for c in cand]
        most = max(w[0] for w in walks)
        if most < 5:
            continue
        best_err = min(w[1] for w in walks if w[0] == most)
        # the shortest beat that walks as well: twice the beat walks too
        fit = [w[2] for w in walks if w[0] == most and w[1] <= best_err + max(3e-3, 0.02 * w[2])]
        return p, min(fit)
    return None


def _follow(times, own_idx, other_idx, seed_pos, beat, end_time):
    """Follow forwards from own_idx[seed_pos]: dict beat number → (index, masked)."""
    got = {0: (int(own_idx[seed_pos]), False)}
    when = {0: times[own_idx[seed_pos]]}
    last, n, period = 0, 1, beat
    while n - last <= MAX_MISSING:
        if n - 2 in when:
            predicted, tol = when[n - 2] + 2 * period, SWING_TOLERANCE * period
        else:
            predicted = when[last] + (n - last) * period
            tol = BEAT_TOLERANCE * period
        if predicted > end_time + tol:
            break
        i, d = _nearest(times, own_idx, predicted)
        masked = False
        if d > tol:
            i, d = _nearest(times, other_idx, predicted)
            masked = True
            if d > MASKED_TOLERANCE:
                i = -1
        if i >= 0:
            got[n] = (i, masked)
            when[n] = times[i]
            if n - 2 in when and not masked:
                swing = 0.5 * (when[n] - when[n - 2])
                if abs(swing - period) < SWING_TOLERANCE * period:
                    period += 0.2 * (swing - period)
            last = n
        n += 1
    return got, period


def track(times, own, *, others=None, start: int = 0, beat_range=BEAT_RANGE):
    """The `Train` through one seed at or after own[start] (see the module docstring).

    times : (K,) all tick times, sorted. own : (P,) sorted indices of the voice's ticks
    not yet taken. others : sorted indices of ticks a masked beat may take.
    Returns (Train or None, position in ``own`` after the seed).
    """
    times = np.asarray(times, dtype=float)
    own = np.asarray(own, dtype=np.int64)
    others = np.zeros(0, dtype=np.int64) if others is None else np.asarray(others, np.int64)
    found = _seed(times, own, start, beat_range)
    if found is None:
        return None, own.size
    pos, beat = found
    end, begin = times[-1], times[0]
    fwd, period_f = _follow(times, own, others, pos, beat, end)
    # backwards: the same on mirrored time
    mirror = -times[::-1]
    rev = lambda idx: (times.size - 1 - idx)[::-1]  # noqa: E731
    r_own, r_others = rev(own), rev(others)
    r_pos = int(np.flatnonzero(r_own == times.size - 1 - own[pos])[0])
    bwd, _ = _follow(mirror, r_own, r_others, r_pos, beat, -begin)
    beats = {n: v for n, v in fwd.items()}
    for n, (i, m) in bwd.items():
        if n > 0:
            beats[-n] = (times.size - 1 - i, m)
    numbers = np.array(sorted(beats))
    index = np.array([beats[n][0] for n in numbers], dtype=np.int64)
    masked = np.array([beats[n][1] for n in numbers], dtype=bool)
    keep = np.concatenate([[True], np.diff(index) > 0])  # one tick never serves two beats
    numbers, index, masked = numbers[keep], index[keep], masked[keep]
    numbers = numbers - numbers[0]
    span = times[index[-1]] - times[index[0]]
    mean_beat = span / numbers[-1] if numbers[-1] > 0 else period_f
    return Train(index, numbers, float(mean_beat), masked), pos + 1


def trains_of_voice(
    times, own, *, others=None, min_ticks: int = 8, beat_range=BEAT_RANGE
) -> list[Train]:
    """Every metronome heard in one voice's ticks ``own`` (sorted indices into times),
    its first beat sought in ``beat_range`` (s)."""
    left = np.asarray(own, dtype=np.int64)
    out: list[Train] = []
    start = 0
    while left.size >= min_ticks and start < left.size:
        train, start = track(times, left, others=others, start=start, beat_range=beat_range)
        if train is None:
            break
        if train.index.size < min_ticks or train.coverage < MIN_COVERAGE:
            continue
        out.append(train)
        taken = train.index[~train.masked]
        left = left[~np.isin(left, taken)]
        others = np.union1d(others if others is not None else [], taken).astype(np.int64)
        start = 0
    return out


def drop_shared(trains: list[Train], voice: list[int]) -> tuple[list[Train], list[int]]:
    """Trains that are mostly masked ticks, their own or taken by other trains, are
    dropped: two metronomes that tick together make a sound of their own, a voice that
    is neither."""
    own = [t.masked.mean() < 0.5 for t in trains]  # a train of borrowed ticks is none
    trains = [t for t, k in zip(trains, own, strict=True) if k]
    voice = [v for v, k in zip(voice, own, strict=True) if k]
    keep = []
    for a, t in enumerate(trains):
        taken = np.zeros(t.index.size, dtype=bool)
        for b, u in enumerate(trains):
            if b != a:
                taken |= np.isin(t.index, u.index[u.masked])
        keep.append(taken.mean() < 0.5)
    return ([t for t, k in zip(trains, keep, strict=True) if k],
            [v for v, k in zip(voice, keep, strict=True) if k])  # fmt: skip


def own_again(trains: list[Train], voice: list[int], labels: np.ndarray) -> list[Train]:
    """Each train's ticks of its own voice that it holds as taken from another train
    (a train of that voice took them first, and `drop_shared` dropped it), its own
    again where no other train holds them at all. Counted as borrowed they made a
    metronome whose tick took two sounds look like pieces of a voice split by chance
    (unseen corpus seed 4/432: 42 % of one train's ticks, all of its own voice, taken
    first by two trains at a quarter and a fifth of its tempo)."""
    claims = np.zeros(labels.size, dtype=np.int64)
    for t in trains:
        claims[t.index] += 1
    out = []
    for t, v in zip(trains, voice, strict=True):
        mine = t.masked & (labels[t.index] == v) & (claims[t.index] == 1)
        out.append(replace(t, masked=t.masked & ~mine) if mine.any() else t)
    return out


def holders(k: int, trains: list[Train]) -> np.ndarray:
    """(K,) the train that holds each of ``k`` ticks as its own: the one train that holds
    it unmasked, or, where none does, the one train that holds it at all; −1 for none,
    or two (their ticks fell together). A train that holds a tick masked took it from
    the metronome whose tick hid its own."""
    own = np.zeros(k, dtype=np.int64)
    claims = np.zeros(k, dtype=np.int64)
    for t in trains:
        claims[t.index] += 1
        own[t.index[~t.masked]] += 1
    out = np.full(k, -1, dtype=np.int64)
    for m, t in enumerate(trains):
        unmasked = t.index[~t.masked]
        out[unmasked[own[unmasked] == 1]] = m
        masked = t.index[t.masked]
        out[masked[(own[masked] == 0) & (claims[masked] == 1)]] = m
    return out


def with_ticks(train: Train, index: np.ndarray, beat: np.ndarray, masked=None) -> Train:
    """``train`` with the ticks ``index`` added on its beats ``beat``, in beat order;
    each held as its own unless ``masked`` says it was taken from another voice."""
    if masked is None:
        masked = np.zeros(index.size, dtype=bool)
    number = np.concatenate([train.beat, beat])
    order = np.argsort(number, kind="stable")
    return Train(np.concatenate([train.index, index])[order], number[order], train.period,
                 np.concatenate([train.masked, masked])[order])  # fmt: skip


def fold_parts(times: np.ndarray, trains: list[Train], voice: list[int], strength=None):
    """Trains that are part of another's ticks, folded into it: (trains, voices,
    indices of the folded ticks).

    A train B is part of a train A when B's ticks keep a fixed lag (spread below
    `PART_LAG_SPREAD`), within `MAX_TICK_LENGTH`, to A's, and either B's period is a
    multiple (2 or more) of A's (a sound ahead of or after every few ticks: the
    pre-echo a lossy coder smears ahead of a click, so fainter than the ticks it comes
    before: one louder is their first impact, A's train having taken a later one; corpus
    seed 209) or it is A's period, B comes after
    A and is fainter (``strength`` (K,), dB): a later impact of each tick that sounds
    different from the first. A later impact at least `LATER_FAINTER` dB fainter is
    timed in the first one's ring: its lag may spread twice as much (an echo beyond
    the ring keeps the room's one delay, as a tock far fainter than its tick does not:
    it moves with the metronome's beat). One at least
    `ECHO_FAINTER` dB fainter is part of A at any lag within A's beat (a room's echo, a
    last faint impact beyond `MAX_TICK_LENGTH`), its lag taken from A's tick before it
    (more than half a beat on, it lies nearer A's next tick). Two metronomes locked a few
    milliseconds apart keep a lag that wanders by more than that, as each one's beat
    jitters.
    """
    trains = list(trains)
    keep = [True] * len(trains)
    folded = []
    for b, tb in enumerate(trains):
        for a, ta in enumerate(trains):
            if a == b or not keep[a]:
                continue
            ratio = tb.period / ta.period
            k = round(ratio)
            if k < 1 or abs(ratio - k) > 0.01 * k:
                continue
            t_a, t_b = times[ta.index], times[tb.index]
            j = np.clip(np.searchsorted(t_a, t_b), 1, t_a.size - 1)
            nearer = np.where(np.abs(t_a[j] - t_b) < np.abs(t_a[j - 1] - t_b), j, j - 1)
            lag = t_b - t_a[nearer]
            drop = (
                float(np.mean(strength[ta.index]) - np.mean(strength[tb.index]))
                if strength is not None
                else 0.0
            )
            if drop >= ECHO_FAINTER:
                # an echo follows its tick, maybe by more than half a beat: its lag is
                # from the tick before it, not the nearest
                before = np.searchsorted(t_a, t_b, side="right") - 1
                lag = np.where(before >= 0, t_b - t_a[np.maximum(before, 0)], lag)
            middle = float(np.median(lag))
            # a later impact in the ring is timed less precisely; an echo beyond it keeps
            # the room's one delay, where a tock far fainter than its tick moves with the
            # metronome's beat
            ring = 0 < middle < MAX_TICK_LENGTH and drop > LATER_FAINTER
            limit = 2 * PART_LAG_SPREAD if ring else PART_LAG_SPREAD
            echo = middle > 0 and drop >= ECHO_FAINTER
            if (abs(middle) >= MAX_TICK_LENGTH and not echo) or robust_spread(lag) >= limit:
                continue
            if k == 1 and (middle <= 0 or strength is None or drop <= 1.0):
                continue
            if k > 1 and middle < 0 and strength is not None and np.mean(
                strength[tb.index]) >= np.mean(strength[ta.index[nearer]]):  # fmt: skip
                trains[a], later = _first_impacts_taken(times, ta, tb, nearer, lag, middle, limit)
                keep[b] = False
                folded.append(later)
                break
            keep[b] = False
            folded.append(tb.index[~tb.masked])
            break
    return ([t for t, k in zip(trains, keep, strict=True) if k],
            [v for v, k in zip(voice, keep, strict=True) if k], folded)  # fmt: skip


def _first_impacts_taken(times, ta: Train, tb: Train, nearer, lag, middle: float, limit: float):
    """(A with B's ticks in place of the ticks of A's that each comes before at the
    usual lag ``middle``, and B's other ticks on the beats where A had none or held
    only another's tick that hid its own (corpus seed 4/209, at the file's start);
    the ticks of A's so replaced): B, louder and ahead of every k-th of A's ticks at a
    fixed lag, is their first impact, where A's train took a later one (or, once
    another's tick hid it, none)."""
    paired = np.abs(lag - middle) <= 3 * limit
    at, first = np.unique(nearer[paired], return_index=True)
    taken = np.flatnonzero(paired)[first]
    index, masked = ta.index.copy(), ta.masked.copy()
    later = index[at]
    index[at], masked[at] = tb.index[taken], tb.masked[taken]
    # the rest of B's ticks on the beats of A's they come before, where A has no tick
    rest = np.setdiff1d(np.arange(tb.index.size), taken)
    ref = nearer[rest]
    number = ta.beat[ref] + np.round((times[tb.index[rest]] - middle - times[ta.index[ref]])
                                     / ta.period).astype(ta.beat.dtype)  # fmt: skip
    new, once = np.unique(number, return_index=True)
    rest = rest[once]
    # and where A holds only another's tick that hid its own, B's tick heard there
    hidden = np.isin(new, ta.beat[masked]) & ~tb.masked[rest]
    free = ~np.isin(new, ta.beat) | hidden
    stays = ~(np.isin(ta.beat, new[hidden]) & masked)
    out = with_ticks(Train(index[stays], ta.beat[stays], ta.period, masked[stays]),
                     tb.index[rest[free]], new[free], tb.masked[rest[free]])  # fmt: skip
    # one before A's first tick is beat 0
    return Train(out.index, out.beat - out.beat[0], out.period, out.masked), later


def first_impacts(
    times: np.ndarray, strength: np.ndarray, trains: list[Train], head: np.ndarray
) -> list[Train]:
    """Each train's ticks moved to their first impact: where, for one kind of beat (tick
    or tock), most of a train's ticks follow a louder impact at a fixed lag (spread
    below `PART_LAG_SPREAD`, within `MAX_TICK_LENGTH`) that no train holds, the train
    was built on a later impact of each tick (its first impact sounded different, and
    its voice's train was folded away or never followed). Those ticks are timed at that
    impact instead; ``head`` (K,) is updated in place. A pre-echo comes ahead of a tick
    too, but fainter, and two metronomes a few milliseconds apart keep a lag that
    wanders by more."""
    times = np.asarray(times, dtype=float)
    held = np.zeros(times.size, dtype=bool)
    for t in trains:
        held[t.index] = True
    out = []
    for t in trains:
        index = t.index.copy()
        for parity in (0, 1):
            sel = np.flatnonzero((t.beat % 2 == parity) & ~t.masked)
            if sel.size < 8:
                continue
            mine = times[index[sel]]
            lo = np.searchsorted(times, mine - MAX_TICK_LENGTH)
            hi = np.searchsorted(times, mine - 1e-3, side="right")
            lags, owner = [], []
            for s, (a, b) in enumerate(zip(lo, hi, strict=True)):
                for i in range(a, b):
                    if not held[i]:
                        lags.append(mine[s] - times[i])
                        owner.append(s)
            if len(lags) < 0.5 * sel.size:
                continue
            lags_a = np.asarray(lags)
            bins = np.round(lags_a / 0.5e-3)
            values, counts = np.unique(bins, return_counts=True)
            centre = values[np.argmax(counts)] * 0.5e-3
            near = np.abs(lags_a - centre) <= 1e-3
            if len(set(np.asarray(owner)[near])) < 0.5 * sel.size:
                continue
            lag = float(np.median(lags_a[near]))
            if robust_spread(lags_a[near]) >= PART_LAG_SPREAD:
                continue
            moves = {}
            for s, x in zip(np.asarray(owner)[near], mine[np.asarray(owner)[near]] - lags_a[near],
                            strict=True):  # fmt: skip
                i = int(np.argmin(np.abs(times - x)))
                if abs((mine[s] - times[i]) - lag) <= 1e-3 and s not in moves:
                    moves[s] = i
            earlier = np.array(list(moves.values()))
            if np.median(strength[earlier]) <= np.median(strength[index[sel]]):
                continue
            for s, i in moves.items():
                head[index[sel[s]]] = False
                head[i] = True
                held[i] = True
                index[sel[s]] = i
        out.append(Train(index, t.beat, t.period, t.masked))
    return out


def off_the_beat(times: np.ndarray, beat: np.ndarray) -> np.ndarray:
    """(M,) True for the ticks of one train that lie off its beat: more than `OFF_BEAT`
    (and 5 robust spreads) from a quadratic in the beat number (a steady drift) fitted
    to each kind of beat (tick, tock: a limp) apart (`_from_the_beat`), or, of the
    ticks that fit keeps, from where its `NEIGHBOURS` of the same kind that it keeps
    put it; a later impact taken for a tick where the first was hidden, at the ends of
    a train, would bias its tempo."""
    times = np.asarray(times, dtype=float)
    out = np.zeros(times.size, dtype=bool)
    kinds = [np.flatnonzero(beat % 2 == parity) for parity in (0, 1)]
    kinds = [sel for sel in kinds if sel.size >= 6]
    for sel in kinds:
        deviation = _from_the_beat(beat[sel].astype(float), times[sel])
        limit = max(OFF_BEAT, 5 * 1.4826 * float(np.median(deviation)))
        out[sel] = deviation > limit
    # and from its neighbours: where two metronomes of nearly one tempo drift
    # through each other, a train that took some of the other's ticks bends away
    # from any quadratic, which then hides a tick 10 ms off. A tick the fit finds
    # off the beat has no say (corpus seed 4/210: a tock train's last three ticks,
    # onsets 28-74 ms after its metronome's tocks, put the right tocks before them
    # off their beat, pass by pass, for nine beats)
    for sel in kinds:
        sel = sel[~out[sel]]
        local = times[sel] - _from_neighbours(beat[sel], times[sel])
        inner = np.isfinite(local)
        if inner.sum() >= 4:
            limit = max(OFF_BEAT, 5 * robust_spread(local[inner]))
            out[sel[inner]] |= np.abs(local[inner] - np.median(local[inner])) > limit
    return out


def _from_the_beat(n: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(S,) each tick's distance from its train's beat, a quadratic in the beat number
    ``n``: of the fits begun from all the ticks and from each third of them
    (`_fit_from`), the one most ticks lie within `OFF_BEAT` of. A run of ticks that
    drift off the beat (a train that followed the wrong onsets for a while: its own
    later impacts, others' rings) draws the fit begun from all to itself (corpus seed
    4/210: fifteen tocks 3-86 ms late, and the seven right tocks after them put off
    the beat)."""
    bounds = np.linspace(0, n.size, 4).astype(int)
    position = np.arange(n.size)
    thirds = [(position >= a) & (position < b) for a, b in pairwise(bounds)]
    best = _fit_from(n, t, np.ones(n.size, dtype=bool))
    best_on = int(np.sum(best <= OFF_BEAT))
    for core in thirds:
        if core.sum() < 3:
            continue
        deviation = _fit_from(n, t, core)
        # fitted again to the ticks on it: half a third's ticks would bend it, away
        # from them, by milliseconds at the train's far end
        for _ in range(REFITS):
            on = deviation <= OFF_BEAT
            if on.sum() < 3 or np.array_equal(on, core):
                break
            core = on
            deviation = _deviation(n, t, core)
        on_the_beat = int(np.sum(deviation <= OFF_BEAT))
        if on_the_beat >= best_on + MORE_ON_THE_BEAT:
            best, best_on = deviation, on_the_beat
    return best


def _fit_from(n: np.ndarray, t: np.ndarray, core: np.ndarray) -> np.ndarray:
    """(S,) each tick's distance from a quadratic fitted to ``core``, then to the half
    of the ticks nearest it, again until that half keeps (at most `REFITS` times):
    later impacts taken for a third of the ticks bend a fit to all of them and widen
    the spread that would hide them."""
    for _ in range(REFITS):
        deviation = _deviation(n, t, core)
        nearest = deviation <= np.median(deviation)
        if np.array_equal(nearest, core):
            break
        core = nearest
    return deviation


def _deviation(n: np.ndarray, t: np.ndarray, core: np.ndarray) -> np.ndarray:
    """(S,) each tick's distance from a quadratic in ``n`` fitted to ``core``, beyond
    their median offset from it."""
    residual = t - np.polyval(np.polyfit(n[core], t[core], 2), n)
    return np.abs(residual - np.median(residual[core]))


def _from_neighbours(n: np.ndarray, t: np.ndarray, side: int = NEIGHBOURS) -> np.ndarray:
    """(S,) each tick's time as its neighbours put it: the median over the lines through
    one of the ``side`` ticks before it and one of the ``side`` after, so that one odd
    neighbour does not move it; NaN within ``side`` of either end (with fewer, one odd
    neighbour would)."""
    size = t.size
    out = np.full(size, np.nan)
    if size <= 2 * side:
        return out
    p = np.arange(side, size - side)
    n = n.astype(float)
    guesses = [t[p - da] + (t[p + db] - t[p - da]) * (n[p] - n[p - da]) / (n[p + db] - n[p - da])
               for da in range(1, side + 1) for db in range(1, side + 1)]  # fmt: skip
    out[p] = np.median(guesses, axis=0)
    return out


def robust_spread(x: np.ndarray) -> float:
    """1.4826 × the median absolute deviation: a standard deviation that a few odd
    values (a masked tick) do not inflate."""
    return float(1.4826 * np.median(np.abs(x - np.median(x))))


def join_fragments(times: np.ndarray, trains: list[Train], voice: list[int]):
    """Trains that are pieces of one metronome's beat, joined: (trains, voices of each
    (tuple)). See the module docstring."""
    trains, groups = list(trains), [(v,) for v in voice]
    joined = True
    while joined:
        joined = False
        for a in range(len(trains)):
            # of the trains that could be a piece of this one, the one nearest its
            # grid: two metronomes of one tempo, each heard as a tick voice and a
            # tock voice, fit either's tock to either's tick, but a metronome is set
            # in beat within a few per cent (unseen corpus seed 4/245: 0.03 BPM apart,
            # each tick joined to the other's tock, both limping 17 %)
            best = None
            for b in range(len(trains)):
                if a == b:
                    continue
                found = _common_beat(times, trains[a], trains[b])
                if found is None:
                    beat = _continues(times, trains[a], trains[b])
                    found = None if beat is None else (beat, CONTINUED)
                if found is None or (best is not None and found[1] >= best[2]):
                    continue
                if not _clash(times, trains[a], trains[b], found[0]):
                    best = (b, *found)
            if best is not None:
                b, beat, _ = best
                trains[a] = _merge(times, trains[a], trains[b], beat)
                groups[a] = groups[a] + groups[b]
                del trains[b], groups[b]
                joined = True
                break
    return trains, groups


def _common_beat(times: np.ndarray, ta: Train, tb: Train) -> tuple[float, float] | None:
    """(the beat T of which both trains' periods are whole multiples (up to
    `MAX_FRAGMENT`) and on whose grid, laid from train a, b's ticks fall at a fixed
    place between a's ticks; how far that place is off the grid, in beats); None if
    there is none."""
    t_a, t_b = times[ta.index], times[tb.index]
    # a tick both trains hold is one tick of the metronome, heard on both grids (every
    # 2nd and every 3rd beat meet on every 6th)
    shared = np.isin(tb.index, ta.index)
    inside = (t_b > t_a[0]) & (t_b < t_a[-1]) & ~shared
    if inside.sum() < 4 or shared.sum() > inside.sum():
        return None
    for ka in range(1, MAX_FRAGMENT + 1):
        beat = ta.period / ka
        kb = round(tb.period / beat)
        if beat < BEAT_RANGE[0] or kb < 1 or ka * kb == 1:
            continue
        if abs(tb.period / (kb * beat) - 1) > 0.01:
            continue
        k = np.searchsorted(t_a, t_b[inside]) - 1
        gap_before = t_b[inside] - t_a[k]
        gap_after = t_a[np.minimum(k + 1, t_a.size - 1)] - t_b[inside]
        if np.mean(np.minimum(gap_before, gap_after) < 0.3 * beat) > 0.1:
            continue  # on a's own ticks: two metronomes ticking together
        z = np.exp(2j * np.pi * gap_before / beat).mean()
        spread = math.sqrt(max(0.0, -2 * math.log(max(abs(z), 1e-12)))) / (2 * np.pi)
        off_grid = abs(np.angle(z) / (2 * np.pi))
        if spread < 2 * LOCKED_SPREAD and off_grid < OFF_GRID:
            if _drift(t_b[inside], tb.beat[inside], gap_before / beat, z) < MAX_DRIFT:
                if not _silent_beats(times, ta, tb, beat, math.lcm(ka, kb)):
                    return beat, off_grid
    return None


def _silent_beats(times: np.ndarray, ta: Train, tb: Train, beat: float, cycle: int) -> bool:
    """Whether trains a and b, joined on ``beat``, leave a kind of beat (its number
    modulo ``cycle``, the pieces' common cycle) that neither holds and where hardly
    any tick at all is heard (under `HEARD_SILENT` of those places, within
    `SILENT_WINDOW` of a beat or `HIDING` before): two metronomes at a whole-number
    ratio of tempo, not one metronome's pieces, whose other beats sound (held by
    another piece, by none, or hidden behind another metronome's tick)."""
    merged = _merge(times, ta, tb, beat)
    b, t = merged.beat, times[merged.index]
    # beats held only every g-th of the grid: the pieces' metronome ticks on that
    # coarser grid, where the grid between is silent anyway
    g = int(np.gcd.reduce(np.append(np.unique(b % cycle), cycle)))
    b, cycle, beat = b // g, cycle // g, beat * g
    missing = np.setdiff1d(np.arange(cycle), np.unique(b % cycle))
    if missing.size == 0:
        return False
    numbers = np.arange(b[0], b[-1])
    numbers = numbers[np.isin(numbers % cycle, missing)]
    if numbers.size < 4:
        return False
    at = np.interp(numbers, b, t)
    # heard: a tick near the place, or one just before that may hide it
    first = np.searchsorted(times, at - HIDING)
    last = np.searchsorted(times, at + SILENT_WINDOW * beat, side="right")
    return bool(np.mean(last > first) < HEARD_SILENT)


def _drift(t: np.ndarray, beat: np.ndarray, place: np.ndarray, z: complex) -> float:
    """How far (beats) ticks at ``t`` drift on another train's grid over their span:
    ``place`` (fractions of a beat after the grid's last beat) about its circular mean
    ``z``, less each kind of beat's median (a limp), fitted by a line in time."""
    x = np.angle(np.exp(2j * np.pi * place) / z) / (2 * np.pi)
    for parity in (0, 1):
        sel = beat % 2 == parity
        if sel.any():
            x[sel] -= np.median(x[sel])
    ok = np.abs(x) < 0.1  # a tick timed by another's that hid it
    if ok.sum() < 4 or np.ptp(t[ok]) <= 0:
        return 0.0
    slope = np.polyfit(t[ok], x[ok], 1)[0]
    return float(abs(slope) * np.ptp(t))


def _continues(times: np.ndarray, ta: Train, tb: Train) -> float | None:
    """The beat, when train b takes up train a's beat after a ended: one metronome
    followed again after ticks of another hid it for more than `MAX_MISSING` beats, or
    only every few of its beats heard (b's period a whole multiple of a's, up to
    `MAX_FRAGMENT`, or a's of b's: the beat is the shorter)."""
    short, long_ = sorted((ta.period, tb.period))
    k = round(long_ / short)
    if k > MAX_FRAGMENT or abs(long_ / (k * short) - 1) > 0.01:
        return None
    end, start = times[ta.index[-1]], times[tb.index[0]]
    beat = 0.5 * (short + long_ / k)
    beats = (start - end) / beat
    if not 1 <= round(beats) <= MAX_BRIDGED or abs(beats - round(beats)) > OFF_GRID:
        return None
    return beat


def _clash(times, ta: Train, tb: Train, beat: float) -> bool:
    """Whether a tick of one train lies within half a beat of one of the other's but
    beyond a tick's length (`MAX_TICK_LENGTH`): not a later impact of it, a sound of
    another metronome on the same beat; the two are not pieces of one."""
    gap = np.diff(np.sort(times[np.union1d(ta.index, tb.index)]))
    return bool(np.any(_on_one_beat(gap, beat) & (gap > MAX_TICK_LENGTH)))


def _on_one_beat(gap: np.ndarray, beat: float) -> np.ndarray:
    """Whether ticks ``gap`` (s) apart lie on one beat of ``beat`` (within half of it)."""
    return np.rint(gap / beat) == 0


def _merge(times, ta: Train, tb: Train, beat: float) -> Train:
    """The two trains' ticks as one train of beat ``beat``, numbered by the beats
    between them; of two ticks within half a beat and `MAX_TICK_LENGTH`, one."""
    index, first = np.unique(np.concatenate([ta.index, tb.index]), return_index=True)
    masked = np.concatenate([ta.masked, tb.masked])[first]
    # a tick both hold is masked only if both took it from another metronome
    masked &= ~np.isin(index, np.concatenate([ta.index[~ta.masked], tb.index[~tb.masked]]))
    order = np.argsort(times[index], kind="stable")
    index, masked = index[order], masked[order]
    # two ticks within half a beat are on one beat (one piece's tick and the other's
    # later impact of it, or another metronome's tick it took for a hidden one): one
    # tick there, the one heard as its own, else the first (corpus seed 220, three
    # metronomes: each such pair counted a beat more, and 189 BPM became 201)
    while index.size > 2:
        gap = np.diff(times[index])
        same = np.flatnonzero(_on_one_beat(gap, beat) & (gap <= MAX_TICK_LENGTH))
        if same.size == 0:
            break
        i = same[0]
        drop = i if masked[i] and not masked[i + 1] else i + 1
        index, masked = np.delete(index, drop), np.delete(masked, drop)
    t = times[index]
    steps = np.maximum(1, np.rint(np.diff(t) / beat)).astype(np.int64)
    beat = np.concatenate([[0], np.cumsum(steps)])
    return Train(index, beat, float((t[-1] - t[0]) / beat[-1]), masked)

"""Ticks that another tick hid, found again where their metronome's beat puts them.

Contract: `recover(recording, scan, ticks, trains)` takes the ticks (`detection.Ticks`,
sorted) and the metronomes' trains over them (`trains.Train`), and returns (ticks,
trains, found): the ticks with those it recovered added, the trains with each
recovered tick in its beat, and how many ticks were added.

First, a tick that lies off its train's beat (`trains.off_the_beat`: a later impact
of a tick whose first impact another tick hid) leaves the train: its beat counts as
missed. They are sought again once those found have left (up to `ON_BEAT_PASSES`
times): a few found first widen the spread the rest are judged by. For each beat a
train missed, its time is predicted from the nearest heard beats of the same kind
(tick or tock), up to `REACH` beats before and after: on a line fitted to up to
`SIDE` of them on each side when both sides were heard (an uneven beat is exact; one
neighbour mistimed by another's ring moves it little), on the local beat when one
side was. A tick already heard that no train holds
(the tracker lost the train there and took it up again further on) and that lies
within `TOLERANCE` of one prediction, and of no other, joins that train.

A tick that falls a few milliseconds after another metronome's, or on its ringing,
barely raises the detection curve: the detector's threshold, set for the whole
recording, misses it. For the beats still missed, the detection curve's highest
point within `WINDOW` of the prediction, if it rises at least `MIN_RISE` dB, is
timed on the waveform like any tick (`detection.refine`), and kept when its onset
lies within `TOLERANCE` of the prediction and no tick is within the detector's
resolution (`detection.RESOLUTION`) of it. Up to `PASSES` passes: each predicts
from the ticks the last one added, so that a long run of missed beats is filled from
both ends inwards.

Last, each beat still missed, and the `END_BEATS` beyond each end of a train (where
the tracker gave up), is sought by the metronome's own sound (`templates.fit`, beside
the other metronomes' sounds that overlap it) within `templates.SEARCH` of the
prediction (the beat just past an end from the beat beside it, by the train's limp,
where the nearest beat of its kind lies in another's ring and that one does not): a
tick whose onset the detector timed too far off in another's ring, or
never heard, is found where it sounds like the metronome (`FOUND_LIKENESS`) and is
about as loud as its ticks (`FOUND_SCALE`); one found over `RECENTRE` off its
prediction is judged on a window around where it was found. The
curve's highest point alone is not enough there: beyond a train's end it is as
often the room's noise. A heard tick that another train holds only as the tick that
hid its own is found so too, where the fit lands on its onset (within
`templates.CRACK`). A heard tick found so keeps the detector's onset unless it
lies in another's ring. Where the tracker gave up on a train before the file ended,
the search walks on, `END_BEATS` at a time, while the train's sound is found there
within `END_SKIP` beats (at most `MAX_END_WALK` steps): another metronome's ticks may
cover the first beats beyond the end. Up to `ROUNDS` rounds of all this: a beat found
by its sound lets the next round predict the beats beside it.

`nearer_another(times, trains, label)` takes a tick's metronome away (−1) where the
tick lies nearer another train's beat than its own train's beat puts it, within the
detector's resolution: two metronomes ticked together there and its onset may be
either's.
"""

from __future__ import annotations

import numpy as np

from . import detection as det
from . import templates as tp
from .trains import Train, holders, off_the_beat, with_ticks

WINDOW = 3e-3
MIN_RISE = 1.0
TOLERANCE = 1.5e-3
#: Farthest heard beat of the same kind a missed beat is predicted from.
REACH = 16
#: Times the ticks off a train's beat are sought: those found first widen the spread
#: that the rest are judged by (corpus seed 169: a tick 36 ms early kept, and the beats
#: beside it predicted 4-8 ms early).
ON_BEAT_PASSES = 3
#: Passes of `recover`: each predicts from the ticks the last one added.
PASSES = 3
#: Rounds of passes and the search by sound, at most: beats the sound found let the
#: next round predict the beats between.
ROUNDS = 3
#: Heard beats of a kind on each side a missed beat's time is fitted to.
SIDE = 3
#: Beats of a kind heard with both beside them that measure the train's limp, at least.
MIN_LIMP_SAMPLES = 4
#: How long after a tick its later impacts and ring can move another's onset, s (the
#: analysis's assumption `templates.LATER_IMPACTS`).
RING = tp.LATER_IMPACTS
#: Beats sought by their sound beyond each end of a train, a step of the walk.
END_BEATS = 2
#: Steps of that walk, at most.
MAX_END_WALK = 64
#: Where a step finds nothing (another metronome's ticks cover those beats), the beats
#: up to this many beyond the end are sought before the walk stops (corpus seed 74:
#: another's ticks covered seven beats in a row).
END_SKIP = 10
#: A beat sought by its sound is found where it sounds at least this much like it.
FOUND_LIKENESS = 0.5
#: ... and found at least this loud, as a share of the ticks its sound was learned
#: from: true ticks found by sound 0.34-1.4 (corpus seeds 2/185, 4/85, 3/187, 4/127,
#: 4/10, 3/12); past a train's end, 72 ms into another metronome's ring, a tick of
#: 0.01 its loudness was as alike (0.53; seed 2/185).
FOUND_SCALE = 0.2
#: A beat found by its sound this far from where it was predicted (s) is judged again
#: on a window around it: the first window held only its first milliseconds (corpus
#: seed 4/160: a last tick predicted 3.2 ms early, 0.33 alike, then dropped).
RECENTRE = 1e-3
#: A tick in another's ring this many robust spreads off its beat is unattributed ...
RING_OFF_BEAT = 1.0
#: ... or this many, where the sum of the sounds explains it this well (likeness): its
#: onset was fitted, and one spread dropped a metronome's usual ticks in a ring.
FITTED_OFF_BEAT = 2.5
FITTED_LIKENESS = 0.7
#: ... or this many where its sound explains it this well: fitted so closely, a ring
#: hardly moved it, and a tick's jitter alone puts one in a hundred 2.6 spreads off
#: its beat (corpus seed 4/57: a tick on time, 0.96 alike, 1.6 ms off its
#: neighbours' line).
TRUSTED_OFF_BEAT = 3.0
TRUSTED_LIKENESS = 0.9


def _predictions(
    times: np.ndarray, train: Train, beyond: int = 0, in_ring: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(beats missed, their predicted times) of one train: from the nearest heard beats
    of the same kind (tick or tock) before and after (not a masked tick: the tick that
    hid it timed it; but where most of a kind is masked, its tock sounds like another
    voice and those are its own), at most `REACH` beats away, on a line fitted to up to
    `SIDE` on each side (`_fit_between`); from one side only, midway between the beats
    beside it where both were heard, moved by the train's limp (`_midway`, `_limps`),
    else on the beat of the two nearest heard beats of the kind there (within 5 % of the
    train's mean beat, else the mean). With ``beyond``, only the ``beyond`` beats before
    the train's first tick and as many after its last; with ``in_ring`` (per tick of
    ``times``: in another's ring), the one just past an end is predicted from the beat
    beside it, by the train's step between the two kinds (`_steps`), where the nearest
    beat of its kind lies in another's ring and that beat does not."""
    heard = ~train.masked  # a masked tick is timed by the tick that hid it
    for parity in (0, 1):
        # ... unless most of a kind is: those are the metronome's own, in another voice
        kind = train.beat % 2 == parity
        if (heard & kind).sum() < 0.5 * kind.sum():
            heard |= kind
    beat, t = train.beat[heard], times[train.index[heard]]
    ring = None if in_ring is None else in_ring[train.index[heard]]
    if beat.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    if beyond:
        first, last = train.beat[0], train.beat[-1]
        missing = np.r_[first - beyond : first, last + 1 : last + beyond + 1]
    else:
        missing = np.setdiff1d(np.arange(train.beat[0], train.beat[-1] + 1), train.beat)
    swing = 2 * train.period
    limps = _limps(beat, t)
    steps = _steps(beat, t)
    out_n, out_t = [], []
    for parity in (0, 1):
        mine = beat % 2 == parity
        b, tb = beat[mine], t[mine]
        want = missing[missing % 2 == parity]
        if b.size == 0 or want.size == 0:
            continue
        j = np.searchsorted(b, want)
        lo, hi = np.maximum(j - 1, 0), np.minimum(j, b.size - 1)
        has_lo = (j > 0) & (want - b[lo] <= REACH)
        has_hi = (j < b.size) & (b[hi] - want <= REACH)
        both = has_lo & has_hi
        p = np.full(want.size, np.nan)
        for w in np.flatnonzero(both):
            p[w] = _fit_between(b, tb, lo[w], hi[w], want[w])
        # from one side: the swing of the two nearest heard beats of the kind there
        # (a metronome that speeds up), or the train's mean
        before = np.maximum(lo - 1, 0)
        after = np.minimum(hi + 1, b.size - 1)
        beat_lo = (tb[lo] - tb[before]) / np.maximum(b[lo] - b[before], 1)
        beat_hi = (tb[after] - tb[hi]) / np.maximum(b[after] - b[hi], 1)
        step_lo = _near_mean(np.where(lo > before, beat_lo, 0.0), 0.5 * swing)
        step_hi = _near_mean(np.where(after > hi, beat_hi, 0.0), 0.5 * swing)
        only_lo = has_lo & ~has_hi
        p[only_lo] = (tb[lo] + (want - b[lo]) * step_lo)[only_lo]
        only_hi = has_hi & ~has_lo
        p[only_hi] = (tb[hi] - (b[hi] - want) * step_hi)[only_hi]
        # where the kind was heard on one side only, but both beats beside were: midway
        # between them, moved by the train's limp
        one_sided = ~both
        if one_sided.any():
            between = _midway(beat, t, want[one_sided]) + limps[parity]
            p[one_sided] = np.where(np.isfinite(between), between, p[one_sided])
        # just past an end, from the beat beside it (of the other kind) by the train's
        # step between the two kinds (its limp), where the nearest beat of its own kind,
        # two on, lies in another's ring and may be timed milliseconds off there (corpus
        # seed 4/51: a train's first beat sought 5.4 ms early, from the beat of its kind
        # two on, heard 3.5 ms early), and the beat beside it does not (seed 3/260: the
        # beat beside the end heard 7.5 ms late in a ring)
        if beyond and ring is not None:
            p = _beside_an_end(beat, t, ring, want, steps[parity], p)
        ok = np.isfinite(p)
        out_n.append(want[ok])
        out_t.append(p[ok])
    if not out_n:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    n, p = np.concatenate(out_n), np.concatenate(out_t)
    order = np.argsort(n)
    return n[order].astype(np.int64), p[order]


def _steps(beat: np.ndarray, t: np.ndarray) -> list[tuple[float, float]]:
    """For each kind of beat (tick, tock): the median time (s) from it to the next beat
    and from the beat before to it, over the train's heard neighbouring beats (``beat``,
    ``t``, sorted); NaN with fewer than `MIN_LIMP_SAMPLES` of them."""
    step = np.diff(t)
    neighbours = np.diff(beat) == 1

    def typical(steps: np.ndarray) -> float:
        return float(np.median(steps)) if steps.size >= MIN_LIMP_SAMPLES else np.nan

    onwards = [typical(step[neighbours & (beat[:-1] % 2 == parity)]) for parity in (0, 1)]
    into = [typical(step[neighbours & (beat[1:] % 2 == parity)]) for parity in (0, 1)]
    return list(zip(onwards, into, strict=True))


def _beside_an_end(beat, t, ring, want, step: tuple[float, float], p: np.ndarray) -> np.ndarray:
    """``p`` with the beats of ``want`` just before the train's first heard beat and just
    after its last (``beat``, ``t``) predicted from that beat, by ``step`` (s: from the
    kind of ``want`` to the next beat, and from the beat before to it; `_steps`), where
    the nearest heard beat of their kind lies in another's ring and that beat does not
    (``ring``, per heard beat)."""
    onwards, into = step
    p = p.copy()
    kind = np.flatnonzero(beat % 2 == want[0] % 2)
    if kind.size == 0:
        return p
    first = (want == beat[0] - 1) & np.isfinite(onwards) & ring[kind[0]] & ~ring[0]
    last = (want == beat[-1] + 1) & np.isfinite(into) & ring[kind[-1]] & ~ring[-1]
    p[first] = t[0] - onwards
    p[last] = t[-1] + into
    return p


def _midway(beat: np.ndarray, t: np.ndarray, n: np.ndarray) -> np.ndarray:
    """(len(n),) the time midway between the heard beats n − 1 and n + 1 (``beat``,
    ``t``: the train's heard beats, sorted); NaN where either was not heard."""
    out = np.full(n.size, np.nan)
    if beat.size == 0:
        return out
    lo = np.minimum(np.searchsorted(beat, n - 1), beat.size - 1)
    hi = np.minimum(np.searchsorted(beat, n + 1), beat.size - 1)
    both = (beat[lo] == n - 1) & (beat[hi] == n + 1)
    out[both] = (t[lo[both]] + t[hi[both]]) / 2
    return out


def _limps(beat: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """How far each kind's heard beats lie from midway between the beats beside them
    (median, s), NaN for a kind with fewer than `MIN_LIMP_SAMPLES` such beats."""
    offset = t - _midway(beat, t, beat)
    out = []
    for parity in (0, 1):
        mine = offset[np.isfinite(offset) & (beat % 2 == parity)]
        out.append(float(np.median(mine)) if mine.size >= MIN_LIMP_SAMPLES else np.nan)
    return out[0], out[1]


def _fit_between(b: np.ndarray, tb: np.ndarray, lo: int, hi: int, want: int) -> float:
    """The time of beat ``want`` on a line fitted to up to `SIDE` heard beats of its
    kind on each side (``b``, ``tb``: their numbers and times; ``lo``, ``hi``: the
    nearest before and after), within `REACH` of it: one of them mistimed by another's
    ring moves the prediction by a fraction of its error."""
    left = np.arange(max(lo - SIDE + 1, 0), lo + 1)
    right = np.arange(hi, min(hi + SIDE, b.size))
    use = np.concatenate([left[want - b[left] <= REACH], right[b[right] - want <= REACH]])
    x = b[use] - want
    slope, intercept = np.polyfit(x.astype(float), tb[use], 1)
    return float(intercept)


def _near_mean(beat: np.ndarray, mean: float) -> np.ndarray:
    """A local beat (s) where it is within 5 % of the train's mean beat, else the mean."""
    return np.where(np.abs(beat / mean - 1) < 0.05, beat, mean)


def _on_beat(times: np.ndarray, train: Train) -> Train:
    """The train without its ticks that lie off its beat (`trains.off_the_beat`): a
    later impact taken for a tick whose first another tick hid is not the tick; its
    beat is sought again as missed."""
    for _ in range(ON_BEAT_PASSES):
        off = off_the_beat(times[train.index], train.beat)
        if not off.any() or (~off).sum() < 2:
            return train
        beat = train.beat[~off]
        train = Train(train.index[~off], beat - beat[0], train.period, train.masked[~off])
    return train


def _take_unheld(times: np.ndarray, trains: list[Train], owner, beat, pred):
    """(trains with the ticks no train holds that lie within `TOLERANCE` of one of their
    predicted beats added, mask of the predictions so met): a tick the tracker lost
    where its metronome's beat was followed again from elsewhere."""
    held = np.zeros(times.size, dtype=bool)
    for t in trains:
        held[t.index] = True
    free = np.flatnonzero(~held)
    met = np.zeros(pred.size, dtype=bool)
    if free.size == 0 or pred.size == 0:
        return trains, met
    j = np.clip(np.searchsorted(times[free], pred), 1, max(free.size - 1, 1))
    left, right = free[j - 1], free[np.minimum(j, free.size - 1)]
    nearest = np.where(np.abs(times[left] - pred) <= np.abs(times[right] - pred), left, right)
    close = np.abs(times[nearest] - pred) <= TOLERANCE
    # a tick two beats want is neither's
    wanted, counts = np.unique(nearest[close], return_counts=True)
    close &= np.isin(nearest, wanted[counts == 1])
    out = []
    for m, train in enumerate(trains):
        mine = close & (owner == m)
        out.append(with_ticks(train, nearest[mine], beat[mine]))
    return out, close


def recover(recording, scan, ticks, trains: list[Train]):
    """(ticks, trains, recovered): see the module docstring."""
    trains = [_on_beat(ticks.time, t) for t in trains]
    recovered = 0
    for _ in range(ROUNDS):
        for _ in range(PASSES):
            ticks, trains, added, taken = _pass(recording, scan, ticks, trains)
            recovered += added
            if added + taken == 0:
                break
        sounds = tp.learn(recording, scan, ticks.time, trains)
        ticks, trains, added, joined = _by_sound(recording, scan, ticks, trains, sounds)
        recovered += added
        found = added + joined
        # a train the tracker gave up on before the file ended: walked on, `END_BEATS`
        # at a time, while its beats are found where its sound is
        for _ in range(MAX_END_WALK):
            # beats just beyond an end that another metronome's ticks cover: further on
            for beyond in range(END_BEATS, END_SKIP + 1, END_BEATS):
                ticks, trains, added, joined = _by_sound(
                    recording, scan, ticks, trains, sounds, gaps=False, beyond=beyond
                )
                if added + joined:
                    break
            recovered += added
            found += added + joined
            if added + joined == 0:
                break
        if found == 0:
            break
    return ticks, trains, recovered


def _by_sound(
    recording,
    scan,
    ticks,
    trains: list[Train],
    sounds,
    *,
    gaps: bool = True,
    beyond: int = END_BEATS,
):
    """(ticks, trains, ticks added, heard ticks joined): each beat still missed (with
    ``gaps``), and the ``beyond`` beats past each end of a train, sought by the train's
    own sound (``sounds``, `templates.learn`) within `templates.SEARCH` of the prediction,
    beside the other trains' sounds: kept where it sounds like the train
    (`FOUND_LIKENESS`) and no tick is within the detector's resolution of it; a tick
    heard there that no train holds (or one holds only as the tick that hid its own,
    found on its onset) is the one found, timed on the sounds only where it lies in
    another's ring (`templates.retime`): elsewhere the detector is exact."""
    rate = recording.sample_rate
    lo, hi = tp.BEFORE + tp.MARGIN, recording.frames / rate - tp.AFTER - tp.MARGIN
    owner = holders(ticks.time.size, trains)
    sources = tp.sounding(ticks.time, trains, sounds)
    in_ring = tp.ringing(ticks.time, sources, ticks.time)
    metronomes: list[int] = []
    beats: list[np.ndarray] = []
    times: list[np.ndarray] = []
    for m, train in enumerate(trains):
        if sounds[m] is None:
            continue
        for reach in (0, beyond) if gaps else (beyond,):
            n, p = _predictions(ticks.time, train, reach, in_ring)
            ok = (p > lo) & (p < hi)
            metronomes += [m] * int(ok.sum())
            beats.append(n[ok])
            times.append(p[ok])
    if not metronomes:
        return ticks, trains, 0, 0
    want_m, want_n, want_t = np.array(metronomes), np.concatenate(beats), np.concatenate(times)
    order = np.argsort(want_t)
    want_m, want_n, want_t = want_m[order], want_n[order], want_t[order]
    own = [sounds[m] for m in want_m]

    def around(at, metronome):
        return tp.context(ticks.time, sources, sounds, at, metronome)

    onset, likeness, scale = tp.fit(recording, scan, want_t, own, around(want_t, want_m))
    # a tick found well off its prediction was judged on a window that held little of
    # it: judged again on one around it
    again = np.flatnonzero((np.abs(onset - want_t) > RECENTRE) & (likeness < FOUND_LIKENESS))
    if again.size:
        again = again[np.argsort(onset[again])]
        refit = tp.fit(recording, scan, onset[again], [own[i] for i in again],
                       around(onset[again], want_m[again]))  # fmt: skip
        onset[again], likeness[again], scale[again] = refit
    j = np.clip(np.searchsorted(ticks.time, onset), 1, max(ticks.time.size - 1, 1))
    near = np.where(np.abs(ticks.time[j] - onset) < np.abs(ticks.time[j - 1] - onset), j, j - 1)
    close = np.abs(ticks.time[near] - onset) <= det.RESOLUTION
    # and as loud as a tick: in another's ring, what its sound leaves can be as alike
    keep = (likeness >= FOUND_LIKENESS) & (np.abs(scale) >= FOUND_SCALE)
    # a heard tick that another train holds only as the tick that hid its own is no
    # one's own: it is this train's where found on its onset (corpus seed 4/496: a
    # tick 6.6 ms before another metronome's, which that one's train held as hiding
    # its own; not one found 5 ms before it, seed 4/24)
    hid = ~_held_as_own(ticks.time.size, trains)[near]
    keep &= ~close | (owner[near] < 0) | (hid & (np.abs(ticks.time[near] - onset) <= tp.CRACK))
    # one found tick per beat and per sound: two beats that found one onset are neither's
    _, first, counts = np.unique(np.round(onset[keep] * rate), return_index=True,
                                 return_counts=True)  # fmt: skip
    chosen = np.flatnonzero(keep)[first[counts == 1]]
    if chosen.size == 0:
        return ticks, trains, 0, 0
    reuse = chosen[close[chosen]]
    time = ticks.time.copy()
    # heard, but in another's ring: timed on the sounds
    ringing = tp.ringing(ticks.time, sources, ticks.time[near[reuse]])
    time[near[reuse[ringing]]] = onset[reuse[ringing]]
    fresh = chosen[~close[chosen]]
    fields = det.Ticks.__dataclass_fields__
    # loudness and rise as the detector measures them; the time is the fitted onset
    hops = np.clip(np.round(onset[fresh] * rate / scan.hop).astype(np.int64), 0,
                   scan.curve.size - 1)  # fmt: skip
    measured = det.refine(recording, scan, hops)
    extra = {f: getattr(measured, f) for f in fields}
    extra["time"] = onset[fresh]
    merged = {f: np.concatenate([time if f == "time" else getattr(ticks, f), extra[f]])
              for f in fields}  # fmt: skip
    index_of = np.empty(chosen.size, dtype=np.int64)
    index_of[close[chosen]] = near[reuse]
    index_of[~close[chosen]] = ticks.time.size + np.arange(fresh.size)
    # a beat found before the first counts from 0 again
    new_ticks, out = _merged(merged, trains, index_of, want_m[chosen], want_n[chosen],
                             from_first=True)  # fmt: skip
    return new_ticks, out, int(fresh.size), int(reuse.size)


def _pass(recording, scan, ticks, trains: list[Train]):
    """(ticks, trains, ticks added, heard ticks taken) after one pass of `recover`."""
    rate = recording.sample_rate
    hop_s = scan.hop / rate
    reach = max(1, round(WINDOW / hop_s))
    owners, beats, predicted = [], [], []
    for m, train in enumerate(trains):
        n, p = _predictions(ticks.time, train)
        owners.append(np.full(n.size, m))
        beats.append(n)
        predicted.append(p)
    if not trains:
        return ticks, trains, 0, 0
    owner, beat, pred = (np.concatenate(x) for x in (owners, beats, predicted))
    trains, met = _take_unheld(ticks.time, trains, owner, beat, pred)
    taken = int(met.sum())
    owner, beat, pred = owner[~met], beat[~met], pred[~met]
    if pred.size == 0:
        return ticks, trains, 0, taken
    centre = np.round(pred / hop_s).astype(np.int64)
    offsets = np.arange(-reach, reach + 1)
    cols = np.clip(centre[:, None] + offsets[None, :], 0, scan.curve.size - 1)
    best = cols[np.arange(cols.shape[0]), np.argmax(scan.curve[cols], axis=1)]
    ok = scan.curve[best] >= MIN_RISE
    owner, beat, pred, best = owner[ok], beat[ok], pred[ok], best[ok]
    if best.size == 0:
        return ticks, trains, 0, taken
    order = np.argsort(best, kind="stable")
    owner, beat, pred, best = owner[order], beat[order], pred[order], best[order]
    found = det.refine(recording, scan, best)
    near = np.abs(found.time - pred) <= TOLERANCE
    j = np.clip(np.searchsorted(ticks.time, found.time), 1, max(ticks.time.size - 1, 1))
    gap = np.minimum(np.abs(ticks.time[j] - found.time), np.abs(ticks.time[j - 1] - found.time))
    near &= gap > det.RESOLUTION
    if not near.any():
        return ticks, trains, 0, taken
    fields = det.Ticks.__dataclass_fields__
    merged = {f: np.concatenate([getattr(ticks, f), getattr(found, f)[near]]) for f in fields}
    added_index = ticks.time.size + np.arange(int(near.sum()))
    new_ticks, new_trains = _merged(merged, trains, added_index, owner[near], beat[near],
                                    from_first=False)  # fmt: skip
    return new_ticks, new_trains, int(near.sum()), taken


def _held_as_own(k: int, trains: list[Train]) -> np.ndarray:
    """(K,) True for the ticks some train holds as its own, not as hidden behind them."""
    out = np.zeros(k, dtype=bool)
    for train in trains:
        out[train.index[~train.masked]] = True
    return out


def _merged(merged: dict, trains: list[Train], index, owner, beat, *, from_first: bool):
    """The ticks of ``merged`` (the detector's fields, the old ticks then the added)
    sorted by time, and each train with the ticks ``index`` that ``owner`` gives it at
    their ``beat``s, renumbered from its first beat when ``from_first``."""
    fields = det.Ticks.__dataclass_fields__
    order = np.argsort(merged["time"], kind="stable")
    new_ticks = det.Ticks(*(merged[f][order] for f in fields))
    where = np.empty(order.size, dtype=np.int64)
    where[order] = np.arange(order.size)
    out = []
    for m, train in enumerate(trains):
        mine = owner == m
        added = with_ticks(train, index[mine], beat[mine])
        first = added.beat[0] if from_first else 0
        out.append(Train(where[added.index], added.beat - first, train.period, added.masked))
    return new_ticks, out


def _own_offset(times: np.ndarray, train: Train) -> np.ndarray:
    """(M,) each tick's distance (s) from its beat as the train's neighbouring heard beats
    of the same kind put it (the one before and the one after; at an end, the next
    two); NaN where a kind has fewer than three ticks."""
    out = np.full(train.index.size, np.nan)
    t = times[train.index]
    for parity in (0, 1):
        sel = np.flatnonzero(train.beat % 2 == parity)
        if sel.size < 3:
            continue
        b, tb = train.beat[sel].astype(float), t[sel]
        pos = np.arange(sel.size)
        lo, hi = pos - 1, pos + 1
        lo[0], hi[0] = 1, 2
        lo[-1], hi[-1] = sel.size - 3, sel.size - 2
        slope = (tb[hi] - tb[lo]) / (b[hi] - b[lo])
        out[sel] = tb - (tb[lo] + slope * (b - b[lo]))
    return out


def nearer_another(
    times: np.ndarray, trains: list[Train], label: np.ndarray, likeness: np.ndarray | None = None
) -> np.ndarray:
    """(K,) ``label`` (the metronome of each tick, −1 for none) with −1 for each tick
    that lies nearer another train's beat (a tick it heard, or one it missed or took
    from another, where predicted) than its own train's beat puts it, within the
    detector's resolution (two metronomes ticked together there and the tick's onset
    may be either's); and for each tick that falls within `RING` after another train's
    tick and lies off its own beat by more than `RING_OFF_BEAT` of its train's robust
    spread (at least a millisecond; `FITTED_OFF_BEAT` where its ``likeness`` (K,) to
    its sound is at least `FITTED_LIKENESS`, `TRUSTED_OFF_BEAT` where at least
    `TRUSTED_LIKENESS`): its onset is timed by the other's later impacts and ring."""
    out = label.copy()
    if len(trains) < 2:
        return out
    beats, heard = [], []
    for train in trains:
        # a masked tick is another's onset: its beat is where the train's beat puts it
        own = ~train.masked
        unmasked = Train(train.index[own], train.beat[own], train.period, train.masked[own])
        _, predicted = _predictions(times, unmasked)
        beats.append(np.sort(np.concatenate([times[unmasked.index], predicted])))
        heard.append(np.sort(times[unmasked.index]))
    for m, train in enumerate(trains):
        held = label[train.index] == m
        mine = train.index[held]
        if mine.size == 0:
            continue
        offset = _own_offset(times, train)
        own = np.abs(offset)[held]
        x = times[mine]
        other = np.full(x.size, np.inf)
        since = np.full(x.size, np.inf)
        for j in range(len(trains)):
            if j == m or beats[j].size == 0:
                continue
            grid = beats[j]
            q = np.clip(np.searchsorted(grid, x), 1, max(grid.size - 1, 1))
            d = np.minimum(np.abs(grid[q - 1] - x), np.abs(grid[np.minimum(q, grid.size - 1)] - x))
            other = np.minimum(other, d)
            q = np.searchsorted(heard[j], x)
            before = x - heard[j][np.maximum(q - 1, 0)]
            since = np.minimum(since, np.where((q > 0) & (before > 0), before, np.inf))
        spread = 1.4826 * np.nanmedian(np.abs(offset - np.nanmedian(offset)))
        bar = np.full(x.size, RING_OFF_BEAT)
        if likeness is not None:
            bar[likeness[mine] >= FITTED_LIKENESS] = FITTED_OFF_BEAT
            bar[likeness[mine] >= TRUSTED_LIKENESS] = TRUSTED_OFF_BEAT
        limit = np.maximum(1e-3, bar * spread) if np.isfinite(spread) else np.inf
        drop = (other < own) & (other <= det.RESOLUTION)
        drop |= (since <= RING) & (own > limit)
        out[mine[drop]] = -1
    return out

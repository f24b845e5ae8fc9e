"""A train that followed every k-th beat of its metronome, given the beats between.

Contract: `subdivided(times, trains)` returns the trains, each that holds only every
k-th beat of its metronome (k = 2 to `trains.MAX_FRAGMENT`) given the ticks that no
train holds on the beats between, with its beat and period divided by k.

Where several metronomes tick, a slow one's ticks are often the ones another's ring
or ticks overlap: the tracker can lock on every second or third of them, a train of
half or a third of the metronome's tempo, and leave the ticks between to no one. Such
a train is told by those ticks: for each place j/k of the way from one of its beats to
the next (between two of its ticks up to `MAX_STEP` beats apart), a tick no train
holds lies near it (within `WINDOW` of a beat: a limp puts a tock off the middle) in
at least `MIN_SHARE` of those places (the rest may be hidden by other ticks), at an
offset from it that keeps still: robust spread under `MAX_SPREAD`, for each place and
each kind of beat (tick or tock) apart, as a limp offsets the two kinds oppositely. A
few milliseconds remain, as the places are interpolated between a tick and a tock;
another metronome's ticks near those places drift through them and spread over tens.
Where a tick's later impacts are among them (its first impact lost in another's ring)
and widen the spread, the tightest cluster of offsets (within `CLUSTER`) is enough if
it holds at least `CLUSTER_SHARE` of them, and the place's clusters `CLUSTER_PLACES`
of its places. The ticks taken lie within `trains.OFF_BEAT` of their place's usual
offset, the centre of that cluster.
The smallest k that fits is taken, and the search repeated on the divided train (a
train of every fourth beat is halved twice), down to beats of `MIN_BEAT`.
"""

from __future__ import annotations

import numpy as np

from .trains import MAX_FRAGMENT, OFF_BEAT, Train, robust_spread, with_ticks

#: A tick between is sought this far (fraction of the divided beat) from its place.
WINDOW = 0.15
#: ... in at least this share of the places of one kind: the others may be hidden.
MIN_SHARE = 0.3
#: Places are sought between ticks of the train up to this many of its beats apart.
MAX_STEP = 3
#: Largest robust spread of its offsets from the places, s.
MAX_SPREAD = 6e-3
#: Where other ticks widen that spread, the tightest cluster: within this of its
#: members' offsets, s, ...
CLUSTER = 3e-3
#: ... at least this many of them and this share of the kind's close ticks, ...
MIN_CLUSTER = 2
CLUSTER_SHARE = 0.25
#: ... and, with the place's other kind, in at least this share of the place's places.
CLUSTER_PLACES = 0.2
#: Pairs of ticks (up to `MAX_STEP` beats apart) a train needs before it is tried.
MIN_PAIRS = 8
#: Shortest beat a train is divided to, s (300 BPM).
MIN_BEAT = 0.2


def subdivided(times: np.ndarray, trains: list[Train]) -> list[Train]:
    """The trains, each that followed every k-th beat of its metronome given the ticks
    between (see the module docstring)."""
    times = np.asarray(times, dtype=float)
    out = list(trains)
    for m in range(len(out)):
        for _ in range(MAX_FRAGMENT):
            held = np.zeros(times.size, dtype=bool)
            for t in out:
                held[t.index] = True
            divided = _divided(times, out[m], np.flatnonzero(~held))
            if divided is None:
                break
            out[m] = divided
    return out


def _divided(times: np.ndarray, train: Train, free: np.ndarray) -> Train | None:
    """``train`` with its beat divided by the smallest k that the ticks ``free`` (indices
    no train holds) fit, or None."""
    t, b = times[train.index], train.beat
    step = np.diff(b)
    pairs = np.flatnonzero((step <= MAX_STEP) & ~train.masked[:-1] & ~train.masked[1:])
    if pairs.size < MIN_PAIRS or free.size == 0:
        return None
    free_t = times[free]
    odd_limp = _limp(t, b, step, pairs)
    for k in range(2, MAX_FRAGMENT + 1):
        beat = train.period / k
        if beat < MIN_BEAT:
            return None
        # every place between two of the train's ticks a divided beat would fill:
        # (time, beat number, place j of k, kind of the metronome's beat there). For an
        # even k the train's ticks are all of one kind, and so are the beats at place j:
        # one kind per place, however few of the train's beats of either parity a
        # place was heard after (seed 168: another metronome hid every other tock).
        limp = odd_limp if k % 2 else 0.0  # for an even k the limp cancels (`_limp`)
        rows = [
            (
                _place(t[p], t[p + 1], b[p] % 2, n, i, limp),
                b[p] * k + i,
                i % k,
                (b[p] + i // k) % 2 if k % 2 else 0,
            )
            for p, n in zip(pairs, step[pairs] * k, strict=True)
            for i in range(1, n)
            if i % k
        ]
        where, number, place, kind = (np.array(c) for c in zip(*rows, strict=True))
        at = _fitting(free_t, where, place, kind, beat)
        if at is None:
            continue
        ok = at >= 0
        divided = Train(train.index, b * k, beat, train.masked)
        return with_ticks(divided, free[at[ok]], number[ok])
    return None


def _limp(t: np.ndarray, b: np.ndarray, step: np.ndarray, pairs: np.ndarray) -> float:
    """How much longer the metronome's beat after its kind-0 beats is than after its
    kind-1 beats, s, seen in a train of every k-th beat for an odd k (0 when too few
    intervals show it).

    A limp alternates tick and tock. For an odd k the train's own beats alternate too,
    and its interval after a kind-0 beat holds one more long beat than the one after a
    kind-1 beat: their difference is the limp. Without it the places between, spaced
    evenly along a span, would sit off by a third, a half or four ninths of the limp as
    the span is 1, 2 or 3 of the train's beats, and their offsets spread with the span
    (corpus seed 207). For an even k both intervals hold as many of each."""
    one = pairs[step[pairs] == 1]
    after = t[one + 1] - t[one]
    kind0 = b[one] % 2 == 0
    if kind0.sum() < 3 or (~kind0).sum() < 3:
        return 0.0
    return float(np.median(after[kind0]) - np.median(after[~kind0]))


def _place(t0: float, t1: float, kind0: int, n: int, i: int, limp: float) -> float:
    """Where the i-th of ``n`` beats from a beat of kind ``kind0`` at ``t0`` to one at
    ``t1`` falls, the beats after kind-0 beats ``limp`` longer than the others."""
    if limp == 0.0:
        return t0 + (t1 - t0) * i / n
    longs = (n + 1 - kind0) // 2  # of the n beats, those after a kind-0 beat
    short = (t1 - t0 - longs * limp) / n
    longs_before = (i + 1 - kind0) // 2
    return t0 + i * short + longs_before * limp


def _fitting(free_t, where, place, kind, beat: float) -> np.ndarray | None:
    """(P,) the free tick (index into ``free_t``) at each place ``where`` (−1: none), if
    every kind of place passes the test of the module docstring; else None."""
    near, offset = _nearest(free_t, where)
    close = np.abs(offset) <= WINDOW * beat
    usual = np.zeros(where.size)
    for j in np.unique(place):
        mine = place == j
        if close[mine].mean() < MIN_SHARE:
            return None
        kept, polluted = 0, False
        for parity in (0, 1):
            sel = close & mine & (kind == parity)
            if sel.sum() == 0:
                continue
            # the usual offset is the tight cluster's: other ticks among them (a tick's
            # later impacts, its first one hidden in another's ring; corpus seed 138)
            # would pull a plain median off, and widen the spread
            centre, members = _cluster(offset[sel])
            usual[mine & (kind == parity)] = centre
            if sel.sum() >= 3 and robust_spread(offset[sel]) < MAX_SPREAD:
                kept += int(sel.sum())
            elif members >= MIN_CLUSTER and members >= CLUSTER_SHARE * sel.sum():
                kept, polluted = kept + members, True
            else:
                return None
        if polluted and kept < CLUSTER_PLACES * mine.sum():
            return None
    # each place's tick is the free one nearest its usual offset from it
    near, offset = _nearest(free_t, where + usual)
    keep = np.abs(offset) <= OFF_BEAT
    # a tick taken for two places is neither's
    unique, counts = np.unique(near[keep], return_counts=True)
    keep &= np.isin(near, unique[counts == 1])
    return np.where(keep, near, -1)


def _cluster(offsets: np.ndarray) -> tuple[float, int]:
    """(centre, count) of the most offsets within ``CLUSTER`` of one of them."""
    x = np.sort(offsets)
    count = np.searchsorted(x, x + CLUSTER, "right") - np.searchsorted(x, x - CLUSTER)
    best = x[np.abs(x - x[np.argmax(count)]) <= CLUSTER]
    return float(np.median(best)), int(best.size)


def _nearest(sorted_t: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(index of the nearest of ``sorted_t`` to each of ``at``, its offset from it, s)."""
    q = np.clip(np.searchsorted(sorted_t, at), 1, max(sorted_t.size - 1, 1))
    left, right = q - 1, np.minimum(q, sorted_t.size - 1)
    near = np.where(np.abs(sorted_t[left] - at) <= np.abs(sorted_t[right] - at), left, right)
    return near, sorted_t[near] - at

"""A train made mostly of the beats another metronome's train missed, given back.

Contract: `given_back(times, trains)` returns the trains, each train B that mostly
fills another train A's missed beats dissolved: A takes those ticks, and B's other
ticks are left to no train (recovery gives them to the train whose beat they fall on).

The tracker follows one voice's ticks train by train, each taking what the last left.
Where four metronomes tick, one's train can miss a third of its beats, hidden by the
others, and the tracker then finds a "metronome" in what is left: every other beat
of the missed ones, at 3/2 of that metronome's beat, stitched with another's ticks
between (corpus seed 198: a 104.7 BPM train of a 157 BPM metronome's missed beats and
another's ticks, five metronomes counted for four). Such a train B is told by its
ticks: at least `MIN_SHARE` of them (and `MIN_FILLS`) lie within `trains.OFF_BEAT`
of a beat A missed, inside A's span, where A's ticks of the same kind (tick or tock:
a limp) put it. A real metronome's ticks fall on another's missed beats only by
chance, a few in a hundred; two locked at 3:2 meet on the other's ticks, not its
missed beats. A train at a whole multiple of A's beat on A's missed beats is given
back too: every fifth or fourth beat of a metronome whose train missed a fifth of its
beats stood as a metronome of its own, at 33.3 and 40.1 BPM, which the joins left
(unseen corpus seeds 4/259, 4/271: five metronomes counted for four).
"""

from __future__ import annotations

import numpy as np

from .trains import OFF_BEAT, Train, with_ticks

#: Share of a train's ticks on another's missed beats that makes it that one's.
MIN_SHARE = 0.5
#: ... and at least this many of them.
MIN_FILLS = 8


def given_back(times: np.ndarray, trains: list[Train]) -> list[Train]:
    """The trains, with each that fills another's missed beats dissolved into it (see
    the module docstring)."""
    times = np.asarray(times, dtype=float)
    out = list(trains)
    dissolved = True
    while dissolved:
        dissolved = False
        for b, tb in enumerate(out):
            for a, ta in enumerate(out):
                if a == b or ta.index.size < MIN_FILLS:
                    continue
                number, fills = _fills(times, ta, tb)
                if fills.sum() < max(MIN_FILLS, MIN_SHARE * tb.index.size):
                    continue
                out[a] = with_ticks(ta, tb.index[fills], number[fills])
                del out[b]
                dissolved = True
                break
            if dissolved:
                break
    return out


def _fills(times: np.ndarray, ta: Train, tb: Train) -> tuple[np.ndarray, np.ndarray]:
    """(A's beat number nearest each of B's ticks, whether it lies within `OFF_BEAT` of
    that beat and A missed it), each beat once."""
    t_a, n_a = times[ta.index], ta.beat
    t_b = times[tb.index]
    slope, intercept = np.polyfit(n_a.astype(float), t_a, 1)
    number = np.round((t_b - intercept) / slope).astype(n_a.dtype)
    fills = (number > n_a[0]) & (number < n_a[-1]) & ~np.isin(number, n_a)
    where = np.full(t_b.size, np.nan)
    for parity in (0, 1):
        kind = n_a % 2 == parity
        if kind.sum() < 2:
            continue
        # between two of A's ticks of the kind: beyond them the limp is not known
        mine = fills & (number % 2 == parity)
        mine &= (number > n_a[kind][0]) & (number < n_a[kind][-1])
        where[mine] = np.interp(number[mine], n_a[kind], t_a[kind])
    fills &= np.abs(t_b - where) <= OFF_BEAT  # NaN: no beat of the kind to put it
    # a beat two of B's ticks would fill is neither's
    numbers, counts = np.unique(number[fills], return_counts=True)
    fills &= np.isin(number, numbers[counts == 1])
    return number, fills

"""Pieces of one metronome's ticks, followed as several trains, are one metronome."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.audio.interleaved import join_interleaved
from metrosync.audio.trains import Train, _clash, _merge, join_fragments

BEAT = 60.0 / 141.33


def ticks(n, *, beat=BEAT, limp=0.03, start=0.3, jitter=0.4e-3, seed=0):
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    return start + k * beat + np.where(k % 2, limp * beat, 0.0) + rng.normal(0, jitter, n)


def indexed(*groups):
    """All times sorted, and each group's indices into them."""
    times = np.concatenate(groups)
    order = np.argsort(times, kind="stable")
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    bounds = np.cumsum([0] + [g.size for g in groups])
    return times[order], [where[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def train(index, times, period):
    index = np.sort(index)
    beat = np.rint((times[index] - times[index[0]]) / period).astype(np.int64)
    return Train(index, beat, period, np.zeros(index.size, bool))


def test_every_second_and_every_third_beat_that_share_ticks_are_one_metronome():
    """Corpus seed 143: one metronome's ticks were held by a train of every 4th beat
    and one of every 3rd; they meet on every 12th, both holding that tick, and were
    counted as two metronomes."""
    mine = ticks(90)
    other = ticks(110, beat=60 / 197.7, start=0.12, seed=1)
    times, (own, _) = indexed(mine, other)
    k = np.arange(mine.size)
    fours = train(own[k % 4 == 2], times, 4 * BEAT)
    threes = train(own[k % 3 == 1], times, 3 * BEAT)
    assert np.intersect1d(fours.index, threes.index).size >= 7
    joined, groups = join_fragments(times, [fours, threes], [0, 1])
    assert len(joined) == 1 and sorted(groups[0]) == [0, 1]
    one = joined[0]
    assert set(one.index) == set(fours.index) | set(threes.index)
    assert one.index.size == np.unique(one.index).size
    assert abs(one.period / BEAT - 1) < 1e-3
    # each tick on its own beat of the metronome
    assert np.array_equal(one.beat, k[(k % 4 == 2) | (k % 3 == 1)] - 1)


def test_two_metronomes_of_one_tempo_each_join_their_own_tock():
    """Unseen corpus seed 4/245: two metronomes 0.03 BPM apart, each heard as a tick
    voice and a tock voice. Either's tock lies on either's tick grid, within the 15 %
    of a beat a joint allows; taken in the order found, each tick was joined to the
    other's tock, and both metronomes limped 17 %. The pair nearest the grid (the
    metronome's own limp, 3 and 2 %) joins first."""
    a = ticks(90, limp=0.03)
    b = ticks(90, limp=0.02, start=0.3 + 0.1 * BEAT, seed=1)
    times, (own_a, own_b) = indexed(a, b)
    tick = np.arange(90) % 2 == 0
    own = [own_a[tick], own_b[~tick], own_a[~tick], own_b[tick]]  # each tick, the other's tock
    pieces = [train(index, times, 2 * BEAT) for index in own]
    joined, groups = join_fragments(times, pieces, [0, 1, 2, 3])
    assert sorted(sorted(g) for g in groups) == [[0, 2], [1, 3]]
    assert sorted(set(j.index) for j in joined) == sorted([set(own_a), set(own_b)])
    assert all(abs(j.period / BEAT - 1) < 1e-3 for j in joined)


def test_a_train_whose_ticks_the_other_holds_is_not_a_piece_of_it():
    """A train of every second beat that holds only ticks of another train adds no beat."""
    mine = ticks(90)
    times, (own,) = indexed(mine)
    whole = train(own, times, BEAT)
    half = train(own[::2], times, 2 * BEAT)
    joined, _ = join_fragments(times, [whole, half], [0, 0])
    assert len(joined) == 2


def halves(*, lag=0.026, fainter=6.0, both=True, seed=0):
    """One limping metronome's ticks, each with a later impact ``lag`` after it and
    ``fainter`` dB below; train A: the ticks (even beats) and the tocks' later impacts,
    train B: the tocks and (``both``) the ticks' later impacts. (times, strength, A, B,
    indices of the true ticks)."""
    rng = np.random.default_rng(seed)
    first = ticks(94, seed=seed)
    later = first + lag + rng.normal(0, 0.05e-3, first.size)
    times, (true, echo) = indexed(first, later)
    strength = np.zeros(times.size)
    strength[echo] = -fainter
    k = np.arange(first.size)
    a_index = np.concatenate([true[k % 2 == 0], echo[k % 2 == 1]])
    a = train(a_index, times, BEAT)
    if both:
        b = train(np.concatenate([true[k % 2 == 1], echo[k % 2 == 0]]), times, BEAT)
    else:
        b = train(true[k % 2 == 1], times, 2 * BEAT)
    return times, strength, a, b, true


@pytest.mark.parametrize("both", [True, False])
def test_two_halves_of_one_metronome_each_with_later_impacts_are_one(both):
    """Corpus seeds 100 (both trains at full tempo, each taking the other kind's later
    impacts) and 78 (the tocks alone at half the tempo, the other train the ticks and
    the tocks' later impacts): one metronome counted as two."""
    times, strength, a, b, true = halves(both=both)
    joined = join_interleaved(times, strength, [a, b])
    assert len(joined) == 1
    one = joined[0]
    assert np.array_equal(one.index, np.sort(true))
    assert np.array_equal(one.beat, np.arange(true.size))
    assert abs(one.period / BEAT - 1) < 1e-3


def test_later_impacts_at_two_lags_are_one_metronome():
    """Corpus seed 65: a tick's second and third impacts, 24 and 34 ms on, taken by turns."""
    times, strength, a, b, true = halves()
    late = np.isin(np.arange(times.size), true, invert=True)
    shift = np.where(late & (np.arange(times.size) % 3 == 0), 0.010, 0.0)
    moved = times + shift
    order = np.argsort(moved, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    a, b = (train(rank[t.index], moved[order], t.period) for t in (a, b))
    joined = join_interleaved(moved[order], strength[order], [a, b])
    assert len(joined) == 1 and np.array_equal(joined[0].index, np.sort(rank[true]))


@pytest.mark.parametrize(
    ("case", "kwargs"),
    [
        ("as loud", {"fainter": 0.0}),
        ("lag wanders", {"wander": 2e-3}),
    ],
)
def test_two_metronomes_locked_a_few_milliseconds_apart_stay_two(case, kwargs):
    """Two metronomes locked 20 ms apart at one tempo, the second's tock 20 ms ahead
    of the first's: as loud, or with a lag that wanders as real beats jitter, they are
    two."""
    rng = np.random.default_rng(5)
    first = ticks(94)
    k = np.arange(first.size)
    second = first + np.where(k % 2, -0.02, 0.02) + rng.normal(0, kwargs.get("wander", 0.0), k.size)
    times, (i1, i2) = indexed(first, second)
    strength = np.zeros(times.size)
    fainter = kwargs.get("fainter", 6.0)
    strength[i2[k % 2 == 0]] = -fainter  # the later one on ticks ...
    strength[i1[k % 2 == 1]] = -fainter  # ... and on tocks
    a, b = train(i1, times, BEAT), train(i2, times, BEAT)
    assert len(join_interleaved(times, strength, [a, b])) == 2, case


def test_a_quarter_tempo_train_of_tocks_and_a_train_of_the_rest_are_one():
    """Corpus seed 165: one metronome's every other tock (others hid the rest from the
    tracker) at a quarter of its tempo, and a train of its ticks, the tocks between and
    the later impacts of the quarter train's tocks: counted as two metronomes."""
    times, strength, a, _, true = halves()
    k = np.arange(true.size)
    # the later impacts of the tocks of beats 4j + 1 that a took; a keeps its ticks and
    # takes the tocks of beats 4j + 3 as they are
    echo_of = {
        int(i): int(e)
        for i, e in zip(true, np.sort(np.setdiff1d(np.arange(times.size), true)), strict=True)
    }
    quarter = true[k % 4 == 1]
    rest = np.concatenate([true[k % 4 != 1], [echo_of[int(i)] for i in quarter]])
    joined = join_interleaved(
        times, strength, [train(rest, times, BEAT), train(quarter, times, 4 * BEAT)]
    )
    assert len(joined) == 1
    assert np.array_equal(joined[0].index, np.sort(true))
    assert np.array_equal(joined[0].beat, np.arange(true.size))


def test_a_train_of_later_impacts_seen_once_its_metronome_is_complete_is_no_ticks():
    """Corpus seed 151: a train of the later impact (30 ms on) of every other tick of one
    metronome, found only after recovery completed that metronome's train, was a
    metronome of half its tempo. It is folded, and its sounds are not ticks."""
    from metrosync.audio.dataset import _later_impacts_folded
    from metrosync.audio.detection import Ticks

    rng = np.random.default_rng(151)
    first = ticks(90, seed=151)
    later = first[::2] + 0.030 + rng.normal(0, 0.05e-3, first[::2].size)
    other = ticks(100, beat=60 / 149.2, start=0.28, seed=152)
    times, (own, echo, theirs) = indexed(first, later, other)
    strength = np.full(times.size, -10.0)
    strength[echo] = -20.0
    heard = Ticks(times, strength, strength[:, None], np.full(times.size, 12.0))
    trains = [train(own, times, BEAT), train(echo, times, 2 * BEAT),
              train(theirs, times, 60 / 149.2)]  # fmt: skip
    kept_ticks, kept = _later_impacts_folded(heard, trains)
    assert len(kept) == 2
    assert kept_ticks.time.size == times.size - echo.size
    assert np.array_equal(kept_ticks.time[kept[0].index], times[np.sort(own)])
    assert np.array_equal(kept_ticks.time[kept[1].index], times[np.sort(theirs)])


def test_two_metronomes_at_four_to_three_are_not_one_of_their_common_beat():
    """Corpus seed 81: metronomes at 143.4 and 191.2 BPM (4:3 within 0.01 %), the
    second's ticks and tocks of different sounds. A train of all the first's beats and
    one of the second's ticks lie on one grid (286.8 BPM: every 2nd and every 3rd of
    its beats), which then never sounds on two beats of every six: two metronomes,
    not one followed in pieces."""
    slow = ticks(95, beat=60 / 143.4, limp=0.0)
    fast = ticks(127, beat=60 / 191.2, limp=0.0, start=0.3, seed=1)
    # where the two tick together the detector hears one tick, which both trains hold
    apart = np.min(np.abs(fast[:, None] - slow[None, :]), axis=1) > 5e-3
    times, (a, _) = indexed(slow, fast[apart])
    b = np.argmin(np.abs(fast[:, None] - times[None, :]), axis=1)
    whole = train(a, times, 60 / 143.4)
    its_ticks = train(b[::2], times, 2 * 60 / 191.2)
    joined, _ = join_fragments(times, [whole, its_ticks], [0, 1])
    assert len(joined) == 2


def test_pieces_of_one_metronome_whose_other_beats_hide_behind_another_are_one():
    """Corpus seed 162: one metronome followed as a train of every 2nd beat and one of
    every 4th; the beats left, one in four, each fall 28 ms after another metronome's
    tick, in its ring, and are not heard. Those places are not silent: another's tick
    just before hides them."""
    mine = ticks(100)
    k = np.arange(mine.size)
    hider = mine[k % 4 == 3] - 0.028
    times, (own, _) = indexed(mine[k % 4 != 3], hider)
    kept = k[k % 4 != 3]
    halves = train(own[kept % 2 == 0], times, 2 * BEAT)
    quarters = train(own[kept % 4 == 1], times, 4 * BEAT)
    joined, _ = join_fragments(times, [halves, quarters], [0, 1])
    assert len(joined) == 1
    assert abs(joined[0].period / BEAT - 1) < 1e-3


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_piece_whose_tick_is_a_later_impact_of_one_the_other_holds_adds_no_beat(seed):
    """Corpus seed 220, three metronomes: a piece of every fourth beat, the later
    impacts (32.7 ms on) of ticks whose first impacts were lost, joined a 189 BPM train
    that held a few of those ticks' first impacts, or another metronome's tick it took
    for a hidden one 11 ms before. Each such pair, 44 ms or less apart, was counted a
    beat: the joined train's beats ran ahead, and 189 BPM became 201. Two ticks within
    half a beat are one beat: the first impact, or the one heard as its own, stays."""
    rng = np.random.default_rng(seed)
    beat = 60.0 / 189.08
    own = ticks(120, beat=beat, limp=0.0, seed=seed)
    k = np.arange(120)
    piece = k % 4 == 1  # the beats whose first impact was lost ...
    both = piece & (rng.uniform(size=120) < 0.25)  # ... or heard, by the other train
    later = own[piece] + 0.0327 + rng.normal(0, 0.05e-3, int(piece.sum()))
    times, (first, late) = indexed(own, later)
    a_beats = ~piece | both
    a = train(first[a_beats], times, beat)
    b = train(late, times, 4 * beat)
    merged = _merge(times, a, b, beat)
    assert merged.period == pytest.approx(beat, rel=1e-3)
    # each beat once; where both were heard, the first impact
    assert np.array_equal(merged.beat, k)
    expected = first.copy()
    expected[piece & ~both] = late[~both[piece]]
    assert np.array_equal(merged.index, expected)


def test_a_sound_on_the_same_beat_beyond_a_ticks_length_is_another_metronomes():
    """Of two pieces, a tick 32 ms after the other's is a later impact of it (one
    beat); one 124 ms after it, within half a beat but beyond a tick's length, is
    another metronome's sound on that beat, and the pieces are not one (corpus seed 1
    of four: two metronomes hidden behind each other, joined, gave one at 197 BPM
    with 41 ms of jitter)."""
    beat = 60.0 / 195.0
    own = ticks(80, beat=beat, limp=0.0, seed=4)
    k = np.arange(80)
    for lag, clash in ((0.032, False), (0.124, True)):
        extra = own[k == 10] + lag  # after one of the first piece's ticks
        times, (first, other) = indexed(own[k % 4 != 1], np.r_[own[k % 4 == 1], extra])
        a = train(first, times, beat)
        b = train(other, times, 4 * beat)
        assert _clash(times, a, b, beat) == clash

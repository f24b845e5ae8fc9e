"""A train that followed every k-th beat of its metronome is given the beats between."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.audio.subdivision import subdivided
from metrosync.audio.trains import Train, fold_parts, off_the_beat


def beats(bpm, duration, *, limp=0.03, jitter=0.6e-3, start=0.1, seed=0):
    """Tick times of one metronome: tock offset by ``limp`` of a beat, jittered."""
    rng = np.random.default_rng(seed)
    period = 60.0 / bpm
    n = np.arange(int((duration - start) / period))
    return start + n * period + np.where(n % 2, limp * period, 0.0) + rng.normal(0, jitter, n.size)


def setting(k, *, hidden=0.4, other_bpm=131.0, seed=1):
    """(all tick times, the train of every k-th beat of a 107 BPM metronome, the indices
    of that metronome's ticks, of the other metronome's); ``hidden`` of the beats between
    were never heard."""
    rng = np.random.default_rng(seed)
    mine = beats(107.0, 40.0, seed=seed)
    number = np.arange(mine.size)
    heard = (number % k == 0) | (rng.uniform(size=mine.size) > hidden)
    mine, number = mine[heard], number[heard]
    other = beats(other_bpm, 40.0, limp=0.0, start=0.23, seed=seed + 1)
    times = np.concatenate([mine, other])
    order = np.argsort(times)
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    own, others = where[: mine.size], where[mine.size :]
    on = number % k == 0
    train = Train(own[on], number[on] // k, k * 60.0 / 107.0, np.zeros(int(on.sum()), bool))
    return times[order], train, own, others


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("k", [2, 3, 4])
def test_a_train_of_every_kth_beat_gets_the_beats_between(k, seed):
    times, train, own, others = setting(k, seed=seed)
    (out,) = subdivided(times, [train])
    assert out.period == pytest.approx(60.0 / 107.0)
    # every heard tick of the metronome between the train's ends (beyond them, the
    # recovery walks on); another's tick within 3 ms of a beat whose own tick was
    # hidden cannot be told from it by its time
    first, last = times[train.index[0]], times[train.index[-1]]
    inside = own[(times[own] >= first) & (times[own] <= last)]
    assert set(inside) <= set(out.index)
    assert len(set(out.index) - set(own)) <= 1
    assert np.all(np.diff(out.beat) >= 1)
    # the beat numbers count the metronome's beats
    assert np.allclose(np.diff(times[out.index]) / np.diff(out.beat), 60.0 / 107.0, rtol=0.05)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_limping_train_of_every_third_beat_with_gaps_is_divided(seed):
    """A train of every third beat that lost a quarter of its own ticks: its pairs span
    3, 6 or 9 beats. Across an odd number of beats a limp does not cancel, so the places
    between, interpolated along each span, would sit off by a third, a half or four
    ninths of the limp, and their offsets spread with the span (corpus seed 207: a
    metronome followed at a third of its tempo)."""
    rng = np.random.default_rng(seed)
    times, train, own, others = setting(3, hidden=0.2, seed=seed)
    kept = np.ones(train.index.size, dtype=bool)
    kept[1:-1] = rng.uniform(size=train.index.size - 2) > 0.25
    gappy = Train(train.index[kept], train.beat[kept], train.period, train.masked[kept])
    (out,) = subdivided(times, [gappy])
    assert out.period == pytest.approx(60.0 / 107.0)
    assert len(set(out.index) - set(own)) <= 1
    assert np.all(np.diff(out.beat) >= 1)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_train_of_every_second_beat_whose_every_other_tock_is_hidden_is_divided(seed):
    """A train of the ticks of a metronome, every second beat: the tock after each of
    its odd beats hidden by another metronome's tick (corpus seed 168, three
    metronomes: 103.9 BPM reported as 52). The tocks left all follow the train's even
    beats; a tock is a tock whichever of the train's beats it follows."""
    times, train, own, others = setting(2, hidden=0.0, seed=seed)
    behind = own[np.isin(own, train.index, invert=True)][1::2]  # the tocks after odd beats
    left = np.flatnonzero(~np.isin(np.arange(times.size), behind))
    where = np.full(times.size, -1)
    where[left] = np.arange(left.size)
    mine = Train(where[train.index], train.beat, train.period, train.masked)
    (out,) = subdivided(times[left], [mine])
    assert out.period == pytest.approx(60.0 / 107.0)
    heard = where[own[~np.isin(own, behind)]]
    first, last = times[left][mine.index[[0, -1]]]
    inside = heard[(times[left][heard] >= first) & (times[left][heard] <= last)]
    assert set(inside) <= set(out.index)
    assert len(set(out.index) - set(heard)) <= 1


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_train_of_every_third_beat_among_later_impacts_is_divided(seed):
    """Half the beats between a train of every third beat hidden, most of them leaving
    a later impact of their tick 10-23 ms after the beat (its first impact fell in
    another's ring; corpus seed 138, four metronomes: 156 BPM reported as 52). Those
    impacts widen the offsets' spread past the bar, but the heard ticks still sit
    tightly on their places: they are taken, and the later impacts are not."""
    rng = np.random.default_rng(seed)
    times, train, own, others = setting(3, hidden=0.0, seed=seed)
    between = own[~np.isin(own, train.index)]
    hidden = between[rng.uniform(size=between.size) < 0.55]
    echoes = hidden[rng.uniform(size=hidden.size) < 0.6]
    later = times[echoes] + rng.uniform(0.010, 0.023, echoes.size)
    kept = np.setdiff1d(np.arange(times.size), hidden)
    all_t = np.concatenate([times[kept], later])
    order = np.argsort(all_t)
    where = np.empty(all_t.size, dtype=np.int64)
    where[order] = np.arange(all_t.size)
    back = np.full(times.size, -1)
    back[kept] = where[: kept.size]
    mine = Train(back[train.index], train.beat, train.period, train.masked)
    (out,) = subdivided(all_t[order], [mine])
    assert out.period == pytest.approx(60.0 / 107.0)
    heard = back[np.setdiff1d(own, hidden)]
    first, last = times[train.index[[0, -1]]]
    inside = heard[(all_t[order][heard] >= first) & (all_t[order][heard] <= last)]
    assert len(set(inside) - set(out.index)) <= 0.02 * inside.size
    assert not set(out.index) & set(where[kept.size :])  # no later impact taken
    assert len(set(out.index) - set(heard)) <= 1


def test_ticks_another_train_holds_are_not_taken():
    times, train, own, others = setting(2)
    between = np.setdiff1d(own, train.index)
    holder = Train(np.sort(between), np.arange(between.size), 1.0, np.zeros(between.size, bool))
    out = subdivided(times, [train, holder])
    assert out[0].period == train.period and np.array_equal(out[0].index, train.index)


@pytest.mark.parametrize(
    ("other_bpm", "unheld"), [(131.0, 0.2), (131.0, 1.0), (160.5, 0.2), (214.0, 0.2), (214.0, 1.0)]
)
def test_a_slow_metronome_beside_another_is_left_as_it_is(other_bpm, unheld):
    """Only another metronome's ticks lie between the train's, ``unheld`` of them held
    by no train: they drift through the places a divided beat would fill and are not
    taken; 214 BPM is twice 107, but off its beat. (160.5 BPM is locked at 3:2 with
    perfect timing: every third of its ticks keeps one place between the slow one's;
    beyond timing alone, it is tried with its own train holding all but a fifth.)"""
    times, _, own, others = setting(1, other_bpm=other_bpm, hidden=0.0)
    slow = Train(own, np.arange(own.size), 60.0 / 107.0, np.zeros(own.size, bool))
    rng = np.random.default_rng(3)
    held = np.sort(others[rng.uniform(size=others.size) >= unheld])
    trains = [slow, Train(held, np.arange(held.size), 60.0 / other_bpm, held < 0)]
    assert subdivided(times, trains)[0] is slow


def test_a_train_too_short_is_left_as_it_is():
    times, train, _, _ = setting(2)
    short = Train(train.index[:5], train.beat[:5], train.period, train.masked[:5])
    assert subdivided(times, [short])[0] is short


def test_later_impacts_taken_for_a_quarter_of_the_tocks_are_off_the_beat():
    """A train that took a tock's later impact, 31.5 ms after its hidden first one, for
    a quarter of its tocks (corpus: three metronomes, seed 35): each is off the beat,
    though they bend a first fit of the beat and widen its spread."""
    rng = np.random.default_rng(35)
    n = np.arange(0, 88)
    times = 0.1 + n * 0.4483 + np.where(n % 2, 0.012, 0.0) + rng.normal(0, 0.6e-3, n.size)
    late = (n % 2 == 1) & (rng.uniform(size=n.size) < 0.25)
    times[late] += 0.0315
    assert np.array_equal(off_the_beat(times, n), late)


@pytest.mark.parametrize("lag", [0.115, 0.34])
@pytest.mark.parametrize(("drop_db", "folded"), [(35.0, True), (2.0, False)])
def test_a_faint_train_at_a_fixed_lag_beyond_a_tick_is_its_echo(drop_db, folded, lag):
    """One metronome (corpus, seed 117): a sound 115 ms after every second tick of one
    voice, 35 dB fainter, was a train of its own, a second metronome. Far fainter, at
    a fixed lag within the beat, it is the first train's echo; as loud, it is not. Seed
    201: an echo more than half a beat on (159 ms at 199 BPM) lies nearer the next
    tick; it is still the tick before it's."""
    rng = np.random.default_rng(117)
    first = 0.1 + np.arange(60) * 0.64 + rng.normal(0, 0.5e-3, 60)
    echo = first[::2] + lag + rng.normal(0, 0.02e-3, 30)
    times = np.concatenate([first, echo])
    order = np.argsort(times)
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    strength = np.where(np.arange(times.size) < first.size, -3.0, -3.0 - drop_db)[order]
    a = Train(where[:60], np.arange(60), 0.64, np.zeros(60, bool))
    b = Train(where[60:], np.arange(30), 1.28, np.zeros(30, bool))
    kept, _, parts = fold_parts(times[order], [a, b], [0, 1], strength)
    assert (len(kept) == 1) == folded
    assert (len(parts) == 1 and set(parts[0]) == set(b.index)) == folded


def test_a_train_that_took_its_tocks_later_impacts_gets_their_first_ones():
    """Corpus seed 209, four metronomes: one metronome's train took its ticks and, on
    the tocks' beats, each tock's later impact 27 ms on; the tocks' first impacts, 8 dB
    louder, were a train of every second beat of their own. That train, ahead of every
    second tick at a fixed lag, was folded away as a pre-echo, and the metronome heard
    tick by tick was wrong on every tock. Louder than the ticks it comes before, it is
    their first impact: the metronome's train takes it instead."""
    rng = np.random.default_rng(209)
    beat = 60 / 168.7
    n = np.arange(100)
    on = 0.1 + n * beat + rng.normal(0, 0.4e-3, n.size)
    tock = n % 2 == 1
    heard_later = tock & (rng.uniform(size=n.size) > 0.2)  # a fifth of them hidden
    later = on[heard_later] + 0.02746 + rng.normal(0, 0.05e-3, int(heard_later.sum()))
    times = np.concatenate([on, later])
    strength = np.concatenate([np.where(tock, -12.0, -10.0), np.full(later.size, -20.0)])
    order = np.argsort(times)
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    a_ticks = np.concatenate([where[n[~tock]], where[100:]])
    a_beats = np.concatenate([n[~tock], n[heard_later]])
    sort = np.argsort(a_beats)
    a = Train(a_ticks[sort], a_beats[sort], beat, np.zeros(a_ticks.size, bool))
    b = Train(where[n[tock]], np.arange(50), 2 * beat, np.zeros(50, bool))
    kept, _, parts = fold_parts(times[order], [a, b], [0, 1], strength[order])
    assert len(kept) == 1
    (metronome,) = kept
    assert np.array_equal(metronome.index, where[n]) and np.array_equal(metronome.beat, n)
    assert set(np.concatenate(parts)) == set(where[100:])


def test_a_first_impact_takes_the_beat_its_train_held_only_as_hidden():
    """Corpus seed 209 again, at the file's start: the metronome's train held its first
    tock's beat as hidden behind another metronome's tick 25 ms after the tock (not its
    later impact's usual lag). The tock's first impact, held by the train of every
    second beat, was dropped with that train; it now takes the beat."""
    rng = np.random.default_rng(209)
    beat = 60 / 168.7
    n = np.arange(100)
    on = 0.1 + n * beat + rng.normal(0, 0.4e-3, n.size)
    tock = n % 2 == 1
    heard_later = tock & (n > 1)
    later = on[heard_later] + 0.02746 + rng.normal(0, 0.05e-3, int(heard_later.sum()))
    another = on[1] + 0.0249  # another metronome's tick, which the train took as hiding
    times = np.concatenate([on, later, [another]])
    strength = np.concatenate([np.where(tock, -12.0, -10.0), np.full(later.size, -20.0), [-10.0]])
    order = np.argsort(times)
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    a_ticks = np.concatenate([where[n[~tock]], where[100 : 100 + later.size], [where[-1]]])
    a_beats = np.concatenate([n[~tock], n[heard_later], [1]])
    a_masked = np.arange(a_ticks.size) == a_ticks.size - 1
    sort = np.argsort(a_beats)
    a = Train(a_ticks[sort], a_beats[sort], beat, a_masked[sort])
    b = Train(where[n[tock]], np.arange(50), 2 * beat, np.zeros(50, bool))
    kept, _, _ = fold_parts(times[order], [a, b], [0, 1], strength[order])
    (metronome,) = kept
    assert np.array_equal(metronome.index, where[n]) and np.array_equal(metronome.beat, n)
    assert not metronome.masked.any()


def test_a_tock_far_fainter_than_its_tick_is_not_its_echo():
    """Corpus seed 72: a metronome's tocks, 18.6 dB fainter than its ticks, half a beat
    on. Their lag from the tick before moves with the metronome's beat (its jitter),
    an echo's does not: they stay the metronome's other beat, not an echo."""
    rng = np.random.default_rng(72)
    swing = 60 / 91.9
    ticks_ = 0.08 + np.arange(60) * swing + rng.normal(0, 0.35e-3, 60)
    tocks = 0.08 + (np.arange(60) + 0.5) * swing + 0.03 * swing + rng.normal(0, 0.35e-3, 60)
    times = np.concatenate([ticks_, tocks])
    order = np.argsort(times)
    where = np.empty(times.size, dtype=np.int64)
    where[order] = np.arange(times.size)
    strength = np.where(np.arange(times.size) < 60, -3.0, -21.6)[order]
    a = Train(where[:60], np.arange(60), swing, np.zeros(60, bool))
    b = Train(where[60:], np.arange(60), swing, np.zeros(60, bool))
    kept, _, parts = fold_parts(times[order], [a, b], [0, 1], strength)
    assert len(kept) == 2 and not parts

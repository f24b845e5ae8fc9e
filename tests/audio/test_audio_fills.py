"""A train made mostly of another metronome's missed beats is given back to it."""

from __future__ import annotations

import numpy as np
import pytest
from test_audio_fragments import indexed, ticks

from metrosync.audio.fills import given_back
from metrosync.audio.trains import Train


def metronome(bpm, n, *, limp=0.03, start=0.2, seed=0):
    """Tick times of one metronome: tocks ``limp`` of a beat late, jittered 0.5 ms."""
    return ticks(n, beat=60.0 / bpm, limp=limp, start=start, jitter=0.5e-3, seed=seed)


def train(index, beat, period):
    order = np.argsort(beat)
    return Train(index[order], beat[order], period, np.zeros(index.size, dtype=bool))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_train_of_anothers_missed_beats_and_stray_ticks_is_given_back(seed):
    """Corpus seed 198, four metronomes: a 157 BPM metronome's train missed a third of
    its beats; every other one of those, at 3/2 of its beat, stitched with another
    metronome's ticks between, was a 104.7 BPM "metronome" of its own."""
    rng = np.random.default_rng(seed)
    own = metronome(157.0, 100, seed=seed)
    beat = np.arange(100)
    missed = np.zeros(100, dtype=bool)
    missed[2:-2] = rng.uniform(size=96) < 0.35  # both kinds heard at both ends
    taken = np.flatnonzero(missed)[::2]  # the stray train's share of them
    strays = 0.2 + rng.uniform(0, 38, taken.size * 2 // 3)  # another's ticks between
    times, (mine, stray) = indexed(own, strays)
    a = train(mine[~missed], beat[~missed], 60 / 157.0)
    b_index = np.concatenate([mine[taken], stray])
    b = train(b_index, np.argsort(np.argsort(times[b_index])), 1.5 * 60 / 157.0)
    out = given_back(times, [a, b])
    assert len(out) == 1
    (whole,) = out
    assert set(mine[taken]) <= set(whole.index)
    assert not set(stray) & set(whole.index)
    assert np.array_equal(times[whole.index], np.sort(times[whole.index]))
    assert np.all(np.diff(whole.beat) > 0)


@pytest.mark.parametrize("other_bpm", [104.66, 131.0, 171.0])
def test_another_metronome_is_left_as_it_is(other_bpm):
    """A metronome of its own, at any tempo, its ticks on the missed beats only by
    chance; at 104.66 BPM it is at 2:3 with the first, locked, a tick on every third of
    the first's ticks: on ticks the first holds, not on its missed beats."""
    rng = np.random.default_rng(5)
    first = metronome(157.0, 100, limp=0.0, seed=5)
    beat = np.arange(100)
    missed = np.zeros(100, dtype=bool)
    missed[1:-1] = rng.uniform(size=98) < 0.35
    missed[::3] = False  # where the other ticks with it, the first is heard
    second = metronome(other_bpm, 60, limp=0.0, start=0.2, seed=6)
    times, (one, two) = indexed(first, second)
    a = train(one[~missed], beat[~missed], 60 / 157.0)
    b = train(two, np.arange(two.size), 60 / other_bpm)
    assert given_back(times, [a, b]) == [a, b]


def test_a_fragment_of_a_trains_missed_beats_at_a_whole_multiple_is_given_back():
    """Unseen corpus seeds 4/259 and 4/271: every fifth (fourth) beat of a metronome
    whose train missed them stood as a metronome of its own, at 33.3 (40.1) BPM."""
    own = metronome(157.0, 100, seed=4)
    times, (mine,) = indexed(own)
    beat = np.arange(100)
    a = train(mine[beat % 5 != 0], beat[beat % 5 != 0], 60 / 157.0)
    b = train(mine[beat % 5 == 0], beat[beat % 5 == 0] // 5, 5 * 60 / 157.0)
    (whole,) = given_back(times, [a, b])
    inside = (beat > 0) & (beat < 99)  # A's missed beats within its span
    assert set(times[whole.index]) == set(times[mine[(beat % 5 != 0) | inside]])
    # beside its own ticks, not on its missed beats: left alone
    c = train(mine[beat % 5 == 0], beat[beat % 5 == 0] // 5, 5 * 60 / 157.0)
    full = train(mine, beat, 60 / 157.0)
    assert given_back(times, [full, c]) == [full, c]


def test_a_train_of_a_few_ticks_takes_none():
    """Too few ticks to put a beat on: nothing is given to it (and nothing fails)."""
    own = metronome(157.0, 100, seed=7)
    times, (mine,) = indexed(own)
    beat = np.arange(100)
    a = train(mine[:1], beat[:1], 60 / 157.0)
    b = train(mine[1:], beat[1:], 60 / 157.0 * 1.5)
    assert given_back(times, [a, b]) == [a, b]

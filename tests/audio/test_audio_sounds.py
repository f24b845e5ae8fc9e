"""Each metronome's sound learned from its ticks; whose an onset is by its sound."""

import math

import numpy as np

from metrosync.audio.settings import MODEL
from metrosync.audio.sounds import CLEAR, learn_sounds


def two_makes(separation=6.0, size=200, dims=17, seed=0):
    """Onsets of two metronomes 0.3 s apart in time, each sounding its own: features
    about centres ``separation`` spreads apart (spread 2 dB) in every dimension."""
    rng = np.random.default_rng(seed)
    t = np.arange(2 * size) * 0.15
    who = np.arange(2 * size) % 2
    centres = np.stack([np.zeros(dims), np.full(dims, 2.0 * separation / np.sqrt(dims))])
    x = centres[who] + rng.normal(0, 2.0, (2 * size, dims))
    ticks = [np.flatnonzero(who == m) for m in (0, 1)]
    kinds = [np.arange(size) % 2 for _ in (0, 1)]
    return t, x, who, ticks, kinds


def test_onsets_of_two_makes_are_each_their_own_by_sound():
    t, x, who, ticks, kinds = two_makes()
    sounds = learn_sounds(x, ticks, kinds, t)
    assert sounds.learned.all()
    for m in (0, 1):
        assert np.mean(sounds.others(m)[who != m]) > 0.95
        assert not sounds.others(m)[who == m].any()
        assert np.mean(sounds.mine(m)[who == m]) > 0.95


def test_two_of_one_make_say_nothing_by_sound():
    t, x, who, ticks, kinds = two_makes(separation=0.0)
    sounds = learn_sounds(x, ticks, kinds, t)
    for m in (0, 1):
        # by chance alone the likelihood ratio rarely reaches a thousand
        assert np.mean(sounds.others(m)) < 0.02 and np.mean(sounds.mine(m)) < 0.02
        assert not sounds.told_apart(m, ticks)


def test_a_crowded_onset_is_not_judged_by_its_sound():
    t, x, who, ticks, kinds = two_makes()
    t = t.copy()
    t[11] = t[10] + 0.5 * CLEAR  # another's onset just before: two sounds at once
    sounds = learn_sounds(x, ticks, kinds, t)
    assert not sounds.clear[10] and not sounds.clear[11]
    assert not sounds.others(0)[11] and not sounds.mine(1)[11]


def test_a_sound_is_learned_robustly_from_ticks_partly_another_s():
    # the pursuit let metronome 0 follow metronome 1's ticks for a third of its ticks
    t, x, who, ticks, kinds = two_makes(separation=12.0)
    taken = ticks[1][: ticks[0].size // 2]
    mixed = np.sort(np.concatenate([ticks[0], taken]))
    kind = np.empty(t.size, dtype=int)
    for own, k in zip(ticks, kinds, strict=True):
        kind[own] = k
    sounds = learn_sounds(x, [mixed, ticks[1]], [kind[mixed], kinds[1]], t)
    assert np.mean(sounds.others(0)[who == 1]) >= 0.99
    assert sounds.told_apart(1, [mixed, ticks[1]]) and sounds.told_apart(0, [mixed, ticks[1]])


def test_too_few_clear_ticks_learn_nothing():
    t, x, who, ticks, kinds = two_makes(size=20)  # 8 clear ticks of a kind are needed
    sounds = learn_sounds(x, [ticks[0][:14], ticks[1]], [kinds[0][:14], kinds[1]], t)
    assert not sounds.learned[0] and sounds.learned[1]
    assert not sounds.others(0).any() and not sounds.mine(1).any()
    assert math.log(MODEL.sound_apart) > 6.0  # a ratio of a thousand, as documented

"""Onsets of several metronomes, precursors and bounces included, told apart by timing."""

import numpy as np
import pytest
from test_audio_structure import metronome

from metrosync.audio.decompose import decompose


def mixture(bpms, duration=40.0, seed=0):
    rng = np.random.default_rng(seed)
    louds, onsets = [], []
    for i, bpm in enumerate(bpms):
        loud, heard = metronome(bpm, duration, limp=rng.uniform(0, 0.05), seed=10 * seed + i,
                                phase=rng.uniform(0.05, 0.5))  # fmt: skip
        louds.append(loud)
        onsets.append(heard)
    every = np.sort(np.concatenate(onsets))
    apart = np.ones(every.size, dtype=bool)
    apart[1:] = np.diff(every) > 2e-3  # a detector hears onsets 2 ms apart as one
    return louds, every[apart]


@pytest.mark.parametrize(("bpms", "seed"), [([96.4], 1), ([100.0, 131.0], 2),
                                            ([72.0, 118.0, 176.0], 3)])  # fmt: skip
def test_each_metronome_is_found_once_with_its_ticks(bpms, seed):
    louds, onsets = mixture(bpms, seed=seed)
    heard, owner = decompose(onsets)
    assert len(heard) == len(bpms)
    for loud, h in zip(louds, heard, strict=True):  # slowest first, as given
        assert h.followed.timing.bpm == pytest.approx(60 / np.median(np.diff(loud)), rel=0.05)
        found = onsets[h.ticks]
        recall = np.isin(np.round(loud, 6), np.round(found, 6)).mean()
        assert recall > 0.9
        assert np.all(owner[h.ticks] == heard.index(h))


def test_a_limping_metronome_is_not_also_its_half_tempo():
    louds, onsets = mixture([165.7], seed=14)
    heard, _ = decompose(onsets)
    assert [round(h.followed.timing.bpm) for h in heard] == [166]


def test_clutter_alone_is_no_metronome():
    rng = np.random.default_rng(5)
    assert decompose(np.sort(rng.uniform(0, 40, 120)))[0] == []


def _locked_pair(place_gap_db):
    """A metronome at 176 BPM and another locked 40 ms after it, each heard on two
    microphones: the second ``place_gap_db`` louder on the right than the first."""
    rng = np.random.default_rng(5)
    first = 0.2 + np.arange(110) * 60 / 176 + rng.normal(0, 0.4e-3, 110)
    second = first + 0.040 + rng.normal(0, 0.4e-3, 110)
    times = np.concatenate([first, second])
    right = np.concatenate([np.zeros(110), np.full(110, place_gap_db)])
    levels = np.column_stack([np.full(220, -20.0), -20.0 + right]) + rng.normal(0, 0.5, (220, 2))
    order = np.argsort(times)
    return times[order], levels[order], np.concatenate([np.zeros(110), np.ones(110)])[order]


def test_two_metronomes_locked_at_one_offset_are_two_where_heard_from_two_places():
    times, levels, truth = _locked_pair(12.0)
    heard, _ = decompose(times, channel_levels=levels)
    assert len(heard) == 2
    held = sorted(set(truth[h.ticks]) for h in heard)
    assert held == [{0.0}, {1.0}] and all(h.ticks.size >= 105 for h in heard)


def test_a_tick_whose_impacts_come_from_one_place_is_one_metronome():
    """In timing alone the pair above is one tick of two impacts: heard from one place
    (a strike and its bounce), it is one metronome."""
    times, levels, _ = _locked_pair(0.0)
    heard, _ = decompose(times, channel_levels=levels)
    assert len(heard) == 1 and len(heard[0].followed.structure[0].impacts) == 2


def test_a_tempo_window_holds_when_a_metronome_is_followed_again():
    # asked for 42.5-57.5 BPM, a 100 BPM metronome is heard at half its tempo; followed
    # again, it must not be taken at twice that, outside the window
    _, onsets = mixture([100.0], seed=2)
    heard, _ = decompose(onsets, bpm_range=(42.5, 57.5))
    assert heard and all(42.5 <= h.followed.timing.bpm <= 57.5 for h in heard)


def test_a_metronome_followed_at_a_quarter_of_its_tempo_is_taken_at_its_tempo():
    from metrosync.audio.decompose import _at_its_tempo, _metronome

    loud, onsets = metronome(160.0, 40.0, seed=6)
    quarter = _metronome(onsets, 40.0)
    assert quarter is not None  # every fourth beat is a metronome too
    bpm, followed = _at_its_tempo(onsets, 40.0, quarter, None)
    assert bpm == 160.0 and followed.timing.bpm == pytest.approx(160.0, abs=0.1)
    assert np.allclose(np.sort(onsets[followed.ticks]), loud)


def _falling_into_step(seed=3):
    """Metronome A at 185 BPM; B, a little slower, catches it up, is one sound with it
    for 16 beats (B's onset not heard), and comes out the other side, pulled to a beat
    0.2 % shorter. Each of its own make: features (17 dB values)
    about centres 40 dB apart."""
    rng = np.random.default_rng(seed)
    period = 60 / 185
    k = np.arange(int(58 / period))
    a = 0.2 + k * period
    gap = 0.060 * (1 - k / 100)  # B 60 ms behind, closing, one with A for 16 beats
    b = a + np.where(k < 100, gap, 0.0) - np.where(k > 116, 0.002 * period * (k - 116), 0.0)
    b = b + rng.normal(0, 0.2e-3, k.size)
    a = a + rng.normal(0, 0.2e-3, k.size)
    b_heard = b[np.abs(b - a) > 2e-3]
    t = np.concatenate([a, b_heard])
    who = np.concatenate([np.zeros(a.size), np.ones(b_heard.size)])
    x = np.where(who[:, None] == 0, 0.0, 40.0 / np.sqrt(17)) + rng.normal(0, 2.0, (t.size, 17))
    order = np.argsort(t)
    return t[order], x[order], who[order], a, b_heard


def test_two_makes_falling_into_step_are_each_followed_through_by_their_sound():
    t, x, who, a, b = _falling_into_step()
    # by timing alone, B is lost where it comes out of A's ticks and found again as a
    # third metronome
    assert len(decompose(t)[0]) == 3
    heard, _ = decompose(t, features=x)
    assert len(heard) == 2
    for h in heard:
        mine = who[h.ticks]
        m = int(np.median(mine))
        assert np.mean(mine == m) >= 0.98  # where 2 ms apart, a tick can go to the other
        truth = a if m == 0 else b
        assert np.isin(np.round(truth, 9), np.round(t[h.ticks], 9)).mean() >= 0.98

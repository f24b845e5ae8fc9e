"""A tick's impacts learned from onsets of known structure; its time the regular one."""

import numpy as np
import pytest

from metrosync.audio import structure
from metrosync.audio.periodicity import candidate_tempi
from metrosync.audio.settings import MODEL
from metrosync.audio.structure import follow, learn_structure
from metrosync.audio.timing import Timing
from metrosync.errors import AnalysisError


def metronome(bpm, duration, *, limp=0.039, jitter=0.5e-3, precursor=(0.011, 0.042, 0.88),
              bounce=(0.025, 1.5e-3, 0.7), phase=0.2, seed=0):  # fmt: skip
    """Onsets of one metronome: its loud impacts, a precursor before most of them with a
    lead drawn anew each tick from ``precursor``'s range, a bounce after some."""
    rng = np.random.default_rng(seed)
    period = 60.0 / bpm
    k = np.arange(int((duration - phase) / period) - 1)
    loud = Timing(phase, period, limp, 0.0, 0.0, (0.0,) * 4, k.size).predict(k)
    loud = loud + rng.normal(0, jitter, k.size)
    lo, hi, share = precursor
    early = loud - rng.uniform(lo, hi, k.size)
    early = early[rng.uniform(size=k.size) < share]
    delay, spread, share = bounce
    late = loud + delay + rng.normal(0, spread, k.size)
    late = late[rng.uniform(size=k.size) < share]
    return loud, np.sort(np.concatenate([loud, early, late]))


def test_a_precursor_that_wanders_is_learned_and_the_loud_impact_times_the_tick():
    # as measured on a real phone recording: 96.4 BPM, limp 3.9 %, a quieter impact
    # 11-42 ms before 21 of 24 loud ones
    loud, onsets = metronome(96.4, 15.0)
    found = follow(onsets, 96.5)
    assert np.allclose(np.sort(onsets[found.ticks]), loud)
    for s in found.structure:  # the tick's and the tock's
        assert s.main_impact.offset == pytest.approx(0.0, abs=3e-4)
        assert s.main_impact.spread < 1e-3
        before = [i for i in s.impacts if i.offset < -5e-3]
        assert before and all(i.spread > 2 * s.main_impact.spread for i in before)
    assert found.timing.bpm == pytest.approx(96.4, abs=0.1)
    assert found.timing.limp == pytest.approx(0.039, abs=0.005)


def test_what_one_metronome_explains_leaves_no_second_one():
    loud, onsets = metronome(96.4, 15.0, seed=1)
    assert any(abs(c.bpm - 96.4) < 0.5 for c in candidate_tempi(onsets))
    found = follow(onsets, 96.4)
    left = onsets[found.impact < 0]
    assert left.size < 3 or not candidate_tempi(left)


@pytest.mark.parametrize("seed", range(5))
def test_over_many_draws_every_loud_impact_is_a_tick(seed):
    rng = np.random.default_rng(100 + seed)
    bpm = rng.uniform(60, 208)
    loud, onsets = metronome(bpm, 30.0, limp=rng.uniform(0, 0.06), seed=seed,
                             precursor=(0.010, 0.045, rng.uniform(0.5, 1.0)))  # fmt: skip
    found = follow(onsets, bpm * (1 + rng.uniform(-2e-3, 2e-3)))
    ticks = np.sort(onsets[found.ticks])
    assert ticks.size == loud.size and np.allclose(ticks, loud)


def test_clutter_is_left_to_no_impact():
    rng = np.random.default_rng(7)
    loud, onsets = metronome(120.0, 30.0, precursor=(0.02, 0.03, 0.0), bounce=(0.02, 1e-3, 0.0))
    noise = rng.uniform(0, 30, 15)
    every = np.sort(np.concatenate([onsets, noise]))
    found = follow(every, 120.0)
    assert np.allclose(np.sort(every[found.ticks]), loud)
    assert np.sum(found.impact[np.isin(every, noise)] >= 0) <= 2  # a few fall on a beat


def test_a_tick_of_one_impact_is_one_impact():
    rng = np.random.default_rng(8)
    offsets = rng.normal(0, 0.5e-3, 200)
    structure, label = learn_structure(offsets, 2 * np.arange(200), 0.2)
    assert len(structure.impacts) == 1 and np.all(label == 0)


def test_onsets_of_a_beat_that_slides_past_are_no_impact_of_the_tick():
    """Another metronome 0.4 beat slower over the recording: its onsets cross this one's
    beat at every offset. No impact wanders so far: they are clutter, not an impact."""
    from metrosync.audio.structure import learn_structure

    rng = np.random.default_rng(9)
    beats = np.arange(120)
    main = rng.normal(0.0, 0.4e-3, beats.size)
    sliding = np.linspace(-0.12, 0.12, beats.size)
    offsets = np.concatenate([main, sliding])
    structure, label = learn_structure(offsets, np.concatenate([beats, beats]), 0.15)
    assert all(i.spread <= MODEL.impact_spread[1] for i in structure.impacts)
    assert structure.main_impact.offset == pytest.approx(0.0, abs=0.3e-3)
    assert np.mean(label[beats.size :] == -1) > 0.8


def plain_em(d, means, spreads, shares, uniform, iterations):
    """The EM of `structure._mixture` written with NumPy arrays, all iterations run."""
    count = means.size
    for _ in range(iterations):
        dens = np.empty((d.size, count + 1))
        z = (d[:, None] - means) / spreads
        dens[:, :count] = shares[:count] * np.exp(-0.5 * z**2) / (spreads * np.sqrt(2 * np.pi))
        dens[:, count] = shares[count] * uniform
        total = dens.sum(axis=1)
        resp = dens / np.maximum(total, 1e-300)[:, None]
        weight = resp.sum(axis=0)
        shares = np.maximum(weight / d.size, 1e-9)
        held = weight[:count] > 1e-9
        safe = np.where(held, weight[:count], 1.0)
        means = np.where(held, (resp[:, :count] * d[:, None]).sum(axis=0) / safe, means)
        var = (resp[:, :count] * (d[:, None] - means) ** 2).sum(axis=0) / safe
        spreads = np.maximum(np.sqrt(var), MODEL.impact_spread[0])
    return means, spreads, shares, resp, total


@pytest.mark.parametrize("count", [1, 2, 3])
def test_the_compiled_em_is_the_plain_one(count):
    # A strike, a precursor 25 ms ahead in 70 % of the beats, and clutter over ±0.15 s.
    rng = np.random.default_rng(count)
    d = np.concatenate([rng.normal(0.0, 0.6e-3, 300), rng.normal(-0.025, 3e-3, 210),
                        rng.uniform(-0.15, 0.15, 60)])  # fmt: skip
    start = (np.array([0.0, -0.02, 0.01][:count]), np.full(count, 2e-3),
             np.full(count + 1, 1.0 / (count + 1)))  # fmt: skip
    expected = plain_em(d, *(a.copy() for a in start), 1 / 0.3, 60)
    means, spreads, shares = (a.copy() for a in start)
    resp, total = structure._em(d, means, spreads, shares, 1 / 0.3, 60, MODEL.impact_spread[0])
    for got, want in zip((means, spreads, shares, resp, total), expected, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_beats_are_numbered_right_far_into_a_drifting_recording():
    # 161 BPM speeding up by 0.05 BPM a minute for ten minutes: by the end the drift's
    # ½·Ṫ·k² has moved beat k 2.3 beats from (t − φ)/T, and the limp moves odd beats
    period, drift = 60.0 / 161.25, -7.2e-7
    timing = Timing(0.3, period, 0.04, drift, 0.5e-3, (0.0,) * 4, 1600)
    k = np.arange(1612)
    t = timing.predict(k) + np.random.default_rng(0).normal(0, 0.5e-3, k.size)
    assert 0.5 * abs(drift) * k[-1] ** 2 > 2 * period
    beat, offset = structure._nearest_beats(t, timing)
    np.testing.assert_array_equal(beat, k)
    assert np.abs(offset).max() < 3e-3


def test_another_metronomes_beat_passing_is_no_impact_but_a_sparse_bounce_is():
    # 600 beats of one kind: the main impact at most of them, a bounce at a random third
    # of them all along, and another metronome's ticks crossing one offset in two runs
    rng = np.random.default_rng(3)
    beats = np.arange(0, 1200, 2)
    main = beats[rng.uniform(size=beats.size) < 0.9]
    bounce = beats[rng.uniform(size=beats.size) < 0.3]
    passing = np.concatenate([beats[100:130], beats[400:425]])
    every = np.concatenate([main, bounce, passing])
    label = np.repeat([0, 1, 2], [main.size, bounce.size, passing.size])
    assert structure._passing(every, label, 3).tolist() == [False, False, True]
    # the main impact is not tested, even where it comes in runs
    assert not structure._passing(passing, np.zeros(passing.size, dtype=int), 1).any()


def _precursor_and_strike():
    """A tick as a Neewer strikes it: a wandering precursor ~20 ms ahead, the strike."""
    impacts = (structure.Impact(-0.020, 0.008, 0.9), structure.Impact(0.0, 0.5e-3, 1.0))
    return structure.Structure(impacts, main=1, clutter=0.01)


def test_a_beat_s_onsets_are_paired_with_its_impacts_one_to_one():
    # both onsets of beat 0 are, each alone, likelier the strike than the precursor (the
    # strike's density is sharp and tall); an impact is struck once a beat, so the
    # earlier is the precursor. Beat 2's lone early onset stays the precursor's, and
    # beat 4's onset far from both is clutter.
    s = _precursor_and_strike()
    offset = np.array([-1.2e-3, 0.3e-3, -0.021, 0.3])
    beat = np.array([0, 0, 2, 4])
    assert structure._assigned(offset, beat, s, reach=0.45).tolist() == [0, 1, 0, -1]
    # the pairing does not depend on the onsets' order
    flip = np.array([1, 0, 2, 3])
    assert structure._assigned(offset[flip], beat[flip], s, 0.45).tolist() == [1, 0, 0, -1]


def test_the_strike_s_timing_is_heavy_tailed_and_each_impact_s_rate_sums_to_its_presence():
    s = _precursor_and_strike()
    x = np.linspace(-0.2, 0.2, 400_001)
    dx = x[1] - x[0]
    for j, impact in enumerate(s.impacts):
        assert np.exp(s.log_density(j, x)).sum() * dx == pytest.approx(impact.presence, rel=1e-3)
    # an escapement's 5-sigma error is far likelier under the strike's Student-t than
    # under a Gaussian of the same spread
    z5 = np.exp(s.log_density(1, 5 * 0.5e-3)) * 0.5e-3
    assert z5 > 100 * np.exp(-12.5) / np.sqrt(2 * np.pi)


@pytest.mark.parametrize("seed", range(4))
def test_a_strike_s_rare_large_errors_stay_the_strike_s(seed):
    # 300 beats of one kind, a bounce at +25 ms after half of them, and the strike's
    # jitter 0.5 ms but for two escapement errors of +4 sigma: neither is an impact of
    # its own (a narrow component on the two), nor left to clutter or the bounce
    rng = np.random.default_rng(seed)
    beats = np.arange(0, 600, 2)
    strike = rng.normal(0, 0.5e-3, beats.size)
    strike[[40, 170]] = [2.0e-3, 2.1e-3]
    heard = rng.uniform(size=beats.size) < 0.5
    bounce = 0.025 + rng.normal(0, 1.5e-3, heard.sum())
    offsets = np.concatenate([strike, bounce])
    every = np.concatenate([beats, beats[heard]])
    s, _ = learn_structure(offsets, every, reach=0.2)
    assert len(s.impacts) == 2
    assert s.main_impact.offset == pytest.approx(0.0, abs=2e-4)
    label = structure._assigned(offsets, every, s, reach=0.2)
    assert np.all(label[: beats.size] == s.main)


def test_the_uniformity_test_is_scipy_s_kolmogorov_smirnov():
    from scipy.stats import kstest

    rng = np.random.default_rng(1)
    for n in (5, 12, 40, 300):
        for power in (1.0, 2.0, 3.0):  # uniform, and ever less so
            u = rng.uniform(size=n) ** power
            expected = kstest(u, lambda x: np.clip(x, 0.0, 1.0)).pvalue
            assert structure._uniformity_p(u) == pytest.approx(expected, rel=1e-12, abs=1e-300)


def test_another_metronome_in_a_whole_number_ratio_is_no_impact_but_a_random_one_is():
    # 40 beats of one kind: a bounce at a random third of them, another metronome
    # ticking 5 beats to this one's 3 near one offset at every third beat of the kind
    rng = np.random.default_rng(4)
    beats = np.arange(0, 80, 2)
    main = beats
    bounce = beats[rng.uniform(size=beats.size) < 0.35]
    neighbour = beats[::3]
    every = np.concatenate([main, bounce, neighbour])
    label = np.repeat([0, 1, 2], [main.size, bounce.size, neighbour.size])
    assert structure._locked(every, label, 3).tolist() == [False, False, True]
    # odd beats (the tock's) alike, and the main impact is not tested
    assert structure._locked(every + 1, label, 3).tolist() == [False, False, True]
    assert not structure._locked(neighbour, np.zeros(neighbour.size, dtype=int), 1).any()
    # over many random bounces, hardly ever one taken for a neighbour
    taken = 0
    for seed in range(200):
        r = np.random.default_rng(seed)
        b = beats[r.uniform(size=beats.size) < r.uniform(0.2, 0.9)]
        taken += structure._locked(np.concatenate([main, b]),
                                   np.repeat([0, 1], [main.size, b.size]), 2)[1]  # fmt: skip
    assert taken <= 2


def test_a_kind_hidden_for_the_first_seconds_is_heard_after_them():
    # other metronomes' ticks can hide one kind's (here the tocks) for seconds on end:
    # the first stretch grows until the tock is heard in half its beats
    loud, onsets = metronome(83.5, 40.0, precursor=(0.011, 0.042, 0.5), seed=3)
    k = np.arange(loud.size)
    hidden = (loud < 12.0) & (k % 2 == 1) & (k > 1)
    near = np.abs(onsets[:, None] - loud[hidden][None, :]) < 0.06  # the whole tick
    onsets = onsets[~near.any(axis=1)]
    found = follow(onsets, 83.5)
    assert found.timing.bpm == pytest.approx(83.5, abs=0.1)
    assert np.allclose(np.sort(onsets[found.ticks]), loud[~hidden])


def test_a_kind_hidden_for_50_s_is_heard_after_it_however_many_doublings_it_takes():
    # the first stretch doubled four times: each doubling is no round of the fit
    loud, onsets = metronome(83.5, 600.0, precursor=(0.011, 0.042, 0.5), seed=3)
    k = np.arange(loud.size)
    hidden = (loud < 50.0) & (k % 2 == 1) & (k > 1)
    near = np.abs(onsets[:, None] - loud[hidden][None, :]) < 0.06
    onsets = onsets[~near.any(axis=1)]
    found = follow(onsets, 83.5)
    assert np.allclose(np.sort(onsets[found.ticks]), loud[~hidden])


def _hidden_for_a_while(seed=2):
    """A 185 BPM metronome whose ticks another's hide from 30 s to 36 s, while the pull
    of the others shortens its beat by 0.2 %; and clutter."""
    rng = np.random.default_rng(seed)
    period = 60 / 185
    t = 0.2 + np.arange(int(60 / period)) * period
    after = t > 30
    t[after] -= np.cumsum(np.full(after.sum(), 0.002 * period))
    t = t + rng.normal(0, 0.2e-3, t.size)
    heard = t[(t < 30) | (t > 36)]
    return heard, np.sort(np.concatenate([heard, rng.uniform(0, 60, 40)]))


def test_ticks_lost_behind_another_s_are_found_again_where_they_come_out():
    ticks, onsets = _hidden_for_a_while()
    found = follow(onsets, 185.0, refind=True)
    assert np.allclose(np.sort(onsets[found.ticks]), ticks)
    # carried past the gap, the timing misses the ticks after it by 12 ms and more
    with pytest.raises(AnalysisError, match="half the beats"):
        follow(onsets, 185.0)


def test_the_loudest_of_impacts_as_regular_as_the_sharpest_is_the_strike():
    # a strike timed less well than the bounces it makes (they keep its jitter): the
    # strike; a precursor louder than the strike but wandering four times more: not it
    means, presence, levels = np.array([-0.025, 0.0, 0.017, 0.026]), np.ones(4), np.array(
        [-5.0, -6.0, -10.0, -9.0])  # fmt: skip
    spreads = np.array([4 * 0.5e-3, 0.5e-3, 0.32e-3, 0.29e-3])
    assert structure._main(means, spreads, presence, 50, levels, 0.0) == 1
    # with the strike heard in too few beats, the loudest of the bounces
    presence[1] = 0.2
    assert structure._main(means, spreads, presence, 50, levels, 0.0) == 3
    assert MODEL.strike_spread * 0.5e-3 < 4 * 0.5e-3  # the precursor stays out


def test_a_strike_timed_worse_than_its_bounces_still_times_the_tick():
    """The strike's onsets timed with 0.4 ms of detector noise and one in seven pulled
    1.3 ms early (another's impact just before it); two bounces struck by it, their
    onsets timed cleanly: their timing is more regular than the strike's, which still
    times the tick, as the loudest of the impacts that keep its jitter."""
    rng = np.random.default_rng(4)
    period = 60.0 / 100.0
    k = np.arange(95)
    strike = Timing(0.1, period, 0.0, 0.0, 0.0, (0.0,) * 4, k.size).predict(k)
    strike = strike + rng.normal(0, 0.3e-3, k.size)
    heard = strike + rng.normal(0, 0.4e-3, k.size) - np.where(k % 7 == 3, 1.3e-3, 0.0)
    onsets = np.concatenate([heard, strike + 0.0169, strike + 0.026])
    levels = np.concatenate([np.full(k.size, -6.0), np.full(k.size, -10.7),
                             np.full(k.size, -9.2)])  # fmt: skip
    order = np.argsort(onsets)
    found = follow(onsets[order], 100.0, levels[order])
    assert np.allclose(np.sort(onsets[order][found.ticks]), heard)

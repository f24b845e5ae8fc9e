"""Candidate tempi from onset times: trains found, clutter not."""

import numpy as np
import pytest

from metrosync.audio.periodicity import candidate_tempi, periodogram
from metrosync.audio.settings import MODEL
from metrosync.audio.timing import Timing


def train(bpm, duration, *, limp=0.03, jitter=0.5e-3, drift=0.0, phase=0.1, seed=0):
    period = 60.0 / bpm
    k = np.arange(int(duration / period) - 1)
    rng = np.random.default_rng(seed)
    t = Timing(phase, period, limp, drift, jitter, (0.0,) * 4, k.size).predict(k)
    return t + rng.normal(0, jitter, k.size)


def clutter(rate, duration, seed):
    rng = np.random.default_rng(seed)
    return np.sort(rng.uniform(0, duration, rng.poisson(rate * duration)))


def test_one_train_among_clutter_is_found_at_its_tempo():
    onsets = np.sort(np.concatenate([train(137.0, 40.0), clutter(1.0, 40.0, 1)]))
    found = candidate_tempi(onsets)
    # the clutter moves the peak by about its width (3 BPM) over √Z: the timing model,
    # not the search, times the train
    assert min(abs(c.bpm - 137.0) for c in found) < 0.2
    # its harmonics and subharmonics, and tempi whose summed harmonics meet its own (p/q
    # of it, q up to MODEL.harmonics) are candidates too, for the timing model to reject; no
    # tempo unrelated to 137 is
    m = MODEL.harmonics
    ratios = {p / q for q in range(1, m + 1) for p in range(1, 2 * m + 1)}
    assert all(min(abs(c.bpm / 137.0 - r) for r in ratios) < 0.01 for c in found)


def test_two_free_running_metronomes_4_bpm_apart_are_two_candidates():
    onsets = np.sort(np.concatenate([train(100.0, 40.0, seed=1), train(104.0, 40.0, seed=2)]))
    # the two strongest; the others are tempi whose summed harmonics meet theirs
    bpms = sorted(c.bpm for c in candidate_tempi(onsets, bpm_range=(60, 150))[:2])
    assert bpms == pytest.approx([100.0, 104.0], abs=0.1)


def test_a_drifting_tempo_over_ten_minutes_keeps_one_sharp_peak():
    onsets = train(150.0, 600.0, drift=-2e-7, seed=3)  # 150 → about 152 BPM
    found = candidate_tempi(onsets, bpm_range=(100, 200))
    assert 150.0 < found[0].bpm < 152.5
    # one peak there, however the tempo drifted, and the rest p/q of it, far weaker
    assert all(abs(c.bpm - found[0].bpm) > 10 and c.z < found[0].z / 3 for c in found[1:])


def test_clutter_alone_rarely_gives_a_candidate():
    alarms = sum(bool(candidate_tempi(clutter(3.0, 40.0, seed))) for seed in range(100))
    assert alarms <= 2  # MODEL.false_alarm = 1e-3 a recording: 0.1 expected


def test_clutter_has_a_mean_power_of_one_per_harmonic():
    _, z = periodogram(clutter(5.0, 200.0, 7), segment=60.0)
    assert np.mean(z) == pytest.approx(MODEL.harmonics, abs=0.05 * MODEL.harmonics)


def test_two_trains_at_one_tempo_half_a_beat_apart_are_a_candidate_at_that_tempo():
    """They cancel at the tempo's own frequency; its second harmonic finds them."""
    a, b = (
        train(184.0, 30.0, limp=0.0, seed=4),
        train(184.0, 30.0, limp=0.0, phase=0.1 + 30 / 184, seed=5),
    )
    found = candidate_tempi(np.sort(np.concatenate([a, b])))
    assert found and abs(found[0].bpm - 184.0) < 0.3


def test_three_trains_at_one_tempo_a_third_of_a_beat_apart_are_a_candidate_at_it():
    """A splay state cancels the first two harmonics; the third finds it."""
    period = 60 / 184.0
    trains = [
        train(184.0, 30.0, limp=0.0, phase=0.1 + i * period / 3, seed=6 + i) for i in range(3)
    ]
    found = candidate_tempi(np.sort(np.concatenate(trains)))
    assert any(abs(c.bpm - 184.0) < 0.3 for c in found)


def test_the_compiled_fold_is_the_plain_sum_of_harmonic_powers():
    """`_rayleigh` steps each onset's phasor from one frequency to the next; it must
    equal Σ_h |Σ_k w_k exp(2πi h f t_k)|² computed directly, over a long grid (the
    phasor is set afresh every few steps, so rounding does not build up)."""
    from metrosync.audio.periodicity import _rayleigh

    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 60.0, 300))
    w = rng.uniform(0.2, 1.0, t.size)
    f0, df, nf = 0.5, 1.0 / 300.0, 1400
    f = f0 + df * np.arange(nf)
    direct = sum(np.abs(np.exp(2j * np.pi * h * np.outer(f, t)) @ w) ** 2
                 for h in range(1, MODEL.harmonics + 1))  # fmt: skip
    got = _rayleigh(f0, df, nf, t, w, MODEL.harmonics)
    assert np.allclose(got, direct, rtol=1e-9, atol=1e-9 * direct.max())

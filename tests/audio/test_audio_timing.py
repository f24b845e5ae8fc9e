"""The timing model: known parameters back from constructed tick times."""

import numpy as np
import pytest

from metrosync.audio.timing import Timing, fit_timing, number_beats
from metrosync.errors import AnalysisError


def ticks(k, *, phase=0.31, period=0.5, limp=0.04, drift=2e-6, jitter=0.5e-3, seed=0):
    truth = Timing(phase, period, limp, drift, jitter, (0.0,) * 4, len(k))
    rng = np.random.default_rng(seed)
    return truth, truth.predict(k) + rng.normal(0.0, jitter, np.shape(k))


def test_each_parameter_comes_back_within_its_error():
    k = np.arange(600)
    truth, t = ticks(k)
    fit = fit_timing(t, k)
    for name, err in zip(("phase", "period", "limp", "drift"), fit.errors, strict=True):
        assert abs(getattr(fit, name) - getattr(truth, name)) < 4 * err, name
    assert fit.jitter == pytest.approx(0.5e-3, rel=0.1)
    assert fit.bpm == pytest.approx(120.0, abs=0.01)


def test_the_stated_errors_are_the_scatter_over_recordings():
    k = np.arange(200)
    pulls = []
    for seed in range(200):
        truth, t = ticks(k, seed=seed)
        fit = fit_timing(t, k)
        pulls.append([(fit.period - truth.period) / fit.errors[1],
                      (fit.limp - truth.limp) / fit.errors[2]])  # fmt: skip
    spread = np.std(pulls, axis=0)
    assert np.all((spread > 0.8) & (spread < 1.25)), spread


def test_the_mean_tempo_counts_the_beats_over_the_time_they_take():
    k = np.arange(400)
    truth, t = ticks(k, drift=1e-5, jitter=0.0)  # the beat lengthens by 4 ms over 400
    fit = fit_timing(t, k)
    assert fit.mean_bpm(0, 399) == pytest.approx(60 * 399 / (t[-1] - t[0]), rel=1e-9)
    assert fit.mean_bpm(0, 399) < fit.bpm


def test_missed_beats_and_an_odd_first_beat_change_nothing():
    k = np.arange(3, 400)
    k = k[(k % 7 != 0) & (k % 11 != 0)]  # beats nobody heard
    truth, t = ticks(k, seed=3)
    fit = fit_timing(t, k)
    assert fit.limp == pytest.approx(truth.limp, abs=4 * fit.errors[2])
    assert fit.predict([1000])[0] == pytest.approx(truth.predict([1000])[0], abs=2e-3)


def test_a_few_far_mistimed_ticks_do_not_bend_the_model():
    k = np.arange(300)
    truth, t = ticks(k, drift=0.0, seed=4)
    wrong = t.copy()
    wrong[::25] += 0.02  # 12 ticks timed on another metronome's sound, 20 ms late
    fit = fit_timing(wrong, k)
    assert abs(fit.period - truth.period) < 1e-6
    assert fit.jitter == pytest.approx(0.5e-3, rel=0.15)
    assert np.sum(np.abs(fit.residuals(wrong, k)) > 0.01) == 12


def test_weights_take_a_tick_out_of_the_fit():
    k = np.arange(100)
    truth, t = ticks(k, drift=0.0, seed=5)
    t[10] += 0.1
    weights = np.ones(100)
    weights[10] = 0.0
    assert fit_timing(t, k, weights).ticks == 99
    assert fit_timing(t, k, weights).period == pytest.approx(truth.period, abs=1e-5)


def test_without_drift_the_drift_is_zero_and_the_rest_fitted():
    k = np.arange(80)
    truth, t = ticks(k, drift=0.0, seed=6)
    fit = fit_timing(t, k, drift=False)
    assert fit.drift == 0.0 and fit.errors[3] == 0.0
    assert fit.period == pytest.approx(truth.period, abs=3 * fit.errors[1])


def test_too_few_ticks_or_no_odd_beat_is_refused():
    with pytest.raises(AnalysisError, match="at least 6 ticks"):
        fit_timing(np.arange(5.0), np.arange(5))
    with pytest.raises(AnalysisError, match="undetermined"):
        fit_timing(np.arange(10.0), 2 * np.arange(10))


def test_beats_are_numbered_through_gaps_and_drift():
    k = np.arange(1500)
    truth, t = ticks(k, period=0.3, drift=-1e-6, limp=0.03, seed=7)  # 200 → 203 BPM
    heard = np.delete(np.arange(1500), [5, 6, 100, 700, 701, 702])
    assert np.array_equal(number_beats(t[heard], 0.3), heard)


def test_the_doubled_timing_puts_its_even_beats_on_the_beats_it_came_from():
    k = np.arange(0, 120)
    # a timing at half a metronome's tempo spans tick and tock in each beat: no limp
    _, t = ticks(k, limp=0.0, drift=3e-5, jitter=0.3e-3, seed=4)
    t = t + np.cumsum(np.cumsum(np.random.default_rng(5).normal(0, 2e-5, k.size)))  # a wander
    slow = fit_timing(t, k, wander=True)
    assert slow.wander is not None
    fast = slow.doubled()
    assert fast.bpm == pytest.approx(2 * slow.bpm)
    assert np.allclose(fast.predict(2 * k), slow.predict(k) - slow.limp * slow.period / 2 * (k % 2),
                       atol=1e-9)
    assert fast.mean_bpm(0, 236) == pytest.approx(2 * slow.mean_bpm(0, 118))

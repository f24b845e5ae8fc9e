"""The beat's wander about the timing model (`audio.wander`): the Kalman smoother
against a dense Gaussian posterior, its choice of the process noise, and the timing
model with and without it, on constructed tick times of known answer."""

import numpy as np
import pytest
from scipy.stats import multivariate_normal

from metrosync.audio import wander as wd
from metrosync.audio.timing import fit_timing

JITTER = 0.5e-3


def irw(beats, q, rng):
    """An integrated random walk of process noise ``q`` (s per beat) at unit beats."""
    rate = np.cumsum(rng.normal(0.0, q, beats))
    return np.cumsum(rate)


def dense_posterior(k, r, noise, q, prior):
    """The smoothed (g, ġ) by the joint Gaussian of every state, written out densely:
    x_0 ~ N(0, prior·I), x_{i+1} = F x_i + η_i, observed g_i + e_i, e_i ~ N(0, noise_i)."""
    n = k.size
    # each state as a linear map of the start and the increments: x_i = A_i z, z ~ N(0, S)
    size = 2 + 2 * (n - 1)
    s = np.zeros((size, size))
    s[:2, :2] = prior * np.eye(2)
    maps = [np.zeros((2, size))]
    maps[0][:, :2] = np.eye(2)
    for i in range(1, n):
        d = k[i] - k[i - 1]
        f = np.array([[1.0, d], [0.0, 1.0]])
        block = slice(2 * i, 2 * i + 2)
        s[block, block] = q * q * np.array([[d**3 / 3, d**2 / 2], [d**2 / 2, d]])
        step = f @ maps[-1]
        step[:, block] += np.eye(2)
        maps.append(step)
    a = np.array(maps)  # (n, 2, size)
    h = a[:, 0, :]  # the observed g_i
    cov_y = h @ s @ h.T + np.diag(noise)
    z = s @ h.T @ np.linalg.solve(cov_y, r)
    # the log-likelihood of the residuals after the first two, given those two
    loglik = multivariate_normal(cov=cov_y).logpdf(r) - multivariate_normal(
        cov=cov_y[:2, :2]).logpdf(r[:2])  # fmt: skip
    return a @ z, loglik  # (n, 2), float


def test_the_smoother_is_the_dense_gaussian_posterior():
    rng = np.random.default_rng(3)
    k = np.cumsum(rng.choice([1, 1, 1, 2, 3], 40)).astype(float)  # missed beats too
    r = irw(int(k[-1]) + 1, 2e-4, rng)[k.astype(int)] + rng.normal(0, JITTER, k.size)
    noise = np.full(k.size, JITTER**2) / rng.uniform(0.3, 1.0, k.size)
    out = np.empty((k.size, 2))
    start = 1e-4  # s²: a start the dense solve is well conditioned with
    loglik = wd._kalman(k, r, noise, 2e-4, start, out)
    expected, expected_loglik = dense_posterior(k, r, noise, 2e-4, start)
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-12)
    assert loglik == pytest.approx(expected_loglik, rel=1e-9)


def test_a_wandering_beat_is_followed_and_its_noise_found():
    rng = np.random.default_rng(7)
    q = 1e-4  # a fifth of the jitter per beat
    g = irw(600, q, rng)
    k = np.arange(600.0)
    found = wd.smooth_wander(k, g + rng.normal(0, JITTER, k.size), np.ones(k.size), JITTER)
    assert found is not None
    assert q / 3 < found.q < 3 * q  # the maximum-likelihood noise, of known answer
    # smoothed far below the jitter: it follows the wander, not the ticks' scatter
    assert np.sqrt(np.mean((found.at(k) - g) ** 2)) < 0.5 * JITTER


def test_white_jitter_about_a_straight_beat_asks_for_no_wander():
    rng = np.random.default_rng(11)
    for seed in range(5):
        rng = np.random.default_rng(seed)
        k = np.arange(400.0)
        r = rng.normal(0, JITTER, k.size)
        assert wd.smooth_wander(k, r, np.ones(k.size), JITTER) is None, seed


def test_too_few_ticks_or_no_jitter_give_none():
    k = np.arange(wd.MIN_TICKS - 1.0)
    assert wd.smooth_wander(k, np.sin(k) * 1e-2, np.ones(k.size), JITTER) is None
    k = np.arange(100.0)
    assert wd.smooth_wander(k, np.zeros(k.size), np.ones(k.size), 0.0) is None


def test_the_wander_continues_at_its_rate_past_the_ends():
    w = wd.Wander(np.array([0.0, 1.0, 2.0]), np.array([0.0, 1e-3, 2e-3]),
                  np.array([1e-3, 1e-3, 1e-3]), 1e-4)  # fmt: skip
    np.testing.assert_allclose(w.at([-2.0, 0.5, 5.0]), [-2e-3, 0.5e-3, 5e-3], atol=1e-15)
    assert w.spread_after(0) == 0 and w.spread_after(3) == pytest.approx(1e-4 * 3.0)


def pulled_ticks(rng, beats=300, pull=0.012):
    """A metronome pulled by others: 10 ms of phase over some 80 beats, on a limp."""
    k = np.arange(beats)
    period, limp = 0.32, 0.03
    g = pull * np.sin(2 * np.pi * k / 160.0) * np.exp(-k / 200.0)
    t = 0.7 + k * period + 0.5 * limp * period * (k % 2) + g + rng.normal(0, JITTER, beats)
    return t, k, period, limp


def test_the_timing_model_follows_a_pulled_metronome_and_keeps_its_tempo_and_limp():
    rng = np.random.default_rng(5)
    t, k, period, limp = pulled_ticks(rng)
    plain = fit_timing(t, k)
    wandering = fit_timing(t, k, wander=True)
    assert plain.wander is None and wandering.wander is not None
    assert np.abs(plain.residuals(t, k)).max() > 8 * JITTER  # a straight model leaves it
    assert np.abs(wandering.residuals(t, k)).max() < 5 * JITTER
    assert wandering.jitter == pytest.approx(JITTER, rel=0.3)
    assert wandering.limp == pytest.approx(limp, abs=0.003)
    assert wandering.mean_bpm(0, 299) == pytest.approx(60 * 299 / (t[-1] - t[0]), abs=0.01)


def test_a_free_metronome_fitted_with_wander_is_fitted_as_without():
    rng = np.random.default_rng(9)
    k = np.arange(200)
    t = 0.1 + 0.3 * k + 0.004 * (k % 2) + rng.normal(0, JITTER, k.size)
    both = fit_timing(t, k), fit_timing(t, k, wander=True)
    assert both[1].wander is None
    assert both[0] == both[1]


def test_one_tick_far_off_bends_the_wander_little():
    rng = np.random.default_rng(13)
    t, k, _, _ = pulled_ticks(rng)
    t[150] += 0.02  # a tick timed on another's sound
    fitted = fit_timing(t, k, wander=True)
    assert fitted.residuals(t, k)[150] > 0.015
    assert np.abs(np.delete(fitted.residuals(t, k), 150)).max() < 5 * JITTER

import numpy as np
import pytest

from metrosync import simulate
from metrosync.observables import (
    analytic_phase,
    common_span,
    crossing_order,
    crossing_phase,
    ensemble_statistics,
    equilibrium_order,
    order_parameter,
)


def test_order_parameter_limits():
    assert order_parameter(np.zeros(5)) == pytest.approx(1.0)
    assert order_parameter(np.arange(4) * np.pi / 2) == pytest.approx(0.0, abs=1e-15)
    assert order_parameter([0.0, np.pi]) == pytest.approx(0.0, abs=1e-15)


def test_analytic_phase_of_a_harmonic_swing_advances_uniformly():
    omega, t = 10.0, np.linspace(0, 1, 101)
    phase = np.unwrap(
        analytic_phase(0.3 * np.cos(omega * t), -0.3 * omega * np.sin(omega * t), omega)
    )
    np.testing.assert_allclose(phase, omega * t, atol=1e-12)


def test_crossing_phase_rises_linearly_between_passes():
    times = np.array([1.0, 2.0, 4.0])
    grid = np.array([0.5, 1.0, 1.5, 2.0, 3.0, 3.999, 4.0, 5.0])
    phase = crossing_phase(times, grid)
    expected = [np.nan, 0.0, np.pi, 0.0, np.pi, 2 * np.pi * 0.9995, np.nan, np.nan]
    np.testing.assert_allclose(phase, expected, atol=1e-12)


def test_crossing_order_is_nan_outside_the_common_span():
    a = np.arange(0.0, 10.0, 1.0)
    b = a + 0.25  # a quarter period behind: r = cos(π/4)
    grid = np.linspace(0, 10, 101)
    r = crossing_order([a, b], grid)
    start, end = common_span([a, b])
    inside = (grid >= start) & (grid < end)
    assert np.all(np.isnan(r[~inside]))
    np.testing.assert_allclose(r[inside], np.cos(np.pi / 4), atol=1e-12)


def test_kernel_crossing_r_matches_the_observable_on_interpolated_crossings():
    ds = simulate(4, 192, sigma_bpm=2.0, runs=2, duration=30, trajectories=True, record_every=1)
    for b in range(2):
        th = ds.theta.isel(run=b).values
        t = ds.time.values
        crossings = []
        for i in range(th.shape[1]):
            k = np.nonzero((th[:-1, i] < 0) & (th[1:, i] > 0))[0]
            crossings.append(t[k] + (t[k + 1] - t[k]) * th[k, i] / (th[k, i] - th[k + 1, i]))
        expected = crossing_order(crossings, t)
        got = ds.r_crossing.isel(run=b).values
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
        np.testing.assert_allclose(got, expected, atol=1e-9, equal_nan=True)


def test_equilibrium_and_ensemble_statistics():
    time = np.arange(0, 100.0, 1.0)
    r = np.stack([np.where(time >= 75, 0.8, 0.1), np.where(time >= 75, 0.6, np.nan)], axis=1)
    r_eq = equilibrium_order(r, time, window=20)
    np.testing.assert_allclose(r_eq, [0.8, 0.6])
    mean, spread = ensemble_statistics([0.8, 0.6, np.nan])
    assert mean == pytest.approx(0.7) and spread == pytest.approx(np.std([0.8, 0.6], ddof=1))
    assert np.isnan(ensemble_statistics([np.nan])[0])

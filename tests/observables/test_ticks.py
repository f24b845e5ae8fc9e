"""Tick rate from simulated crossings: what a metronome tuned to a nominal BPM ticks at."""

import numpy as np
import pytest

from metrosync import OverturnWarning, simulate
from metrosync.observables.ticks import CrossingTally, rate_per_minute, tick_rate


def _upward_crossings(theta, time):
    """Upward zero crossings of a sampled θ(t), linearly interpolated."""
    up = np.nonzero((theta[:-1] < 0) & (theta[1:] >= 0))[0]
    return time[up] - theta[up] * (time[up + 1] - time[up]) / (theta[up + 1] - theta[up])


def test_a_192_bpm_metronome_ticks_at_184_6_per_minute_at_the_default_swing():
    ds = simulate(1, 192.0, duration=40.0, record_every=1, trajectories=True)
    span = ds.attrs["tick_rate_span"]
    assert span == pytest.approx(10.0)  # the final window, 40/4 s
    # Count the crossings of the recorded trajectory independently.
    t = ds.time.values
    crossings = _upward_crossings(ds.theta.values[:, 0, 0], t)
    kept = crossings[crossings >= t[-1] - span]
    expected = 120.0 * (kept.size - 1) / (kept[-1] - kept[0])
    measured = float(ds.tick_rate_bpm[0, 0])
    assert measured == pytest.approx(expected, abs=1e-3)
    assert 184.0 < measured < 185.2  # the small-swing tuning says 192
    assert float(ds.frequency_bpm[0, 0]) == pytest.approx(192.0)


def test_the_reference_integrator_measures_the_same_rate():
    kwargs = dict(duration=20.0, record_every=10, theta0=[0.7, -0.5], theta_dot0=[0.0, 0.0])
    verlet = simulate(2, 192.0, **kwargs)
    exact = simulate(2, 192.0, integrator="exact", **kwargs)
    assert np.all(np.isfinite(exact.tick_rate_bpm))
    np.testing.assert_allclose(verlet.tick_rate_bpm, exact.tick_rate_bpm, atol=0.5)


def test_counting_ticks_leaves_the_records_unchanged_and_numpy_agrees():
    kwargs = dict(sigma_bpm=1.0, runs=3, duration=12.0, record_every=3, seed=5)
    fast = simulate(3, 192.0, **kwargs)
    plain = simulate(3, 192.0, backend="numpy", **kwargs)
    np.testing.assert_allclose(fast.tick_rate_bpm, plain.tick_rate_bpm, rtol=1e-9)
    # The window sets where the segments for counting begin; the records must not see it.
    other = simulate(3, 192.0, equilibrium_window=1.0, **kwargs)
    np.testing.assert_array_equal(fast.r, other.r)
    np.testing.assert_array_equal(fast.r_crossing, other.r_crossing)
    assert fast.tick_rate_bpm.dims == ("run", "metronome")
    assert fast.tick_rate_bpm.attrs["units"] == "BPM"


def test_an_overturned_run_has_no_tick_rate():
    with pytest.warns(OverturnWarning):
        ds = simulate(2, 192.0, duration=5.0, amplitude=2.0)
    assert int(ds.status[0]) & 1
    assert np.all(np.isnan(ds.tick_rate_bpm))


def test_tally_counts_one_crossing_per_new_last_up():
    tally = CrossingTally(np.array([[-1.0, 0.2]]))
    for last_up in ([[-1.0, 0.2]], [[0.5, 0.2]], [[0.5, 0.9]], [[1.1, 0.9]], [[1.7, 1.6]]):
        tally.see(np.array(last_up))
    np.testing.assert_array_equal(tally.count, [[3, 2]])
    np.testing.assert_allclose(tally.rate(), [[120 * 2 / 1.2, 120 * 1 / 0.7]])
    assert np.isnan(rate_per_minute(0.0, 1.0, 1))
    np.testing.assert_allclose(tick_rate([[0.0, 0.5, 1.0, 1.5], [2.0]], since=0.4), [240, np.nan])

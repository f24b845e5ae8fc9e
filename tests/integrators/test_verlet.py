"""The compiled kernel against its plain NumPy twin, determinism, and convergence."""

import math

import numba
import numpy as np
import pytest

from metrosync import OverturnWarning, build_ensemble, get_preset, simulate
from metrosync.integrators import REGISTRY, twin, verlet
from metrosync.integrators._state import StepState
from metrosync.status import STATUS_DIVERGED, STATUS_OVERTURNED


def run_backend(backend, ensemble, steps, *, dt=0.01, record_every=10, chunks=1):
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=steps // record_every + 1, trajectories=True,
    )  # fmt: skip
    per = steps // chunks
    for c in range(chunks):
        backend.advance_state(
            state, ensemble.system, dt=dt, step0=c * per, n_steps=per,
            record_every=record_every, overturn_angle=math.pi / 2,
        )  # fmt: skip
    return state.one_coordinate()  # the disk's state per run


def test_compiled_kernel_matches_plain_reference_over_1000_steps(small_ensemble):
    fast = run_backend(verlet, small_ensemble, 1000)
    slow = run_backend(twin.VERLET, small_ensemble, 1000)
    assert np.count_nonzero(np.diff(np.sign(fast.traj_theta), axis=1)) > 50  # kicks happened
    for name in ("theta", "theta_dot", "phi", "phi_dot", "p_phi", "acc_theta"):
        np.testing.assert_allclose(getattr(fast, name), getattr(slow, name), rtol=0, atol=1e-10)
    np.testing.assert_allclose(fast.traj_theta, slow.traj_theta, rtol=0, atol=1e-10)
    np.testing.assert_allclose(fast.r, slow.r, rtol=0, atol=1e-10)
    np.testing.assert_allclose(fast.crossing_order(), slow.crossing_order(), rtol=0, atol=1e-10)
    np.testing.assert_array_equal(fast.status, slow.status)


def test_chunking_does_not_change_the_result(small_ensemble):
    one = run_backend(verlet, small_ensemble, 1000, chunks=1)
    many = run_backend(verlet, small_ensemble, 1000, chunks=10)
    np.testing.assert_array_equal(one.traj_theta, many.traj_theta)
    np.testing.assert_array_equal(one.cross_re, many.cross_re)


@pytest.mark.skipif(
    numba.config.NUMBA_NUM_THREADS < 2, reason="numba is limited to one thread here"
)
def test_results_identical_for_any_thread_count():
    kwargs = dict(sigma_bpm=1.0, runs=6, duration=60, seed=5)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = simulate(7, 192, **kwargs)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        multi = simulate(7, 192, **kwargs)
    finally:
        numba.set_num_threads(threads)
    assert single.identical(multi)


def test_same_seed_same_result_other_seed_other_result():
    a = simulate(4, 192, sigma_bpm=1.0, runs=2, duration=20, seed=1)
    b = simulate(4, 192, sigma_bpm=1.0, runs=2, duration=20, seed=1)
    c = simulate(4, 192, sigma_bpm=1.0, runs=2, duration=20, seed=2)
    assert a.identical(b)
    assert not np.array_equal(a.r.values, c.r.values)


def global_error(dt, t_end=5.0):
    """Error at t_end of the undriven, damped system against a dt/64 solution."""
    params = get_preset("default").with_changes(drive=0.0)
    ens = build_ensemble(3, 192.0, params=params, sigma_bpm=3.0, runs=2, seed=4, amplitude=0.5)

    def final(step):
        n = int(round(t_end / step))
        s = run_backend(verlet, ens, n, dt=step, record_every=n)
        return np.concatenate([s.theta.ravel(), s.theta_dot.ravel(), s.phi, s.phi_dot])

    return np.max(np.abs(final(dt) - final(dt / 64)))


def test_verlet_has_its_declared_order_without_kicks():
    dts = np.array([0.02, 0.01, 0.005, 0.0025])
    errors = np.array([global_error(dt) for dt in dts])
    order = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert order == pytest.approx(REGISTRY["verlet"].order, abs=0.3), (order, errors)


def test_verlet_has_its_declared_order_with_kicks():
    """Against ``exact`` over 5 s: the kick is quantised to the step, so first order.
    The error of one dt swings with the phase at which kicks land, so the slope is
    fitted over decades of dt (measured 0.13, 0.017, 0.0011 rad: slope 1.03)."""
    start = dict(theta0=[0.1, -0.05], duration=5.0, trajectories=True)
    kw = dict(frequencies_bpm=[192.0, 192.0], **start)
    exact = simulate(None, None, integrator="exact", dt=0.01, record_every=10, **kw)
    dts = np.array([0.01, 0.001, 0.0001])
    errors = []
    for dt in dts:
        fixed = simulate(None, None, dt=dt, record_every=int(round(0.1 / dt)), **kw)
        errors.append(np.max(np.abs(fixed.theta.values - exact.theta.values)))
    order = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert order == pytest.approx(REGISTRY["verlet"].order_with_kicks, abs=0.3), (order, errors)


def test_a_diverging_run_is_flagged_and_does_not_stop_the_others():
    theta_dot0 = np.zeros((3, 4))
    theta_dot0[1, 2] = 1e200  # θ̇² overflows: this run must be flagged, the others go on
    with pytest.warns(OverturnWarning, match="1 of 3 run"):  # the start swings past π/2
        ds = simulate(4, 192, runs=3, duration=10, theta0=np.full((3, 4), 0.3),
                      theta_dot0=theta_dot0)  # fmt: skip
    assert ds.status.values[1] & STATUS_DIVERGED
    assert ds.status.values[0] == 0 and ds.status.values[2] == 0
    assert np.isfinite(ds.r.isel(run=0)).all() and np.isfinite(ds.r.isel(run=2)).all()
    assert np.isnan(ds.r.isel(run=1, time=-1))


def test_overturning_is_flagged():
    with pytest.warns(Warning, match="overturn"):
        ds = simulate(2, 192, preset="boda2013", runs=2, duration=20, theta0=[0.1, -0.05])
    assert np.all(ds.status.values & STATUS_OVERTURNED)

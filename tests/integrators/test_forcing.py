"""A periodic torque on the disk (``forcing_amplitude``, ``forcing_bpm``): integrated
alike by every integrator, and entraining one metronome within a locking range that
grows linearly with the amplitude."""

import math
from dataclasses import replace

import numpy as np
import pytest

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.integrators import verlet
from metrosync.integrators._state import StepState
from metrosync.model import bpm_to_omega
from metrosync.observables.entrainment import forcing_lag, is_entrained, upward_crossings


def tick_bpm(ds, after):
    """The metronome's mean beat rate after ``after`` s, from its upward crossings."""
    crossings = upward_crossings(ds.time.values, ds.theta.values[:, 0, 0])
    crossings = crossings[crossings > after]
    return 120.0 * (crossings.size - 1) / (crossings[-1] - crossings[0])


def one_metronome(dt, duration, **changes):
    return simulate(
        1, 192, duration=duration, dt=dt, theta0=[0.76], changes=changes or None,
        trajectories=True, record_every=max(1, round(0.01 / dt)),
    )  # fmt: skip


def test_the_fixed_step_scheme_follows_exact_on_a_forced_disk():
    """The torque enters `exact` through `equations`, the kernels through `_physics`:
    two codes, one trajectory (the disk is forced hard, far from resonance)."""
    changes = {"forcing_amplitude": 0.05, "forcing_bpm": 150.0}
    kwargs = dict(duration=3.0, theta0=[0.3, -0.2], trajectories=True, record_every=10)
    want = simulate(2, 192, dt=0.001, integrator="exact", changes=changes, **kwargs)
    got = simulate(2, 192, dt=0.0001, changes=changes, record_every=100, **{
        k: v for k, v in kwargs.items() if k != "record_every"})  # fmt: skip
    unforced = simulate(2, 192, dt=0.001, integrator="exact", **kwargs)
    moved = float(np.abs(want.phi - unforced.phi).max())
    assert moved > 0.1  # rad: the torque turns the disk a lot ...
    # ... and both follow it alike (measured: 3.6e-7 rad). The pendulums differ by the
    # fixed-step kick's quantisation (7e-4 rad, as without the torque).
    np.testing.assert_allclose(got.phi, want.phi, atol=1e-5 * moved)
    np.testing.assert_allclose(got.theta, want.theta, atol=2e-3)


def test_one_metronome_entrains_near_its_frequency_only():
    free = tick_bpm(one_metronome(0.002, 200.0), after=50)
    near = one_metronome(0.002, 400.0, forcing_amplitude=0.01, forcing_bpm=free + 0.3)
    far = one_metronome(0.002, 400.0, forcing_amplitude=0.01, forcing_bpm=free + 3.0)
    time = near.time.values
    assert is_entrained(time, near.theta.values[:, 0, 0], free + 0.3, window=200)
    assert not is_entrained(time, far.theta.values[:, 0, 0], free + 3.0, window=200)
    # Entrained, it beats at the drive's rate, not its own ...
    assert tick_bpm(near, after=200) == pytest.approx(free + 0.3, abs=2e-3)
    # ... while the far drive barely moves it, and the lag slips by whole turns.
    assert tick_bpm(far, after=200) == pytest.approx(free, abs=0.3)
    crossings = upward_crossings(time, far.theta.values[:, 0, 0])
    assert np.ptp(forcing_lag(crossings[crossings > 200], free + 3.0)) > 4 * np.pi


def test_entrainment_needs_crossings_in_its_window():
    ds = one_metronome(0.01, 5.0)
    with pytest.raises(ParameterError, match=r"`window` = 0.5 s holds \d upward crossings"):
        is_entrained(ds.time.values, ds.theta.values[:, 0, 0], 185.0, window=0.5)


def entrained(amplitudes, bpms, *, dt, duration, window):
    """Whether one metronome on the disk, driven at each (amplitude, BPM), locks to the
    drive: all in one ensemble, one run per pair (the forcing is a per-run constant)."""
    params = get_preset("default").with_changes(forcing_amplitude=1.0, forcing_bpm=180.0)
    ens = build_ensemble(1, 192, params=params, runs=len(bpms), theta0=[0.76])
    system = replace(
        ens.system,
        forcing_amplitude=np.asarray(amplitudes, dtype=float),
        forcing_omega=bpm_to_omega(np.asarray(bpms, dtype=float)),
    )
    steps, every = round(duration / dt), 20
    state = StepState.start(system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                            n_records=steps // every + 1, trajectories=True)  # fmt: skip
    verlet.advance_state(state, system, dt=dt, step0=0, n_steps=steps, record_every=every,
                         overturn_angle=math.pi / 2)  # fmt: skip
    time = np.arange(state.traj_theta.shape[1]) * dt * every
    return np.array([
        is_entrained(time, state.traj_theta[b, :, 0], bpm, window=window)
        for b, bpm in enumerate(bpms)
    ])  # fmt: skip


@pytest.mark.slow
def test_the_locking_range_grows_linearly_with_the_amplitude():
    """Arnold tongue of one metronome: both edges found by bisection to 0.004 BPM.

    dt = 0.001 s, because the paper's 0.01 s quantises each kick to 1.5 % of a period,
    which at small amplitudes blurs the edges; 600 s to lock, then a 1200 s window,
    which resolves a slip rate well below the edge accuracy (`metrosync.observables.
    entrainment`). Measured (2026-11-21): widths 0.630, 1.231, 2.451, 3.694 BPM at
    A = 5, 10, 20, 30 mN m; slope 122.6 BPM per N m, intercept 0.010 BPM."""
    run = dict(dt=0.001, duration=1800.0, window=1200.0)
    free = tick_bpm(one_metronome(0.001, 300.0), after=100)
    amplitudes = np.array([0.005, 0.01, 0.02, 0.03])
    k = amplitudes.size
    assert entrained(amplitudes, np.full(k, free), **run).all()
    amps = np.concatenate([amplitudes, amplitudes])
    inner = np.full(2 * k, free)
    reach = 80 * amplitudes + 0.3
    outer = np.concatenate([free - reach, free + reach])
    assert not entrained(amps, outer, **run).any()
    while np.max(np.abs(outer - inner)) > 0.004:
        mid = 0.5 * (inner + outer)
        locked = entrained(amps, mid, **run)
        inner, outer = np.where(locked, mid, inner), np.where(locked, outer, mid)
    edges = 0.5 * (inner + outer)
    lower, upper = edges[:k], edges[k:]
    width = upper - lower
    slope, intercept = np.polyfit(amplitudes, width, 1)
    assert 110 < slope < 135, (slope, width)
    assert abs(intercept) < 0.05, (intercept, width)  # BPM: a line through the origin
    np.testing.assert_allclose(width, slope * amplitudes + intercept, rtol=0.03)
    # The tongue stands on the free-running rate: both edges move alike.
    np.testing.assert_allclose(upper - free, free - lower, rtol=0.1, atol=0.02)

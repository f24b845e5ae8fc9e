"""The accurate integrator, and the fixed-step scheme converging to it with kicks."""

import math

import numpy as np
import pytest

from metrosync import Metronome, get_preset, simulate
from metrosync.integrators import exact

RIGID = {"inertia": math.inf}


def steady_amplitude(ds, window=20.0):
    late = ds.theta.where(ds.time >= ds.time[-1] - window, drop=True)
    return float(np.abs(late).max())


def small_drive(amplitude):
    """Drive M whose energy-balance amplitude is ``amplitude`` (rad) with c_θ = 5e-5."""
    return amplitude * math.pi * 5e-5 / 2


@pytest.mark.parametrize("integrator", ["verlet", "exact"])
def test_single_metronome_reaches_the_energy_balance_amplitude(integrator):
    target = 0.15
    dt = 0.01 if integrator == "verlet" else 0.005
    ds = simulate(
        1, 192, duration=120, dt=dt, changes={**RIGID, "drive": small_drive(target)},
        theta0=[0.05], trajectories=True, record_every=1, integrator=integrator,
    )  # fmt: skip
    assert steady_amplitude(ds) == pytest.approx(target, rel=0.05)


def test_impulse_gives_angular_momentum_m_on_a_rigid_support():
    params = get_preset("default").with_changes(**RIGID)
    m = Metronome(params.metronome, params.metronome.l2_for_bpm(192))
    from metrosync import build_ensemble

    ens = build_ensemble(1, 192, params=params, theta0=[0.0], theta_dot0=[1.0])
    y = np.array([0.0, 0.0, 0.0, 1.0])
    kicked = exact._apply_impulse(ens.system.run(0), y, 1, 0, 1.0, True)
    assert kicked[3] - 1.0 == pytest.approx(params.metronome.drive / m.inertia, rel=1e-12)
    assert kicked[2] == 0.0


def test_impulse_on_a_free_disk_conserves_total_angular_momentum_change():
    # The escapement torque enters the disk equation as -Σ𝕄 (paper eq. (metron2a)):
    # after an impulse M, p_φ changes by exactly -M.
    from metrosync import build_ensemble
    from metrosync.observables import platform_momentum

    ens = build_ensemble(3, 192, params=get_preset("default"), theta0=[0.0, 0.2, -0.1])
    sys = ens.system.run(0)
    y = np.array([0.0, 0.0, 0.2, -0.1, 0.05, 1.0, 0.3, -0.2])
    kicked = exact._apply_impulse(sys, y, 3, 0, 1.0, False)
    before = platform_momentum(sys, y[None, 1:4], y[None, 5:], y[4:5])
    after = platform_momentum(sys, kicked[None, 1:4], kicked[None, 5:], kicked[4:5])
    assert (after - before)[0] == pytest.approx(-sys.drive[0, 0], rel=1e-10)


def test_fixed_step_statistics_approach_exact_as_dt_shrinks():
    kwargs = dict(sigma_bpm=1.5, runs=4, duration=40, seed=3, trajectories=True)
    ref = simulate(3, 192, integrator="exact", record_every=1, dt=0.005, **kwargs)

    def stats(ds):
        late = ds.theta.where(ds.time >= 20, drop=True)
        return np.array([float(np.abs(late).max("time").mean()), float(ds.r.sel(time=40).mean())])

    target = stats(ref)
    errors = []
    for dt in (0.01, 0.005, 0.0025, 0.00125):
        ds = simulate(3, 192, dt=dt, record_every=max(1, int(round(0.005 / dt))), **kwargs)
        errors.append(np.abs(stats(ds) - target)[0])
    assert errors[-1] < errors[0] / 4, errors
    assert errors[-1] < 2e-3, errors

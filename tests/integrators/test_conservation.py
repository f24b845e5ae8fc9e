"""Invariants of the frictionless, undriven system (c_θ = c_φ = M = 0)."""

import numpy as np
import pytest

from metrosync import simulate
from metrosync.ensemble import build_ensemble
from metrosync.model import get_preset
from metrosync.observables import platform_momentum, total_energy

FREE = {"c_theta": 0.0, "c_phi": 0.0, "drive": 0.0}


def free_run(duration, dt, integrator="verlet", runs=2):
    ds = simulate(
        7, 192, sigma_bpm=3.0, runs=runs, duration=duration, dt=dt, seed=8, changes=FREE,
        amplitude=0.5, trajectories=True, record_every=max(1, int(round(1.0 / dt))),
        integrator=integrator,
    )  # fmt: skip
    ens = build_ensemble(
        7, 192, params=get_preset("default").with_changes(**FREE), sigma_bpm=3.0, runs=runs,
        seed=8, amplitude=0.5,
    )  # fmt: skip
    th, thd, phd = (ds[k].values for k in ("theta", "theta_dot", "phi_dot"))
    return total_energy(ens.system, th, thd, phd), platform_momentum(ens.system, th, thd, phd), ens


@pytest.mark.slow
def test_energy_drifts_less_than_1e4_over_1000_s():
    # The scheme's bounded O(dt²) energy error is ≈ 2e-3 at dt = 0.01 (measured); at
    # dt = 0.002 it is ≈ 25× smaller, and it must not grow over 1000 s.
    energy, _, _ = free_run(1000.0, 0.002)
    drift = np.max(np.abs(energy / energy[0] - 1))
    assert drift < 1e-4, drift


def test_platform_momentum_is_conserved_to_rounding():
    _, momentum, ens = free_run(1000.0, 0.01)
    scale = np.max(np.abs(ens.system.mh)) * ens.system.lever.max() * 10.0  # |R m h θ̇| bound
    assert np.max(np.abs(momentum - momentum[0])) < 1e-12 * scale * 7
    assert np.max(np.abs(momentum[0])) > 1e-6 * scale  # not trivially zero


def test_energy_error_is_second_order_in_dt():
    errors = []
    for dt in (0.01, 0.005):
        energy, _, _ = free_run(50.0, dt)
        errors.append(np.max(np.abs(energy / energy[0] - 1)))
    assert 3.0 < errors[0] / errors[1] < 5.5, errors


def test_exact_integrator_conserves_energy_tightly():
    energy, momentum, _ = free_run(30.0, 0.01, integrator="exact", runs=1)
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-8
    assert np.max(np.abs(momentum - momentum[0])) < 1e-12

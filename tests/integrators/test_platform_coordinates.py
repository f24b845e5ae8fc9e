"""A platform of several coordinates (`equations`, P > 1): the NumPy twin and ``exact``
run it, the compiled kernels refuse it by name; a disk given a second, idle coordinate
is the disk; without damping, drive and forcing the platform's momentum and the energy
are conserved."""

import math

import numpy as np
import pytest

from metrosync import build_ensemble, get_preset
from metrosync.capabilities import UnsupportedFeature
from metrosync.equations import SystemArrays
from metrosync.integrators import exact, located, twin, verlet
from metrosync.integrators._state import StepState
from metrosync.observables import platform_momentum, total_energy
from two_coordinates import padded


def run(advance, sys, ens, steps, **kwargs):
    state = StepState.start(
        sys, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
        n_records=steps // 10 + 1, trajectories=True,
    )  # fmt: skip
    advance(state, sys, dt=0.01, step0=0, n_steps=steps, record_every=10,
            overturn_angle=math.pi / 2, **kwargs)  # fmt: skip
    return state


def disk(changes=None, runs=3, n=4, **options):
    params = get_preset("default").with_changes(**(changes or {}))
    return build_ensemble(n, 192.0, params=params, sigma_bpm=2.0, runs=runs, seed=3, **options)


@pytest.mark.parametrize("changes", [{}, {"forcing_amplitude": 0.02, "forcing_bpm": 189.0}])
def test_the_twin_runs_a_disk_with_an_idle_second_coordinate_as_the_disk(changes):
    ens = disk(changes)
    one = run(twin.VERLET.advance_state, ens.system, ens, 1000)
    two = run(twin.VERLET.advance_state, padded(ens.system), ens, 1000)
    assert two.phi.shape == (3, 2)
    np.testing.assert_allclose(two.theta, one.theta, rtol=0, atol=1e-12)
    np.testing.assert_allclose(two.theta_dot, one.theta_dot, rtol=0, atol=1e-11)
    np.testing.assert_allclose(two.phi[:, :1], one.phi, rtol=0, atol=1e-12)
    np.testing.assert_allclose(two.traj_phi[:, :, :1], one.traj_phi, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(two.phi[:, 1], 0.0)
    np.testing.assert_allclose(two.r, one.r, rtol=0, atol=1e-12)


def test_exact_runs_a_disk_with_an_idle_second_coordinate_as_the_disk():
    ens = disk(runs=1, n=3)
    kw = dict(duration=5.0, grid_dt=0.1, n_records=51, trajectories=True,
              overturn_angle=math.pi / 2)  # fmt: skip
    one = exact.integrate(ens.system, ens.theta0, ens.theta_dot0, ens.phi_dot0, **kw)
    two = exact.integrate(padded(ens.system), ens.theta0, ens.theta_dot0, ens.phi_dot0, **kw)
    assert two.phi.shape == (1, 51, 2)
    np.testing.assert_allclose(two.theta, one.theta, atol=1e-8)
    np.testing.assert_allclose(two.phi[..., 0], one.phi, atol=1e-9)
    np.testing.assert_allclose(two.phi[..., 1], 0.0, atol=1e-12)


@pytest.mark.parametrize("layout", sorted(verlet.LAYOUTS))
@pytest.mark.parametrize("kernels", [verlet, located], ids=["verlet", "located"])
def test_the_compiled_kernels_refuse_a_platform_of_two_coordinates(kernels, layout):
    ens = disk()
    with pytest.raises(UnsupportedFeature, match="2 coordinates") as refused:
        run(kernels.advance_state, padded(ens.system), ens, 10, layout=layout)
    assert refused.value.feature == "platform-coordinates"
    assert refused.value.consumer == f"{kernels.__name__.rsplit('.', 1)[1]}/numba"


def test_located_on_the_twin_refuses_a_platform_of_two_coordinates():
    ens = disk()
    with pytest.raises(UnsupportedFeature, match="2 coordinates") as refused:
        run(twin.LOCATED.advance_state, padded(ens.system), ens, 10)
    assert refused.value.consumer == "located/numpy"
    assert "use integrator='exact'" in str(refused.value)


def test_metronomes_at_different_levers_are_refused_by_name_by_the_kernels():
    """One coordinate, but each metronome at its own lever: the kernels take one lever
    per run."""
    ens = disk()
    lever = ens.system.lever.copy()
    lever[:, 0, 0] *= 1.5
    uneven = SystemArrays(**{**vars(ens.system), "lever": lever})
    with pytest.raises(UnsupportedFeature, match="different levers"):
        run(verlet.advance_state, uneven, ens, 10)


def free_plane(runs=2, n=4):
    """Two coordinates, each metronome swinging along its own direction; no damping,
    no escapement, no forcing."""
    ens = disk({"drive": 0.0, "c_theta": 0.0, "c_phi": 0.0}, runs=runs, n=n, amplitude=0.5)
    angle = np.linspace(0.0, 2.0, n)
    sys = padded(ens.system)
    lever = np.stack([np.cos(angle), np.sin(angle)], axis=-1) * 0.27
    own = 0.2 * np.eye(2)
    m = ens.params.metronome.w1 + ens.params.metronome.w2
    inertia = own + m * np.einsum("np,nq->pq", lever, lever)
    sys = SystemArrays(
        **{
            **vars(sys),
            "lever": np.broadcast_to(lever, (runs, n, 2)).copy(),
            "total_inertia": np.broadcast_to(inertia, (runs, 2, 2)).copy(),
        }
    )
    return ens, sys


def test_a_free_plane_keeps_its_momentum_in_the_twin_and_its_energy_in_exact():
    ens, sys = free_plane()
    state = run(twin.VERLET.advance_state, sys, ens, 2000)
    th, thd = state.traj_theta.transpose(1, 0, 2), state.traj_theta_dot.transpose(1, 0, 2)
    p = platform_momentum(sys, th, thd, state.traj_phi_dot.transpose(1, 0, 2))
    assert np.ptp(state.traj_phi_dot[..., 1]) > 1e-4  # the platform moves along both
    np.testing.assert_allclose(p, np.broadcast_to(p[0], p.shape), rtol=0, atol=1e-15)
    rec = exact.integrate(sys, ens.theta0, ens.theta_dot0, ens.phi_dot0, duration=10.0,
                          grid_dt=0.05, n_records=201, trajectories=True,
                          overturn_angle=math.pi / 2)  # fmt: skip
    th, thd, phd = (a.transpose(1, 0, 2) for a in (rec.theta, rec.theta_dot, rec.phi_dot))
    e = total_energy(sys, th, thd, phd)
    p = platform_momentum(sys, th, thd, phd)
    np.testing.assert_allclose(e, np.broadcast_to(e[0], e.shape), rtol=1e-9)
    np.testing.assert_allclose(p, np.broadcast_to(p[0], p.shape), rtol=0, atol=1e-12)

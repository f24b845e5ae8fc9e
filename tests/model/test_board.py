"""The board on rollers: its equations from its own Lagrangian, its conservation laws,
and every integrator on it (docs/model.md §9)."""

import math
import re

import numpy as np
import pytest

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.equations import accelerations
from metrosync.model import Platform, system_arrays
from metrosync.observables import platform_momentum, total_energy

FREE = {"c_theta": 0.0, "board_damping": 0.0, "drive": 0.0, "tuning": "small-amplitude"}
BOARD = get_preset("pantaleone2002")


def board_lagrangian(board, pendulums, x_dot, theta, theta_dot):
    """L of the board written from scratch: the board (with its rollers' effective mass
    and the cases) at velocity ẋ, each pendulum a rigid body whose pivot moves with the
    board: T_i = ½ m ẋ² + m h cos θ ẋ θ̇ + ½ I θ̇², V_i = −m g h cos θ (I the model's
    coefficient of θ̈, m h² + J_i)."""
    mass, mh, inertia, mgh = pendulums
    kinetic = 0.5 * board * x_dot**2 + np.sum(
        0.5 * mass * x_dot**2 + mh * np.cos(theta) * x_dot * theta_dot
        + 0.5 * inertia * theta_dot**2
    )  # fmt: skip
    return kinetic + np.sum(mgh * np.cos(theta))


def lagrange_residuals(lagrangian, q, q_dot, q_ddot, forces, h=1e-4, hv=1e-2):
    """d/dt ∂L/∂q̇ − ∂L/∂q − Q for the generalized coordinates q, from L alone by
    central differences: steps ``hv`` in the velocities (L is quadratic in them, so
    these differences are exact and a large step keeps rounding small), ``h`` in q."""
    k = len(q)

    def grad(f, x, step):
        return np.array([(f(x + e) - f(x - e)) / (2 * step) for e in np.eye(k) * step])

    def dl_dqdot(qq, vv):
        return grad(lambda v: lagrangian(qq, v), vv, hv)

    # d/dt ∂L/∂q̇ = (∂²L/∂q̇∂q̇) q̈ + (∂²L/∂q̇∂q) q̇, each column by central differences.
    mass_matrix = np.column_stack(
        [(dl_dqdot(q, q_dot + e) - dl_dqdot(q, q_dot - e)) / (2 * hv) for e in np.eye(k) * hv]
    )
    mixed = np.column_stack(
        [(dl_dqdot(q + e, q_dot) - dl_dqdot(q - e, q_dot)) / (2 * h) for e in np.eye(k) * h]
    )
    potential = grad(lambda x: lagrangian(x, q_dot), q, h)
    return mass_matrix @ q_ddot + mixed @ q_dot - potential - forces


@pytest.mark.parametrize("n", [1, 2, 7])
def test_the_solved_form_solves_the_board_s_own_lagrange_equations(rng, n):
    """Every feature on: forcing, an escapement offset (a kick), damping; the board's
    friction force enters both sides as a generalized force (no reaction on the board)."""
    params = BOARD.with_changes(
        board_damping=0.05, forcing_amplitude=0.01, forcing_bpm=200.0, escapement_offset=0.05,
        roller_mass=0.015,
    )  # fmt: skip
    l2 = np.full((1, n), params.metronome.l2_for_bpm(208.0)) + rng.uniform(0, 1e-3, (1, n))
    sys, own = system_arrays(params, l2)
    theta = rng.uniform(-1.0, 1.0, (1, n))
    theta_dot = rng.normal(0, 3, (1, n))
    x_dot = rng.normal(0, 0.05, 1)
    kick = rng.choice([-1.0, 0.0, 1.0], (1, n)) * sys.drive / 0.01
    t = 0.37
    x_ddot, theta_ddot = accelerations(sys, theta, theta_dot, x_dot, kick, t)
    mass = (params.metronome.w1 + params.metronome.w2) * np.ones(n)
    pendulums = (mass, sys.mh[0], sys.inertia[0], sys.mgh[0])

    def lagrangian(q, v):
        return board_lagrangian(own[0], pendulums, v[0], q[1:], v[1:])

    drive = 0.01 * math.sin(float(sys.forcing_omega[0]) * t)
    forces = np.concatenate([[-0.05 * x_dot[0] + drive], kick[0] - sys.c_theta[0] * theta_dot[0]])
    q = np.concatenate([[0.0], theta[0]])
    v = np.concatenate([x_dot, theta_dot[0]])
    a = np.concatenate([x_ddot, theta_ddot[0]])
    residual = lagrange_residuals(lagrangian, q, v, a, forces)
    scale = np.max(np.abs(forces)) + np.max(np.abs(sys.mgh))
    np.testing.assert_allclose(residual, 0, atol=1e-7 * scale)
    # ... and a wrong acceleration is seen.
    wrong = lagrange_residuals(lagrangian, q, v, a * 1.01, forces)
    assert np.max(np.abs(wrong)) > 1e-5 * scale


def test_the_board_s_constants():
    params = BOARD.with_changes(roller_mass=0.015)
    sys, own = system_arrays(params, np.full((3, 2), 0.04))
    sys = sys.one_coordinate()  # the board's constants per run
    pendulum = params.metronome.w1 + params.metronome.w2
    assert own[0] == pytest.approx(0.058 + 0.015 + 2 * 0.0705)
    np.testing.assert_allclose(sys.total_inertia, own + 2 * pendulum)
    np.testing.assert_array_equal(sys.lever, 1.0)
    np.testing.assert_array_equal(sys.escapement_reaction, 0.0)  # no reaction on a board


def free_board_run(integrator, duration=60.0, dt=0.005):
    ds = simulate(
        3, 208.0, preset="pantaleone2002", changes=FREE, sigma_bpm=3.0, runs=2,
        duration=duration, dt=dt, seed=3, amplitude=0.6, trajectories=True,
        record_every=max(1, int(round(0.5 / dt))), integrator=integrator,
    )  # fmt: skip
    ens = build_ensemble(
        3, 208.0, params=BOARD.with_changes(**FREE), sigma_bpm=3.0, runs=2, seed=3,
        amplitude=0.6,
    )  # fmt: skip
    th, thd, xd = (ds[k].values for k in ("theta", "theta_dot", "phi_dot"))
    return total_energy(ens.system, th, thd, xd), platform_momentum(ens.system, th, thd, xd)


@pytest.mark.parametrize("integrator", ["verlet", "located", "exact"])
def test_the_board_s_momentum_is_conserved_without_friction_and_drive(integrator):
    energy, momentum = free_board_run(integrator, duration=60.0 if integrator != "exact" else 10.0)
    assert np.max(np.abs(momentum[0])) > 1e-6  # not trivially zero
    # The fixed-step schemes carry the momentum itself; exact's DOP853 keeps it to its
    # tolerance (as on the disk, test_conservation.py).
    tolerance = 1e-12 if integrator == "exact" else 1e-13
    np.testing.assert_allclose(momentum - momentum[0], 0, rtol=0, atol=tolerance)
    assert np.max(np.abs(energy / energy[0] - 1)) < (1e-8 if integrator == "exact" else 1e-3)


def test_a_parameter_of_the_other_platform_is_refused_by_name():
    with pytest.raises(ParameterError, match=r"^`c_phi` = 0.1 is a parameter of the disk"):
        BOARD.with_changes(c_phi=0.1)
    with pytest.raises(ParameterError, match=r"`board_damping` = 1.0 is a parameter of the board"):
        get_preset("default").with_changes(board_damping=1.0)
    with pytest.raises(ParameterError, match=r"unknown `platform` 'table'; choose one of"):
        Platform(platform="table")
    with pytest.raises(ParameterError, match=r"^`board_mass` must be > 0 kg, got -1.0"):
        Platform(platform="board", board_mass=-1.0)


def test_the_dataset_says_what_phi_is():
    ds = simulate(2, 208.0, preset="pantaleone2002", duration=2.0, trajectories=True,
                  record_every=10)  # fmt: skip
    assert ds.phi.attrs["units"] == "m" and ds.phi.attrs["long_name"] == "board position"
    assert ds.attrs["platform"] == "board" and "radius" not in ds.attrs


def test_a_step_too_long_for_the_board_s_damping_is_refused_with_one_that_works():
    kw = dict(preset="pantaleone2002", changes={"board_damping": 40.0}, duration=1.0)
    with pytest.raises(
        ParameterError, match=r"^`board_damping` = 40.0 damps the board at 1\d\d /s"
    ):
        simulate(2, 208.0, dt=0.01, **kw)
    with pytest.raises(ParameterError, match=r"use dt <= 0\.00\d+ s") as refused:
        simulate(2, 208.0, dt=0.01, integrator="located", **kw)
    step = float(re.search(r"use dt <= (0\.00\d+) s", str(refused.value)).group(1))
    ds = simulate(2, 208.0, dt=step, **kw)
    assert np.isfinite(ds.r.values).all()
    with pytest.raises(ParameterError, match=r"^`c_phi` = 100.0 damps the disk"):
        simulate(2, 192.0, dt=0.01, changes={"c_phi": 100.0}, duration=1.0)

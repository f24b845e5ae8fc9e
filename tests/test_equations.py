"""The solved form (eqm1)–(eqm2) must satisfy the unsolved equations (metron2a)–(metron2),
with the model's switches beyond the paper on or off."""

from dataclasses import replace

import numpy as np
import pytest

from metrosync import ParameterError
from metrosync.equations import (
    SystemArrays,
    accelerations,
    applied_torque,
    escapement,
    residuals,
)
from metrosync.model import get_preset, system_arrays


def test_solved_form_solves_the_equations_of_motion(rng, random_system):
    for _ in range(20):
        sys = random_system()
        shape = sys.shape
        theta = rng.uniform(-np.pi, np.pi, shape)
        theta_dot = rng.normal(0, 5, shape)
        phi_dot = rng.normal(0, 1, shape[0])
        kick = rng.choice([-1.0, 0.0, 1.0], shape) * sys.drive / 0.01
        phi_ddot, theta_ddot = accelerations(sys, theta, theta_dot, phi_dot, kick)
        disk, pendulum = residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot)
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(disk, 0, atol=1e-12 * scale)
        np.testing.assert_allclose(pendulum, 0, atol=1e-12 * scale)


def test_residuals_detect_wrong_accelerations(rng, random_system):
    sys = random_system()
    theta = rng.uniform(-1, 1, sys.shape)
    zeros = np.zeros(sys.shape)
    phi_ddot, theta_ddot = accelerations(sys, theta, zeros, np.zeros(4), zeros)
    disk, pendulum = residuals(sys, theta, zeros, np.zeros(4), zeros, phi_ddot * 1.01, theta_ddot)
    assert np.max(np.abs(disk)) > 1e-8


def test_rigid_support_leaves_the_disk_still(rng, random_system):
    sys = random_system()
    sys = SystemArrays(**{**vars(sys), "total_inertia": np.full(4, np.inf)})
    theta = rng.uniform(-1, 1, sys.shape)
    zeros = np.zeros(sys.shape)
    phi_ddot, theta_ddot = accelerations(sys, theta, zeros, np.zeros(4), zeros)
    assert np.all(phi_ddot == 0)
    np.testing.assert_allclose(theta_ddot, -sys.mgh * np.sin(theta) / sys.inertia)


def with_features(sys, rng):
    """``sys`` with the features beyond the paper on, at random strengths: an applied
    torque, escapement offsets, the escapement's reaction on or off per run, and dry
    friction on the disk."""
    b, n = sys.shape
    return replace(
        sys,
        forcing_amplitude=rng.uniform(0, 0.05, b),
        forcing_omega=rng.uniform(5, 30, b),
        escapement_offset=rng.uniform(-0.2, 0.2, (b, n)),
        escapement_reaction=rng.choice([0.0, 1.0], b),
        dry_friction=rng.uniform(0, 0.05, b),
    )


def test_solved_form_solves_the_equations_with_every_feature_on(rng, random_system):
    for _ in range(20):
        sys = with_features(random_system(), rng)
        theta = rng.uniform(-np.pi, np.pi, sys.shape)
        theta_dot = rng.normal(0, 5, sys.shape)
        phi_dot = rng.normal(0, 1, sys.shape[0])
        kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / 0.01
        t = rng.uniform(0, 100)
        phi_ddot, theta_ddot = accelerations(sys, theta, theta_dot, phi_dot, kick, t)
        disk, pendulum = residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, t)
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(disk, 0, atol=1e-12 * scale)
        np.testing.assert_allclose(pendulum, 0, atol=1e-12 * scale)


def paper_disk_equation(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, reaction):
    """Left minus right of eq. (metron2a) as the paper writes it, with the −Σ𝕄_i term
    kept (``reaction``) or dropped; no applied torque."""
    sys = sys.one_coordinate()  # the disk's constants per run
    lhs = sys.total_inertia * phi_ddot + sys.lever * np.sum(
        sys.mh * (theta_ddot * np.cos(theta) - theta_dot**2 * np.sin(theta)), axis=-1
    )
    rhs = -sys.c_phi * phi_dot - (np.sum(kick, axis=-1) if reaction else 0.0)
    return lhs - rhs


def test_without_escapement_reaction_the_disk_equation_loses_exactly_that_term(rng, random_system):
    on = random_system()
    off = replace(on, escapement_reaction=np.zeros(on.shape[0]))
    theta = rng.uniform(-1.5, 1.5, on.shape)
    theta_dot = rng.normal(0, 5, on.shape)
    phi_dot = rng.normal(0, 1, on.shape[0])
    kick = rng.choice([-1.0, 1.0], on.shape) * on.drive / 0.01
    state = (theta, theta_dot, phi_dot, kick)
    acc_on, acc_off = accelerations(on, *state), accelerations(off, *state)
    scale = np.abs(kick).max()
    for acc, reaction in ((acc_on, True), (acc_off, False)):
        np.testing.assert_allclose(
            paper_disk_equation(on, *state, *acc, reaction), 0, atol=1e-12 * scale
        )
    # The pendulum equation (metron2) keeps its kick either way.
    np.testing.assert_allclose(residuals(off, *state, *acc_off)[1], 0, atol=1e-12 * scale)
    # The solved form: φ̈ gains Σ𝕄_i / D and nothing else (the C term stays), with D
    # the paper's denominator.
    flat = on.one_coordinate()
    d = flat.total_inertia - np.sum(
        (flat.lever[:, None] * on.mh * np.cos(theta)) ** 2 / on.inertia, axis=-1
    )
    np.testing.assert_allclose(
        acc_off[0] - acc_on[0], np.sum(kick, axis=-1) / d, rtol=1e-9, atol=1e-12 * scale
    )
    assert np.all(np.abs(acc_off[0] - acc_on[0]) > 1e-6)  # the term is not negligible here
    # Unkicked, the switch changes nothing.
    zero = np.zeros(on.shape)
    np.testing.assert_array_equal(
        accelerations(on, theta, theta_dot, phi_dot, zero)[0],
        accelerations(off, theta, theta_dot, phi_dot, zero)[0],
    )


def test_applied_torque_is_a_sine_at_the_forcing_bpm():
    params = get_preset("default").with_changes(forcing_amplitude=0.003, forcing_bpm=120.0)
    sys, _ = system_arrays(params, np.full((2, 3), 0.03))
    # 120 BPM is one period per second (two beats a period): Ω = 2π rad/s.
    np.testing.assert_allclose(sys.forcing_omega, 2 * np.pi)
    np.testing.assert_allclose(applied_torque(sys, 0.25), 0.003, rtol=1e-15)
    np.testing.assert_allclose(applied_torque(sys, 0.75), -0.003, rtol=1e-15)
    unforced, _ = system_arrays(get_preset("default"), np.full((2, 3), 0.03))
    assert np.all(applied_torque(unforced, 12.3) == 0)


def test_escapement_kicks_where_theta_crosses_its_offset(random_system):
    sys = replace(random_system(b=1, n=1), escapement_offset=np.full((1, 1), 0.05))
    for before, after, want in [
        (0.04, 0.06, 1.0), (0.06, 0.04, -1.0),
        (-0.01, 0.01, 0.0), (0.01, -0.01, 0.0),  # crossing 0 is no longer a kick
        (0.05, 0.06, 0.0), (0.04, 0.05, 0.0),  # touching δ is not crossing it
    ]:  # fmt: skip
        kick = escapement(sys, np.array([[before]]), np.array([[after]]))
        assert kick[0, 0] == want, (before, after)


def test_solved_form_with_dry_friction_obeys_the_coulomb_law(rng, random_system):
    """Moving, held and breaking-free disks: the disk's equation holds with the friction
    the law allows (−T sign φ̇, −T sign φ̈ from rest, or within ±T at rest)."""
    for _ in range(20):
        sys = random_system()
        sys = SystemArrays(**{**vars(sys), "dry_friction": rng.uniform(0, 0.05, 4)})
        theta = rng.uniform(-np.pi, np.pi, sys.shape)
        theta_dot = rng.normal(0, 5, sys.shape)
        phi_dot = np.where(rng.random(4) < 0.5, 0.0, rng.normal(0, 1, 4))
        kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / 0.01
        phi_ddot, theta_ddot = accelerations(sys, theta, theta_dot, phi_dot, kick)
        disk, pendulum = residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot)
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(disk, 0, atol=1e-12 * scale)
        np.testing.assert_allclose(pendulum, 0, atol=1e-12 * scale)
        # Without the friction the disk's equation no longer holds where it acts.
        bare = SystemArrays(**{**vars(sys), "dry_friction": np.zeros(4)})
        disk, _ = residuals(bare, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot)
        assert np.all(np.abs(disk) > 1e-6 * sys.dry_friction)


def with_coordinates(sys, rng, p):
    """``sys`` on a platform of ``p`` coordinates: each metronome's lever a random
    P-vector, the platform's inertia M = J_p + Σ m ℓ ℓᵀ with a random J_p, damping and
    drive per coordinate."""
    b, n = sys.shape
    mass = sys.mh**2 / sys.inertia  # any positive per-metronome masses will do
    lever = rng.uniform(-0.5, 0.5, (b, n, p))
    own = rng.uniform(0.05, 0.5, (b, p, p))
    own = own @ own.transpose(0, 2, 1) + np.eye(p)  # positive definite
    return SystemArrays(
        **{
            **vars(sys),
            "lever": lever,
            "total_inertia": own + np.einsum("bn,bnp,bnq->bpq", mass, lever, lever),
            "c_phi": rng.uniform(0, 1e-3, (b, p)),
            "forcing_amplitude": rng.uniform(0, 0.05, (b, p)),
            "forcing_omega": rng.uniform(5, 30, b),
            "escapement_reaction": rng.uniform(0, 1, (b, p)),
        }
    )


def test_the_solved_form_solves_the_equations_of_a_platform_of_several_coordinates(
    rng, random_system
):
    for p in (1, 2, 3):
        sys = with_coordinates(random_system(), rng, p)
        theta = rng.uniform(-np.pi, np.pi, sys.shape)
        theta_dot = rng.normal(0, 5, sys.shape)
        phi_dot = rng.normal(0, 1, (sys.shape[0], p))
        kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / 0.01
        phi_ddot, theta_ddot = accelerations(sys, theta, theta_dot, phi_dot, kick, 3.0)
        assert phi_ddot.shape == phi_dot.shape
        disk, pendulum = residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, 3.0)
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(disk, 0, atol=1e-12 * scale)
        np.testing.assert_allclose(pendulum, 0, atol=1e-12 * scale)


def test_one_coordinate_solved_as_a_system_is_the_division(rng, random_system):
    """A disk's constants given with a lever per metronome that differs by rounding
    only take the P × P solve; its φ̈ is the paper's division's to rounding, and the
    disk given per run (B,) and per coordinate (B, 1) is the same, bit for bit."""
    sys = with_features(random_system(), rng)
    theta = rng.uniform(-np.pi, np.pi, sys.shape)
    theta_dot = rng.normal(0, 5, sys.shape)
    phi_dot = rng.normal(0, 1, sys.shape[0])
    kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / 0.01
    per_run = accelerations(sys, theta, theta_dot, phi_dot, kick, 2.0)
    per_coordinate = accelerations(sys, theta, theta_dot, phi_dot[:, None], kick, 2.0)
    np.testing.assert_array_equal(per_coordinate[0][:, 0], per_run[0])
    np.testing.assert_array_equal(per_coordinate[1], per_run[1])
    lever = sys.lever * (1 + np.linspace(0, 1e-15, sys.shape[1]))[None, :, None]
    solved = replace(sys, lever=lever, dry_friction=np.zeros(sys.shape[0]))
    assert solved.one_coordinate() is None
    bare = replace(sys, dry_friction=np.zeros(sys.shape[0]))
    want = accelerations(bare, theta, theta_dot, phi_dot[:, None], kick, 2.0)
    got = accelerations(solved, theta, theta_dot, phi_dot[:, None], kick, 2.0)
    np.testing.assert_allclose(got[0], want[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got[1], want[1], rtol=1e-9, atol=1e-12)


def test_dry_friction_on_a_platform_of_several_coordinates_is_refused(rng, random_system):
    sys = with_coordinates(random_system(), rng, 2)
    with pytest.raises(ParameterError, match="dry_friction"):
        replace(sys, dry_friction=np.full(sys.shape[0], 0.01))


def test_one_coordinate_with_levers_that_differ_obeys_the_coulomb_law(rng, random_system):
    """The P × P solve of one coordinate takes φ̇ per run too, and dry friction."""
    for _ in range(10):
        sys = with_features(random_system(), rng)
        lever = sys.lever * rng.uniform(0.5, 1.5, sys.lever.shape)
        sys = replace(sys, lever=lever)
        assert sys.one_coordinate() is None
        theta = rng.uniform(-np.pi, np.pi, sys.shape)
        theta_dot = rng.normal(0, 5, sys.shape)
        phi_dot = np.where(rng.random(4) < 0.5, 0.0, rng.normal(0, 1, 4))
        kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / 0.01
        phi_ddot, theta_ddot = accelerations(sys, theta, theta_dot, phi_dot, kick, 1.0)
        assert phi_ddot.shape == phi_dot.shape
        again = accelerations(sys, theta, theta_dot, phi_dot[:, None], kick, 1.0)[0]
        np.testing.assert_array_equal(again[:, 0], phi_ddot)
        disk, pendulum = residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, 1.0)
        assert disk.shape == phi_dot.shape
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(disk, 0, atol=1e-12 * scale)
        np.testing.assert_allclose(pendulum, 0, atol=1e-12 * scale)

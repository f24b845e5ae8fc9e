"""The solved form (eqm1)–(eqm2) must satisfy the unsolved equations (metron2a)–(metron2)."""

import numpy as np

from metrosync.equations import SystemArrays, accelerations, residuals


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

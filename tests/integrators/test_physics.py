"""The kernels' scalar physics (`_physics`) against its vectorised statement
(`equations`), in both memory orders the CPU layouts use, and the properties that let
the GPU kernel compile the same source."""

import math
from dataclasses import replace

import numba as nb
import numpy as np
import pytest

from metrosync import equations
from metrosync.integrators import _kernel_parts, _physics, layout_runs, located, verlet
from metrosync.integrators._abi import Constants, constants_of
from metrosync.integrators._physics import (
    applied_torque,
    disk_acceleration,
    disk_torque,
    disk_velocity,
    escapement,
    pendulum_terms,
    theta_ddot,
)
from metrosync.observables.mechanics import platform_momentum

DT = 0.01


@nb.njit
def _one_run(c, m_of, r, theta, theta_dot, phi_dot, kick, t):
    """φ̈ and θ̈ of one run from the scalar pieces, as a kernel combines them."""
    n = theta.shape[0]
    rest = np.empty(n)
    q = np.empty(n)
    s_num = 0.0
    s_den = 0.0
    s_kick = 0.0
    for i in range(n):
        rest[i], q[i], num, den = pendulum_terms(
            c, m_of[i], kick[i], math.sin(theta[i]), math.cos(theta[i]), theta_dot[i]
        )
        s_num += num
        s_den += den
        s_kick += kick[i]
    force = disk_torque(c, r, phi_dot, s_kick) + applied_torque(c, r, t)
    phdd = disk_acceleration(c, r, s_num, s_den, force)
    thdd = np.empty(n)
    for i in range(n):
        thdd[i] = theta_ddot(c, m_of[i], r, rest[i], q[i], phdd)
    return phdd, thdd, force


def scalar_accelerations(c, theta, theta_dot, phi_dot, kick, t, blocked):
    """Every run through `_one_run`, indexing the constants as built ((b, i), b) or as
    the runs-innermost layout blocks them ((block, i, lane), (block, lane))."""
    b_runs, n = theta.shape
    phdd, thdd, force = np.empty(b_runs), np.empty((b_runs, n)), np.empty(b_runs)
    for b in range(b_runs):
        if blocked:
            blk, lane = divmod(b, layout_runs.LANES)
            m_of, r = [(blk, i, lane) for i in range(n)], (blk, lane)
        else:
            m_of, r = [(b, i) for i in range(n)], b
        phdd[b], thdd[b], force[b] = _one_run(
            c, nb.typed.List(m_of), r, theta[b], theta_dot[b], phi_dot[b], kick[b], t
        )
    return phdd, thdd, force


def with_features(sys, rng):
    """``sys`` with the features beyond the paper on, at random strengths."""
    b, n = sys.shape
    return replace(
        sys,
        forcing_amplitude=rng.uniform(0, 0.05, b) * rng.choice([0.0, 1.0], b),
        forcing_omega=rng.uniform(5, 30, b),
        escapement_offset=rng.uniform(-0.2, 0.2, (b, n)),
        escapement_reaction=rng.choice([0.0, 1.0], b),
    )


@pytest.mark.parametrize("features", [False, True], ids=["paper", "features"])
@pytest.mark.parametrize("blocked", [False, True])
def test_scalar_physics_equals_the_vectorised_equations(rng, random_system, blocked, features):
    for _ in range(5):
        sys = random_system(b=5, n=4)
        if features:
            sys = with_features(sys, rng)
        theta = rng.uniform(-np.pi, np.pi, sys.shape)
        theta_dot = rng.normal(0, 5, sys.shape)
        phi_dot = rng.normal(0, 1, sys.shape[0])
        kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / DT
        c = constants_of(sys)
        if blocked:
            c = layout_runs.arrange(c)
        phdd, thdd, force = scalar_accelerations(c, theta, theta_dot, phi_dot, kick, 1.5, blocked)
        want_phdd, want_thdd = equations.accelerations(sys, theta, theta_dot, phi_dot, kick, 1.5)
        scale = np.abs(kick).max() + 1.0
        np.testing.assert_allclose(phdd, want_phdd, rtol=1e-12, atol=1e-13 * scale)
        np.testing.assert_allclose(thdd, want_thdd, rtol=1e-12, atol=1e-12 * scale)
        want_force = equations.disk_torque(sys, phi_dot, kick, 1.5)
        np.testing.assert_allclose(force, want_force, rtol=1e-13, atol=1e-15)


def test_escapement_is_the_papers_discrete_kick(random_system):
    sys = random_system(b=1, n=1)
    c = constants_of(sys)
    for before, after, want in [
        (-0.1, 0.1, 1.0), (0.1, -0.1, -1.0), (0.1, 0.2, 0.0), (-0.1, -0.2, 0.0),
        (0.0, 0.1, 0.0), (-0.1, 0.0, 0.0),  # touching 0 is not crossing it
    ]:  # fmt: skip
        assert escapement.py_func(c, (0, 0), before, after) == want
        assert escapement(c, (0, 0), before, after) == want


@pytest.mark.parametrize("scheme", [verlet, located])
def test_a_scheme_makes_the_escapement_a_torque_or_an_impulse(random_system, scheme):
    """The physics says where and which way; ``verlet`` makes it the paper's torque
    ±M/dt over the step, ``located`` an impulse ±M at the crossing."""
    sys = random_system(b=1, n=1)
    c = constants_of(sys)
    drive = sys.drive[0, 0]
    for before, velocity, sign in [(-0.05, 10.0, 1.0), (0.05, -10.0, -1.0), (0.05, 1.0, 0.0)]:
        after, _, fires, torque, impulse = scheme.begin(c, (0, 0), before, velocity, 0.0, DT, DT**2)
        assert after == before + velocity * DT and fires == sign
        if scheme is verlet:
            assert torque == sign * drive * (1.0 / DT) and impulse == 0.0
        else:
            assert torque == 0.0 and impulse == sign * drive


def test_scalar_escapement_kicks_at_its_offset_like_the_vectorised_one(rng, random_system):
    sys = with_features(random_system(b=3, n=50), rng)
    c = constants_of(sys)
    theta = sys.escapement_offset + rng.uniform(-0.05, 0.05, sys.shape)
    theta_next = sys.escapement_offset + rng.uniform(-0.05, 0.05, sys.shape)
    want = equations.escapement(sys, theta, theta_next)
    got = [[escapement(c, (b, i), theta[b, i], theta_next[b, i]) for i in range(50)]
           for b in range(3)]  # fmt: skip
    np.testing.assert_array_equal(got, want)
    assert np.count_nonzero(want) > 20


def test_applied_torque_is_off_unless_forced(random_system):
    sys = random_system(b=2, n=1)
    forced = replace(sys, forcing_amplitude=np.array([0.0, 0.01]), forcing_omega=np.full(2, 20.0))
    c = constants_of(forced)
    assert applied_torque(c, 0, 0.3) == 0.0
    assert applied_torque(c, 1, 0.3) == pytest.approx(0.01 * math.sin(6.0), rel=1e-15)


def test_disk_velocity_inverts_the_disk_momentum(rng, random_system):
    sys = random_system(b=3, n=5)
    theta = rng.uniform(-1, 1, sys.shape)
    theta_dot = rng.normal(0, 3, sys.shape)
    phi_dot = rng.normal(0, 1, 3)
    p_phi = platform_momentum(sys, theta, theta_dot, phi_dot)
    c = constants_of(sys)
    for b in range(3):
        coupling = float(np.sum(sys.mh[b] * np.cos(theta[b]) * theta_dot[b]))
        assert disk_velocity(c, b, p_phi[b], coupling) == pytest.approx(phi_dot[b], rel=1e-12)
    pinned = constants_of(equations.SystemArrays(**{**vars(sys), "total_inertia": np.full(3, np.inf)}))  # fmt: skip  # noqa: E501
    assert disk_velocity(pinned, 0, 1.0, 2.0) == 0.0


def test_constants_carry_every_system_field():
    """A new model constant reaches the kernels through `SystemArrays` alone."""
    from dataclasses import fields

    assert {f.name for f in fields(equations.SystemArrays)} <= set(Constants._fields)


LEAVES = _physics.FUNCTIONS + (
    _kernel_parts.drift,
    _kernel_parts.velocity,
    _kernel_parts.momentum,
    _kernel_parts.upward,
)


@pytest.mark.parametrize("fn", LEAVES, ids=lambda f: f.py_func.__name__)
def test_physics_functions_are_leaves_the_gpu_can_compile(fn):
    """`kernel_cuda` compiles each from its Python source: it must call no other
    compiled function (a CPU dispatcher is not callable from a CUDA device function)."""
    module = __import__(fn.py_func.__module__, fromlist=["_"])
    called = {
        name
        for name in fn.py_func.__code__.co_names
        if isinstance(getattr(module, name, None), nb.core.registry.CPUDispatcher)
    }
    assert not called, f"{fn.py_func.__name__} calls compiled functions {called}"
    assert fn.targetoptions.get("inline") == "always"

"""The model's forces, once: the scalar pieces of eqs. (eqm1)–(eqm2) that every
compiled kernel calls.

Contract
--------
Each function is a *leaf*: plain arithmetic on scalars and on the kernel `Constants`
``c``, calling no other compiled function, so that

* numba inlines it (``inline="always"``) into the CPU layouts' loops, where it
  vectorizes like hand-written code, and
* `kernel_cuda` compiles the very same Python source as a CUDA device function
  (``cuda.jit(device=True)(fn.py_func)``).

A function reads its own constants: ``c.<field>[m]`` for one metronome and
``c.<field>[r]`` for one run, where the index is whatever the layout's memory order
needs: ``m = (b, i)``, ``r = b`` for the constants as built, ``m = (block, i, lane)``,
``r = (block, lane)`` for the runs-innermost layout's blocked copy. A new model term
therefore adds its constant to `SystemArrays` (which the kernels receive whole) and its
force here; the layouts' loops do not change. `equations.accelerations` states the same
forces vectorised over arrays, for the NumPy reference and ``exact``; tests hold the
two equal (tests/integrators/test_physics.py).

The split of the solved form
----------------------------
With q_i = m_i h_i cos θ_i and the rest of θ̈_i,

    ρ_i = (𝕄_i − m_i g h_i sin θ_i − c_θ θ̇_i) / I_i,      I_i = m_i h_i² + J_i,

eq. (eqm2) reads θ̈_i = ρ_i − R q_i φ̈ / I_i; put into eq. (metron2a) it gives eq. (eqm1),

    φ̈ = (R Σ_i (m_i h_i θ̇_i² sin θ_i − q_i ρ_i) + F) / (J + R² Σm − R² Σ_i q_i² / I_i),

with F the torque on the disk from outside the pendulums' swing: bearing friction, the
escapement's reaction −Σ𝕄_i (unless ``escapement_reaction`` is off), and the applied
torque A sin(Ω t) (when ``forcing_amplitude`` is not 0). A kernel sums the per-metronome
parts (`pendulum_terms`), then calls `disk_acceleration` once per run and
`theta_ddot` once per metronome.

Dry friction
------------
The disk's Coulomb friction (threshold T = ``c.dry_friction[r]``) is part of F. The
fixed-step scheme resolves it per step with `disk_friction` and `disk_friction_stop`
(the scheme is in `verlet`'s docstring); `momentum_at_rest` is p_φ of a disk held at
rest. A run without dry friction never calls them.
"""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def escapement(c, m, theta, theta_next):
    """Where and which way metronome ``m``'s escapement acts over a step from ``theta``
    to ``theta_next``: +1 when θ rises through the escapement's angle δ, −1 when it
    falls through it, else 0 (selects, not branches, so that it vectorizes). δ is
    ``escapement_offset``, 0 in the paper. Its impulse is M (``drive``); the scheme
    makes it a torque over the step (``verlet``: the paper's ±M/dt) or an impulse at
    the crossing (``located``), so the physics knows nothing of the step."""
    at = c.escapement_offset[m]
    up = (theta < at) & (theta_next > at)
    down = (theta > at) & (theta_next < at)
    return 1.0 if up else (-1.0 if down else 0.0)


@nb.njit(cache=True, inline="always")
def escapement_angle(c, m):
    """The angle, rad, at which metronome ``m``'s escapement gives its impulse: where
    `escapement` fires (``escapement_offset``; 0, the vertical, in the paper). The
    ``located`` scheme finds the crossing of this angle inside the step and applies
    the impulse there."""
    return c.escapement_offset[m]


@nb.njit(cache=True, inline="always")
def pendulum_terms(c, m, kick, sin_t, cos_t, theta_dot):
    """Metronome ``m``'s part of eqs. (eqm1)–(eqm2) at angle θ (given as sin θ, cos θ).

    Returns (ρ_i, q_i, its term of φ̈'s numerator sum, its term of the denominator sum).
    """
    inv = c.inv_inertia[m]
    mh = c.mh[m]
    rest = (kick - c.mgh[m] * sin_t - c.c_theta[m] * theta_dot) * inv
    q = mh * cos_t
    return rest, q, mh * theta_dot * theta_dot * sin_t - q * rest, q * q * inv


@nb.njit(cache=True, inline="always")
def disk_torque(c, r, phi_dot, sum_kick):
    """F without the applied torque: bearing friction −c_φ φ̇ and the escapement's
    reaction −Σ𝕄_i on the disk (eq. (metron2a)), the latter times
    ``escapement_reaction`` (1 as the paper has it, 0 to take it off the disk)."""
    return -c.c_phi[r] * phi_dot - c.escapement_reaction[r] * sum_kick


@nb.njit(cache=True, inline="always")
def applied_torque(c, r, t):
    """External torque on the disk at time ``t``, τ = A sin(Ω t), N m
    (``forcing_amplitude``, ``forcing_omega``); `equations.applied_torque` is its
    vectorised twin. An unforced run (A = 0, the default) skips the sine: the branch is
    the same for every step, so it costs nothing measurable."""
    amplitude = c.forcing_amplitude[r]
    if amplitude == 0.0:
        return 0.0
    return amplitude * math.sin(c.forcing_omega[r] * t)


@nb.njit(cache=True, inline="always")
def forced(c, r):
    """Whether run ``r``'s disk feels an applied torque. A layout that vectorizes over
    runs asks once per block, and calls `applied_torque` (a sine: not vectorizable)
    only for a forced block, so an unforced run pays nothing for the feature."""
    return c.forcing_amplitude[r] != 0.0


@nb.njit(cache=True, inline="always")
def disk_acceleration(c, r, sum_num, sum_den, force):
    """φ̈ of eq. (eqm1) from the per-metronome sums and the disk torque F. A pinned
    disk (J + R²Σm = ∞) gives 0."""
    rad = c.lever[r]
    return (rad * sum_num + force) / (c.total_inertia[r] - rad * rad * sum_den)


@nb.njit(cache=True, inline="always")
def theta_ddot(c, m, r, rest, q, phi_ddot):
    """θ̈_i of eq. (eqm2) from ρ_i, q_i and φ̈."""
    return rest - c.lever[r] * q * c.inv_inertia[m] * phi_ddot


@nb.njit(cache=True, inline="always")
def disk_velocity(c, r, p_phi, sum_q_theta_dot):
    """φ̇ from the disk's angular momentum p_φ = (J + R²Σm) φ̇ + R Σ q_i θ̇_i; 0 for a
    pinned disk."""
    total = c.total_inertia[r]
    if math.isinf(total):
        return 0.0
    return (p_phi - c.lever[r] * sum_q_theta_dot) / total


@nb.njit(cache=True, inline="always")
def disk_friction(c, r, phi_dot, sum_num, force):
    """The disk's dry friction for a step that starts at disk velocity ``phi_dot``, and
    whether it holds the disk at rest, from the sums of the step and the other torques
    ``force`` (F without friction).

    Moving (φ̇ ≠ 0): −T sign φ̇, not held. At rest: the torque that keeps φ̈ = 0,
    −(R Σ_i num_i + F), held, when it is within ±T; else ±T against the torques that
    move the disk, not held (the twin of `equations.dry_friction`).
    """
    limit = c.dry_friction[r]
    if phi_dot != 0.0:
        return (-limit if phi_dot > 0.0 else limit), False
    need = -(c.lever[r] * sum_num + force)
    if abs(need) <= limit:
        return need, True
    return (limit if need > 0.0 else -limit), False


@nb.njit(cache=True, inline="always")
def disk_friction_stop(c, r, friction, phi_dot_next, sum_den, dt):
    """The friction at the end of a slipping step whose end velocity ``phi_dot_next``,
    computed with ``friction`` = −T sign(direction), no longer points that way: the disk
    reached rest within the step.

    The end velocity is affine in the friction's end value F, φ̇' = φ̇'(F₀) + (F − F₀)
    dt/(2D) (trapezoid rule, D the denominator of eq. (eqm1)). Returns the F that makes
    φ̇' = 0 and True when it is within ±T (the disk stops); else −``friction`` and False
    (the disk reverses, and the friction turns against the new direction).
    """
    rad = c.lever[r]
    stop = friction - 2.0 * (c.total_inertia[r] - rad * rad * sum_den) * phi_dot_next / dt
    if abs(stop) <= c.dry_friction[r]:
        return stop, True
    return -friction, False


@nb.njit(cache=True, inline="always")
def momentum_at_rest(c, r, sum_q_theta_dot):
    """p_φ of a disk at rest (φ̇ = 0): R Σ_i q_i θ̇_i."""
    return c.lever[r] * sum_q_theta_dot


#: Every function above, for `kernel_cuda` and the tests.
FUNCTIONS = (
    escapement,
    escapement_angle,
    pendulum_terms,
    disk_torque,
    applied_torque,
    forced,
    disk_acceleration,
    theta_ddot,
    disk_velocity,
    disk_friction,
    disk_friction_stop,
    momentum_at_rest,
)

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
escapement's reaction −Σ𝕄_i, and any applied torque. A kernel sums the per-metronome
parts (`pendulum_terms`), then calls `disk_acceleration` once per run and
`theta_ddot` once per metronome.
"""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def escapement(c, m, theta, theta_next):
    """The paper's discrete escapement over one step from ``theta`` to ``theta_next``:
    the torque 𝕄 = +M/dt when θ rises through 0, −M/dt when it falls through 0, else 0
    (selects, not branches, so that it vectorizes)."""
    up = (theta < 0.0) & (theta_next > 0.0)
    down = (theta > 0.0) & (theta_next < 0.0)
    rate = c.kick_rate[m]
    return rate if up else (-rate if down else 0.0)


@nb.njit(cache=True, inline="always")
def escapement_angle(c, m):
    """The angle, rad, at which metronome ``m``'s escapement gives its impulse: where
    `escapement` fires (0, the vertical, in the paper). The ``located`` scheme
    finds the crossing of this angle inside the step and applies the impulse there."""
    return 0.0


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
    reaction −Σ𝕄_i on the disk (eq. (metron2a))."""
    return -c.c_phi[r] * phi_dot - sum_kick


@nb.njit(cache=True, inline="always")
def applied_torque(c, r, t):
    """External torque on the disk at time ``t``, N m: the hook for a driven platform.
    None in the current model; `equations.applied_torque` is its vectorised twin."""
    return 0.0


@nb.njit(cache=True, inline="always")
def disk_acceleration(c, r, sum_num, sum_den, force):
    """φ̈ of eq. (eqm1) from the per-metronome sums and the disk torque F. A pinned
    disk (J + R²Σm = ∞) gives 0."""
    rad = c.radius[r]
    return (rad * sum_num + force) / (c.total_inertia[r] - rad * rad * sum_den)


@nb.njit(cache=True, inline="always")
def theta_ddot(c, m, r, rest, q, phi_ddot):
    """θ̈_i of eq. (eqm2) from ρ_i, q_i and φ̈."""
    return rest - c.radius[r] * q * c.inv_inertia[m] * phi_ddot


@nb.njit(cache=True, inline="always")
def disk_velocity(c, r, p_phi, sum_q_theta_dot):
    """φ̇ from the disk's angular momentum p_φ = (J + R²Σm) φ̇ + R Σ q_i θ̇_i; 0 for a
    pinned disk."""
    total = c.total_inertia[r]
    if math.isinf(total):
        return 0.0
    return (p_phi - c.radius[r] * sum_q_theta_dot) / total


#: Every function above, for `kernel_cuda` and the tests.
FUNCTIONS = (
    escapement,
    escapement_angle,
    pendulum_terms,
    disk_torque,
    applied_torque,
    disk_acceleration,
    theta_ddot,
    disk_velocity,
)

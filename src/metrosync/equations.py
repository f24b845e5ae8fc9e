"""Equations of motion of the disk and its N pendulums (paper §4).

The contract: `accelerations` evaluates the solved form, eqs. (eqm1) and (eqm2),

    φ̈  = [R Σ m_i h_i θ̇_i² sin θ_i − c_φ φ̇ − Σ 𝕄_i + A + B − C] / D
    θ̈_i = [𝕄_i − m_i R φ̈ h_i cos θ_i − m_i g h_i sin θ_i − c_θ θ̇_i] / (m_i h_i² + J_i)

with A, B, C, D as in the paper (generalised to a mass m_i per metronome), and
−c_φ φ̇ − Σ𝕄_i + τ(t) the torque on the disk from outside the pendulums (`disk_torque`;
τ(t) = A sin(Ω t), `applied_torque`, is 0 unless the platform is forced; the −Σ𝕄_i
term is dropped when ``escapement_reaction`` is off). It is the one vectorised
definition shared by the NumPy reference integrator and the accurate ``exact``
integrator; the compiled kernels call the scalar form of the same forces in
`integrators._physics`, and tests hold the two equal. `residuals` evaluates the
unsolved equations (metron2a) and (metron2) so that a test can check that the solved
form satisfies them.

All arrays broadcast over leading "batch" axes: per-metronome arrays have shape
(..., N), per-run arrays shape (...). ``kick`` is the escapement torque 𝕄_i (N m) in
force form; the fixed-step integrators supply ±M/dt or 0 (`escapement`). The constants
come as `SystemArrays` (defined with their builder in `model.system`, re-exported here).

Dry friction. The disk may also feel a Coulomb torque of at most T =
``sys.dry_friction`` (Goldsztein et al., Chaos 32, 043119, 2022), added to the
numerator of eq. (eqm1). `dry_friction` states the law: −T sign φ̇ on a moving disk;
on a disk at rest, the torque that holds it, `holding_torque` (the one that makes
φ̈ = 0), when that is within ±T, else ±T against it (the disk starts to slip). With
T = 0 every result is the frictionless one, bit for bit. `accelerations` applies the
law at the given φ̇ unless it is handed the friction torque (``friction=``), as a
time-stepping scheme or an event-driven integrator does; `effective_inertia` is the
denominator D, by which an extra torque on the disk divides into φ̈.

A platform of P coordinates. The platform is P generalized coordinates φ (P = 1 for
the disk and the board); metronome i's pivot moves by ℓ_i·φ along its swing (the
lever ℓ_i, a P-vector). The equations are then

    I_i θ̈_i = 𝕄_i − m_i h_i cos θ_i (ℓ_i·φ̈) − m_i g h_i sin θ_i − c_θ θ̇_i
    M φ̈ + Σ_i m_i h_i ℓ_i (cos θ_i θ̈_i − sin θ_i θ̇_i²) = F

with M = J_p + Σ_i m_i ℓ_i ℓ_iᵀ (``total_inertia``) and F the generalized forces from
outside the pendulums (`disk_torque`: damping, the escapement's reaction and the
applied drive on each coordinate). Eliminating θ̈ gives D(θ) φ̈ = rhs with
D = M − Σ_i (m_i h_i cos θ_i)²/I_i ℓ_i ℓ_iᵀ (`effective_inertia`), solved as a P × P
system; for one coordinate with one lever for every metronome it is eq. (eqm1),
evaluated by the paper's division with the operations in the same order as ever.
φ̇ and φ̈ are (B, P); a one-coordinate φ̇ may also be given per run, (B,), and φ̈
comes back so. Dry friction is a law of one coordinate.
"""

from __future__ import annotations

import numpy as np

from .model.system import SystemArrays

__all__ = [
    "SystemArrays",
    "accelerations",
    "applied_torque",
    "disk_torque",
    "dry_friction",
    "effective_inertia",
    "escapement",
    "holding_torque",
    "residuals",
]


def applied_torque(sys: SystemArrays, t) -> np.ndarray:
    """External torque τ(t) = A sin(Ω t) on the disk (N m), on each of the platform's
    coordinates, (B, P); 0 where A = 0."""
    amplitude = np.asarray(sys.forcing_amplitude)
    if amplitude.ndim == 1:  # one coordinate, per run
        return amplitude * np.sin(sys.forcing_omega * t)
    return amplitude * np.sin(sys.forcing_omega * t)[..., None]


def disk_torque(sys: SystemArrays, phi_dot, kick, t=0.0):
    """Torque on the disk from outside the pendulums' swing, shaped as ``phi_dot``
    ((B, P), or (B,) for one coordinate given per run): bearing friction, the
    escapement's reaction (times ``escapement_reaction``, 1 or 0) and the applied
    torque, −c_φ φ̇ − Σ𝕄_i + τ(t)."""
    if np.ndim(sys.lever) == 1:  # constants per run (`SystemArrays.one_coordinate`)
        reaction = sys.escapement_reaction * np.sum(kick, axis=-1)
        return -sys.c_phi * phi_dot - reaction + applied_torque(sys, t)
    if _per_run(kick, phi_dot):
        return disk_torque(sys, np.asarray(phi_dot)[..., None], kick, t)[..., 0]
    reaction = sys.escapement_reaction * np.sum(kick, axis=-1)[..., None]
    return -sys.c_phi * phi_dot - reaction + applied_torque(sys, t)


def escapement(sys: SystemArrays, theta, theta_next) -> np.ndarray:
    """Where and which way each escapement acts over a step from ``theta`` to
    ``theta_next``, (B, N): +1 when θ_i rises through its escapement angle δ_i
    (``escapement_offset``, 0 in the paper), −1 when it falls through it, else 0. Its
    impulse is M (``drive``); a scheme makes it a torque over the step (the paper's
    ±M/dt) or an impulse at the crossing (the twin of `_physics.escapement`)."""
    at = sys.escapement_offset
    up = (theta < at) & (theta_next > at)
    down = (theta > at) & (theta_next < at)
    return np.where(up, 1.0, np.where(down, -1.0, 0.0))


def accelerations(sys: SystemArrays, theta, theta_dot, phi_dot, kick, t=0.0, *, friction=None):
    """Solved equations of motion, eqs. (eqm1)–(eqm2), for a platform of P coordinates.

    ``phi_dot`` is (B, P), or (B,) for a one-coordinate platform given per run; φ̈ and
    ``friction`` have its shape. A one-coordinate platform whose metronomes share one
    lever is solved by the paper's division (`_one_coordinate`); any other by solving
    D(θ) φ̈ = rhs (`_coordinates`)."""
    flat, per_run = _as_flat(sys), _per_run(theta, phi_dot)
    if flat is None:
        if friction is not None:
            friction = _with_axis(friction, per_run)
        phi_dot = _with_axis(phi_dot, per_run)
        phi_ddot, theta_ddot = _coordinates(sys, theta, theta_dot, phi_dot, kick, t, friction)
        return (phi_ddot[..., 0] if per_run else phi_ddot), theta_ddot
    phi_dot = phi_dot if per_run else phi_dot[..., 0]
    if friction is not None and not per_run:
        friction = friction[..., 0]
    phi_ddot, theta_ddot = _one_coordinate(flat, theta, theta_dot, phi_dot, kick, t, friction)
    return (phi_ddot if per_run else phi_ddot[..., None]), theta_ddot


def _one_coordinate(sys, theta, theta_dot, phi_dot, kick, t=0.0, friction=None):
    """Solved equations of motion, eqs. (eqm1)–(eqm2), one coordinate (constants per run).

    Parameters
    ----------
    sys : per-run (B,) and per-metronome (B, N) constants.
    theta, theta_dot, kick : arrays (B, N).
    phi_dot : array (B,).
    t : time, s (for the applied torque).
    friction : the disk's dry-friction torque (B,), N m; default the Coulomb law at
        ``phi_dot`` (`dry_friction`).

    Returns
    -------
    phi_ddot : (B,), theta_ddot : (B, N)
    """
    numerator, denominator, sin_t, cos_t = _disk_equation(sys, theta, theta_dot, phi_dot, kick, t)
    if friction is None:
        friction = _coulomb(sys.dry_friction, phi_dot, -numerator)
    phi_ddot = (numerator + friction) / denominator
    theta_ddot = (
        kick
        - sys.lever[:, None] * sys.mh * phi_ddot[:, None] * cos_t
        - sys.mgh * sin_t
        - sys.c_theta * theta_dot
    ) / sys.inertia
    return phi_ddot, theta_ddot


def holding_torque(sys: SystemArrays, theta, theta_dot, phi_dot, kick, t=0.0):
    """The dry-friction torque that would keep the disk from accelerating (φ̈ = 0):
    minus everything else in the numerator of eq. (eqm1), N m, shaped as ``phi_dot``."""
    flat, per_run = _as_flat(sys), _per_run(theta, phi_dot)
    if flat is None:
        rhs = _platform_equation(sys, theta, theta_dot, _with_axis(phi_dot, per_run), kick, t)[0]
        return -(rhs[..., 0] if per_run else rhs)
    phi_dot = phi_dot if per_run else phi_dot[..., 0]
    holding = -_disk_equation(flat, theta, theta_dot, phi_dot, kick, t)[0]
    return holding if per_run else holding[..., None]


def dry_friction(sys: SystemArrays, phi_dot, holding):
    """The Coulomb law of the disk's dry friction, (B,) N m, with T = ``sys.dry_friction``.

    A moving disk (φ̇ ≠ 0) feels −T sign φ̇. A disk at rest feels ``holding`` (the
    `holding_torque`) clipped to ±T: it stays at rest when |holding| ≤ T, else it
    starts to slip the way the other torques push it, against a friction of T.
    """
    limit = np.asarray(sys.dry_friction)
    if np.ndim(phi_dot) > limit.ndim:  # per coordinate: the one coordinate's
        limit = limit[..., None]
    return _coulomb(limit, phi_dot, holding)


def _coulomb(limit, phi_dot, holding):
    return np.where(phi_dot != 0, -limit * np.sign(phi_dot), np.clip(holding, -limit, limit))


def effective_inertia(sys: SystemArrays, theta):
    """D of eq. (eqm1), (B, P, P) kg m²: M − Σ_i (m_i h_i cos θ_i)² / I_i ℓ_i ℓ_iᵀ, for
    one coordinate J + R²Σm − R² Σ_i (m_i h_i cos θ_i)² / I_i, and (B,) when the
    constants are given per run (`SystemArrays.one_coordinate`). An extra torque ΔF on
    the disk changes φ̈ by D⁻¹ΔF (and each θ̈_i by −m_i h_i cos θ_i ℓ_i·D⁻¹ΔF / I_i)."""
    if isinstance(sys, SystemArrays):
        flat = sys.one_coordinate()
        if flat is None:
            q = sys.mh * np.cos(theta)
            outer = np.einsum("...n,...np,...nq->...pq", q * q / sys.inertia, sys.lever, sys.lever)
            return sys.total_inertia - outer
        return effective_inertia(flat, theta)[..., None, None]
    d_sum = (sys.lever[:, None] * sys.mh) ** 2 / sys.inertia * np.cos(theta) ** 2
    return sys.total_inertia - np.sum(d_sum, axis=-1)


def _disk_equation(sys, theta, theta_dot, phi_dot, kick, t):
    """Numerator (without dry friction) and denominator of eq. (eqm1), sin θ, cos θ."""
    sin_t = np.sin(theta)
    cos_t = np.cos(theta)
    lever = sys.lever[:, None]
    mh_over_i = sys.mh / sys.inertia
    a_sum = lever * mh_over_i * sys.mgh * sin_t * cos_t  # A = m²gR Σ h² sin cos / I
    b_sum = lever * mh_over_i * sys.c_theta * theta_dot * cos_t  # B
    c_sum = lever * mh_over_i * kick * cos_t  # C
    numerator = (
        sys.lever * np.sum(sys.mh * theta_dot**2 * sin_t, axis=-1)
        + disk_torque(sys, phi_dot, kick, t)
        + np.sum(a_sum + b_sum - c_sum, axis=-1)
    )
    return numerator, effective_inertia(sys, theta), sin_t, cos_t  # D


def residuals(sys: SystemArrays, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, t=0.0):
    """Left minus right of the unsolved equations (metron2a) and (metron2), the disk's
    with the Coulomb law of its dry friction (`dry_friction`): −T sign φ̇ when it
    moves, −T sign φ̈ when it starts from rest, anything within ±T when it stays at rest.

    Returns (disk residual shaped as ``phi_dot``, pendulum residuals (B, N)); both
    vanish for accelerations that solve the system.
    """
    flat, per_run = _as_flat(sys), _per_run(theta, phi_dot)
    if flat is None:
        disk, pendulum = _coordinate_residuals(
            sys,
            theta,
            theta_dot,
            _with_axis(phi_dot, per_run),
            kick,
            _with_axis(phi_ddot, per_run),
            theta_ddot,
            t,
        )
        return (disk[..., 0] if per_run else disk), pendulum
    if not per_run:
        phi_dot, phi_ddot = phi_dot[..., 0], phi_ddot[..., 0]
    disk, pendulum = _one_residuals(flat, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, t)
    return (disk if per_run else disk[..., None]), pendulum


def _one_residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, t):
    sin_t = np.sin(theta)
    cos_t = np.cos(theta)
    lever = sys.lever[:, None]
    needed = (  # the dry-friction torque these accelerations need
        sys.total_inertia * phi_ddot
        + sys.lever * np.sum(sys.mh * (theta_ddot * cos_t - theta_dot**2 * sin_t), axis=-1)
        - disk_torque(sys, phi_dot, kick, t)
    )
    limit = sys.dry_friction
    allowed = np.where(
        phi_dot != 0,
        -limit * np.sign(phi_dot),
        np.where(phi_ddot != 0, -limit * np.sign(phi_ddot), np.clip(needed, -limit, limit)),
    )
    pendulum = (
        sys.inertia * theta_ddot
        + lever * sys.mh * phi_ddot[:, None] * cos_t
        + sys.mgh * sin_t
        + sys.c_theta * theta_dot
        - kick
    )
    return needed - allowed, pendulum


def _as_flat(sys):
    """The constants per run of a one-coordinate platform with one lever (they may be
    given so already), else None."""
    if np.ndim(sys.lever) == 1:
        return sys
    return sys.one_coordinate()


def _per_run(theta, phi_dot) -> bool:
    """Whether ``phi_dot`` is given per run, without the coordinate axis."""
    return np.ndim(phi_dot) == np.ndim(theta) - 1


def _with_axis(value, per_run):
    return np.asarray(value)[..., None] if per_run else np.asarray(value)


def _platform_equation(sys, theta, theta_dot, phi_dot, kick, t):
    """Right-hand side (without dry friction) and D of D(θ) φ̈ = rhs, P coordinates:
    rhs = F + Σ_i ℓ_i [m_i h_i θ̇_i² sin θ_i + q_i/I_i (m_i g h_i sin θ_i + c_θ θ̇_i − 𝕄_i)],
    q_i = m_i h_i cos θ_i, F the torque from outside the pendulums (`disk_torque`)."""
    sin_t = np.sin(theta)
    cos_t = np.cos(theta)
    q = sys.mh * cos_t
    swing = sys.mh * theta_dot**2 * sin_t + q / sys.inertia * (
        sys.mgh * sin_t + sys.c_theta * theta_dot - kick
    )
    rhs = disk_torque(sys, phi_dot, kick, t) + np.einsum("...np,...n->...p", sys.lever, swing)
    return rhs, effective_inertia(sys, theta), sin_t, q


def _coordinates(sys, theta, theta_dot, phi_dot, kick, t, friction):
    """φ̈ (B, P) from D(θ) φ̈ = rhs + friction, and θ̈ (B, N); a pinned platform
    (an infinite inertia) stays still."""
    rhs, d, sin_t, q = _platform_equation(sys, theta, theta_dot, phi_dot, kick, t)
    if friction is None:
        friction = dry_friction(sys, phi_dot, -rhs)
    rigid = np.any(np.isinf(d), axis=(-2, -1))
    p = d.shape[-1]
    solvable = np.where(rigid[..., None, None], np.eye(p), d)
    solvable = np.where(np.isfinite(solvable), solvable, 1.0)  # a diverged run stays NaN
    phi_ddot = np.linalg.solve(solvable, (rhs + friction)[..., None])[..., 0]
    finite = np.all(np.isfinite(d), axis=(-2, -1)) | rigid
    phi_ddot = np.where(rigid[..., None], 0.0, np.where(finite[..., None], phi_ddot, np.nan))
    along = np.einsum("...np,...p->...n", sys.lever, phi_ddot)
    theta_ddot = (kick - q * along - sys.mgh * sin_t - sys.c_theta * theta_dot) / sys.inertia
    return phi_ddot, theta_ddot


def _coordinate_residuals(sys, theta, theta_dot, phi_dot, kick, phi_ddot, theta_ddot, t):
    """`residuals` for P coordinates: M φ̈ + Σ_i ℓ_i m_i h_i (θ̈_i cos θ_i − θ̇_i² sin θ_i)
    − F, less the friction the Coulomb law allows, and the pendulums' residuals."""
    sin_t = np.sin(theta)
    cos_t = np.cos(theta)
    swing = sys.mh * (theta_ddot * cos_t - theta_dot**2 * sin_t)
    needed = (
        np.einsum("...pq,...q->...p", sys.total_inertia, phi_ddot)
        + np.einsum("...np,...n->...p", sys.lever, swing)
        - disk_torque(sys, phi_dot, kick, t)
    )
    limit = sys.dry_friction[..., None]
    allowed = np.where(
        phi_dot != 0,
        -limit * np.sign(phi_dot),
        np.where(phi_ddot != 0, -limit * np.sign(phi_ddot), np.clip(needed, -limit, limit)),
    )
    along = np.einsum("...np,...p->...n", sys.lever, phi_ddot)
    pendulum = (
        sys.inertia * theta_ddot
        + sys.mh * along * cos_t
        + sys.mgh * sin_t
        + sys.c_theta * theta_dot
        - kick
    )
    return needed - allowed, pendulum

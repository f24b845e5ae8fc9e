"""Conserved quantities of the frictionless, undriven system (paper eq. (lagrange)).

E   = ½ (J + R²Σm) φ̇² + Σ ½ (m h² + J_i) θ̇_i² + R φ̇ Σ m h cos θ_i θ̇_i + Σ m g h (1 − cos θ_i)
p_φ = (J + R²Σm) φ̇ + R Σ m h cos θ_i θ̇_i

and for a platform of P coordinates (lever ℓ_i, inertia M, `SystemArrays`)

E   = ½ φ̇ᵀ M φ̇ + Σ ½ (m h² + J_i) θ̇_i² + φ̇·Σ ℓ_i m h cos θ_i θ̇_i + Σ m g h (1 − cos θ_i)
p_φ = M φ̇ + Σ ℓ_i m h cos θ_i θ̇_i   (P components)

Shapes: theta, theta_dot (..., B, N); phi_dot (..., B, P), or (..., B) for a platform
of one coordinate (then p_φ is (..., B) too); constants from `SystemArrays`. A pinned
platform (M = ∞) contributes nothing.
"""

from __future__ import annotations

import numpy as np

from ..equations import SystemArrays


def total_energy(sys: SystemArrays, theta, theta_dot, phi_dot):
    theta = np.asarray(theta)
    theta_dot = np.asarray(theta_dot)
    phi_dot = np.asarray(phi_dot)
    flat = sys.one_coordinate()
    pend = 0.5 * sys.inertia * theta_dot**2 + sys.mgh * (1 - np.cos(theta))
    if flat is not None:  # the one-coordinate form, as ever
        if phi_dot.ndim == theta.ndim:
            phi_dot = phi_dot[..., 0]
        rigid = np.isinf(flat.total_inertia)
        disk_inertia = np.where(rigid, 0.0, flat.total_inertia)
        phd = np.where(rigid, 0.0, phi_dot)
        cross = flat.lever[:, None] * phd[..., None] * sys.mh * np.cos(theta) * theta_dot
        return 0.5 * disk_inertia * phd**2 + np.sum(pend + cross, axis=-1)
    rigid = np.any(np.isinf(sys.total_inertia), axis=(-2, -1))
    inertia = np.where(rigid[:, None, None], 0.0, sys.total_inertia)
    phd = np.where(rigid[:, None], 0.0, phi_dot)
    own = 0.5 * np.einsum("...p,...pq,...q->...", phd, inertia, phd)
    along = np.einsum("...np,...p->...n", sys.lever, phd)
    return own + np.sum(pend + along * sys.mh * np.cos(theta) * theta_dot, axis=-1)


def platform_momentum(sys: SystemArrays, theta, theta_dot, phi_dot):
    theta = np.asarray(theta)
    phi_dot = np.asarray(phi_dot)
    flat = sys.one_coordinate()
    if flat is not None and phi_dot.ndim == theta.ndim - 1:  # per run, as ever
        rigid = np.isinf(flat.total_inertia)
        disk_inertia = np.where(rigid, 0.0, flat.total_inertia)
        coupling = flat.lever * np.sum(sys.mh * np.cos(theta) * theta_dot, axis=-1)
        return np.where(rigid, 0.0, disk_inertia * phi_dot + coupling)
    if flat is not None:  # the same operations, per coordinate
        return platform_momentum(sys, theta, theta_dot, phi_dot[..., 0])[..., None]
    rigid = np.any(np.isinf(sys.total_inertia), axis=(-2, -1))[:, None]
    inertia = np.where(rigid[..., None], 0.0, sys.total_inertia)
    q = sys.mh * np.cos(theta) * theta_dot
    coupling = np.einsum("...np,...n->...p", sys.lever, q)
    return np.where(rigid, 0.0, np.einsum("...pq,...q->...p", inertia, phi_dot) + coupling)

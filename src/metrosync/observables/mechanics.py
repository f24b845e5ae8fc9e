"""Conserved quantities of the frictionless, undriven system (paper eq. (lagrange)).

E   = ½ (J + R²Σm) φ̇² + Σ ½ (m h² + J_i) θ̇_i² + R φ̇ Σ m h cos θ_i θ̇_i + Σ m g h (1 − cos θ_i)
p_φ = (J + R²Σm) φ̇ + R Σ m h cos θ_i θ̇_i

Shapes: theta, theta_dot (..., B, N); phi_dot (..., B); constants from `SystemArrays`
(B, N) and (B,). A pinned disk (J = ∞) contributes nothing.
"""

from __future__ import annotations

import numpy as np

from ..equations import SystemArrays


def total_energy(sys: SystemArrays, theta, theta_dot, phi_dot):
    theta = np.asarray(theta)
    theta_dot = np.asarray(theta_dot)
    phi_dot = np.asarray(phi_dot)
    rigid = np.isinf(sys.total_inertia)
    disk_inertia = np.where(rigid, 0.0, sys.total_inertia)
    phd = np.where(rigid, 0.0, phi_dot)
    pend = 0.5 * sys.inertia * theta_dot**2 + sys.mgh * (1 - np.cos(theta))
    cross = sys.lever[:, None] * phd[..., None] * sys.mh * np.cos(theta) * theta_dot
    return 0.5 * disk_inertia * phd**2 + np.sum(pend + cross, axis=-1)


def platform_momentum(sys: SystemArrays, theta, theta_dot, phi_dot):
    rigid = np.isinf(sys.total_inertia)
    disk_inertia = np.where(rigid, 0.0, sys.total_inertia)
    coupling = sys.lever * np.sum(sys.mh * np.cos(theta) * theta_dot, axis=-1)
    return np.where(rigid, 0.0, disk_inertia * np.asarray(phi_dot) + coupling)

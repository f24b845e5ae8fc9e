"""Pantaleone's averaged theory of two metronomes on a board, at his parameters.

His model (Am. J. Phys. 70, 992 (2002), Eqs. 1–2 and 12–15) in his dimensionless time
τ = ω t: each pendulum a van der Pol oscillator with the pendulum's sin θ, coupled by
the board's motion,

    θ_i'' + (1 + Δ_i) sin θ_i + μ ((θ_i/θ₀)² − 1) θ_i' = β cos θ_i (Σ_j sin θ_j)'',

with β = x₀ω²/g, x₀ = m r_cm/(M + 2m). Averaging (θ_i = A_i cos(τ + ψ_i), to first order
in μ, β, Δ and the pendulum's anharmonicity sin θ ≈ θ − θ³/6; docs/model.md §9.4 has
the steps) gives for the amplitudes and the phase difference δ = ψ₁ − ψ₂

    A₁' = (μ A₁/2)(1 − A₁²/4θ₀²) + (β/2) A₂ sin δ,
    A₂' = (μ A₂/2)(1 − A₂²/4θ₀²) − (β/2) A₁ sin δ,
    δ'  = d − (A₁² − A₂²)/16 + (β/2) cos δ (A₂/A₁ − A₁/A₂),

d = (Δ₁ − Δ₂)/2 the relative detuning Δω/ω. The coupling moves the amplitudes apart,
and the anharmonic pendulum turns the amplitude difference into a frequency
difference: that is what locks the pair in phase. With the amplitudes slaved
(μ ≫ β) δ' = d − (β θ₀²/2μ) sin δ: a lag sin δ* = 2μ d/(β θ₀²), the faster one
leading, lost at d_c = β θ₀²/(2μ). At his parameters β ≈ μ, so this module solves the
three equations' fixed point itself rather than relying on that limit.

These are our derivation of the averaging his paper describes, evaluated with his
published β, μ and θ₀; they are compared with the simulated board and with the
reduced theory of `metrosync.theory` in the Pantaleone report.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import fsolve

from ..errors import ParameterError


@dataclass(frozen=True)
class VanDerPolPair:
    """His parameters: β (coupling), μ (van der Pol), θ₀ (half the free amplitude)."""

    beta: float = 0.011
    mu: float = 0.010
    theta0: float = 0.39

    def __post_init__(self) -> None:
        for name in ("beta", "mu", "theta0"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(f"`{name}` must be a finite number > 0, got {value!r}.")

    def rates(self, state: np.ndarray, d: float) -> np.ndarray:
        """(A₁', A₂', δ') of the averaged equations (module docstring)."""
        a1, a2, delta = state
        beta, mu, limit = self.beta, self.mu, 4 * self.theta0**2
        return np.array(
            [
                0.5 * mu * a1 * (1 - a1 * a1 / limit) + 0.5 * beta * a2 * math.sin(delta),
                0.5 * mu * a2 * (1 - a2 * a2 / limit) - 0.5 * beta * a1 * math.sin(delta),
                d - (a1 * a1 - a2 * a2) / 16 + 0.5 * beta * math.cos(delta) * (a2 / a1 - a1 / a2),
            ]
        )

    def slaved_threshold(self) -> float:
        """d_c = β θ₀²/(2μ), the locking range with the amplitudes slaved (μ ≫ β)."""
        return self.beta * self.theta0**2 / (2 * self.mu)

    def locked(self, d: float, guess: np.ndarray | None = None) -> np.ndarray | None:
        """The stable locked state (A₁, A₂, δ) at detuning ``d``, or None when the pair
        does not lock (no fixed point, or only unstable ones, near this guess)."""
        start = np.array([2 * self.theta0, 2 * self.theta0, 0.0]) if guess is None else guess
        root, info, status, _ = fsolve(self.rates, start, args=(d,), full_output=True)
        if status != 1 or np.max(np.abs(info["fvec"])) > 1e-12 or root[0] <= 0 or root[1] <= 0:
            return None
        if abs(root[2]) >= math.pi / 2 or not self._stable(root, d):
            return None
        return root

    def _stable(self, state: np.ndarray, d: float, h: float = 1e-7) -> bool:
        jac = np.column_stack(
            [(self.rates(state + e, d) - self.rates(state - e, d)) / (2 * h) for e in np.eye(3) * h]
        )
        return bool(np.all(np.linalg.eigvals(jac).real < 0))

    def lag_curve(self, detunings: np.ndarray) -> np.ndarray:
        """The locked phase lag δ* (rad, > 0: the faster one leads) at each relative
        detuning d ≥ 0 (ascending), by continuation from d = 0; NaN where unlocked."""
        detunings = np.asarray(detunings, dtype=float)
        if np.any(detunings < 0) or np.any(np.diff(detunings) < 0):
            raise ParameterError("`detunings` must be >= 0 and ascending.")
        out = np.full(detunings.shape, np.nan)
        guess = None
        limit = self.threshold()
        for k, d in enumerate(detunings):
            # Near the fold a root finder can land on the other branch: stop at the fold.
            state = self.locked(d, guess) if d <= limit else None
            if state is None:
                break  # past the saddle-node: no locking at larger detuning either
            out[k], guess = state[2], state
        return out

    def threshold(self, tolerance: float = 1e-6) -> float:
        """The largest relative detuning d at which the pair locks (bisection on the
        continuation of `lag_curve`)."""
        low, high = 0.0, 4 * self.slaved_threshold() + 0.1
        guess = None
        while high - low > tolerance:
            middle = 0.5 * (low + high)
            state = self.locked(middle, guess)
            if state is None:
                high = middle
            else:
                low, guess = middle, state
        return low

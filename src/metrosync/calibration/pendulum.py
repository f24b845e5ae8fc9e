"""Amplitude relations of a single pendulum on a rigid support (paper §5).

Contract: pure functions for the undriven pendulum I θ̈ + m g h sin θ + c θ̇ = 0
with ω0² = m g h / I, exact in the amplitude A (no small-angle approximation),
averaged over a swing (valid when damping changes A little per period):

* `mean_square_speed` G(A) = ⟨θ̇²⟩/ω0² = 4[E(m) − (1 − m)K(m)]/K(m), m = sin²(A/2);
* `envelope_coordinate` u(A) = ∫ sin a / (2 G(a)) da, normalised so that
  u(A) = ln A + O(A²). Energy balance, d/dt[m g h (1 − cos A)] = −c ⟨θ̇²⟩, gives
  du/dt = −c/(2I): u(A(t)) is a straight line in t whose slope gives c_θ;
* `time_beyond` and `amplitude_from_ratio`: the fraction of a period spent beyond a
  gate at angle δ, s/T = [1 − F(ψ, m)/K(m)]/2 with sin ψ = sin(δ/2)/sin(A/2), and its
  inverse, which turns light-gate intervals into amplitudes;
* `swing_amplitudes`: the extrema of a sampled θ(t), refined by a parabola.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk, ellipkinc

from ..errors import CalibrationError

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(48)


def mean_square_speed(amplitude):
    """G(A) = ⟨θ̇²⟩ / ω0² over a swing of amplitude A (rad); A²/2 for small A."""
    m = np.sin(np.asarray(amplitude, dtype=float) / 2) ** 2
    k = ellipk(m)
    # E − (1−m)K cancels for small m; its series (π/2)(m/2 + m²/16 + 3m³/128) does not.
    series = np.pi / 2 * m * (0.5 + m * (1 / 16 + m * 3 / 128))
    diff = np.where(m < 1e-3, series, ellipe(m) - (1.0 - m) * k)
    return 4.0 * diff / k


def envelope_coordinate(amplitude):
    """u(A) = ln A + ∫_0^A [sin a/(2G(a)) − 1/a] da, for 0 < A < π."""
    amp = np.atleast_1d(np.asarray(amplitude, dtype=float))
    a = amp[:, None] * (_NODES[None, :] + 1) / 2
    integrand = np.sin(a) / (2 * mean_square_speed(a)) - 1 / a
    out = np.log(amp) + amp / 2 * (integrand @ _WEIGHTS)
    return out if np.ndim(amplitude) else float(out[0])


def time_beyond(amplitude, offset):
    """Fraction s/T of a period the bob spends beyond a gate at ``offset`` (rad)."""
    k = np.sin(np.asarray(amplitude, dtype=float) / 2)
    m = k * k
    psi = np.arcsin(np.clip(np.sin(offset / 2) / k, -1, 1))
    return 0.5 * (1.0 - ellipkinc(psi, m) / ellipk(m))


def amplitude_from_ratio(ratio, offset: float):
    """Invert `time_beyond`: amplitudes (rad) from measured s/T at a gate at ``offset``."""
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    if offset <= 0:
        raise CalibrationError(
            f"the gate offset must be > 0 rad to read amplitudes, got {offset!r}."
        )
    out = np.full(ratio.shape, np.nan)
    lo, hi = offset * (1 + 1e-9), np.pi * (1 - 1e-9)
    top = time_beyond(hi, offset)
    for i, q in enumerate(ratio):
        if 0 < q < top:
            out[i] = brentq(lambda a, q=q: time_beyond(a, offset) - q, lo, hi, xtol=1e-12)
    return out


def swing_amplitudes(time, theta):
    """Extrema of θ(t): (times (E,), amplitudes |θ| (E,)), refined by a parabola.

    time, theta : (T,) uniformly sampled.
    """
    t = np.asarray(time, dtype=float)
    y = np.asarray(theta, dtype=float)
    mid = y[1:-1]
    peak = ((mid > y[:-2]) & (mid >= y[2:]) & (mid > 0)) | (
        (mid < y[:-2]) & (mid <= y[2:]) & (mid < 0)
    )
    k = np.flatnonzero(peak) + 1
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    denom = y0 - 2 * y1 + y2
    with np.errstate(invalid="ignore", divide="ignore"):
        shift = np.where(denom != 0, 0.5 * (y0 - y2) / denom, 0.0)
    h = t[1] - t[0] if t.size > 1 else 0.0
    value = y1 - 0.25 * (y0 - y2) * shift
    return t[k] + shift * h, np.abs(value)

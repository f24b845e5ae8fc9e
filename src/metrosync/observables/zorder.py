"""The z order parameter of two metronomes (paper §6).

With t_i^max, t_i^min the times of the maxima and minima of θ₁ and T_j^max those of
the maxima of θ₂,

    t1 = ⟨ min_i |t_i^max − T_j^max| ⟩_j,    t2 = ⟨ min_i |t_i^min − T_j^max| ⟩_j,
    z  = (t2 − t1) / (t2 + t1) ∈ [−1, 1]:  +1 in phase, −1 in anti-phase.
"""

from __future__ import annotations

import numpy as np


def extrema_times(time, x, kind: str = "max"):
    """Times of the strict local maxima (or minima) of a sampled signal, refined by a
    parabola through the three samples around each. time, x : (T,). Returns (K,)."""
    time = np.asarray(time, dtype=float)
    x = np.asarray(x, dtype=float)
    if kind == "min":
        x = -x
    elif kind != "max":
        raise ValueError(f"`kind` must be 'max' or 'min', got {kind!r}.")
    left, mid, right = x[:-2], x[1:-1], x[2:]
    idx = np.nonzero((mid > left) & (mid >= right))[0] + 1
    curvature = x[idx - 1] - 2 * x[idx] + x[idx + 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        shift = np.where(curvature != 0, 0.5 * (x[idx - 1] - x[idx + 1]) / curvature, 0.0)
    step = time[idx + 1] - time[idx]
    return time[idx] + shift * step


def z_order(time, theta1, theta2, *, start: float | None = None) -> float:
    """z of two metronomes from their sampled angles.

    time : (T,); theta1, theta2 : (T,). ``start`` drops the transient before it.
    Returns NaN when either signal has no maxima or minima to compare.
    """
    time = np.asarray(time, dtype=float)
    if start is not None:
        keep = time >= start
        time, theta1, theta2 = time[keep], np.asarray(theta1)[keep], np.asarray(theta2)[keep]
    max1 = extrema_times(time, theta1, "max")
    min1 = extrema_times(time, theta1, "min")
    max2 = extrema_times(time, theta2, "max")
    if min(max1.size, min1.size, max2.size) == 0:
        return float("nan")
    t1 = _mean_nearest_distance(max1, max2)
    t2 = _mean_nearest_distance(min1, max2)
    if t1 + t2 == 0:
        return float("nan")
    return float((t2 - t1) / (t2 + t1))


def _mean_nearest_distance(reference, targets) -> float:
    """⟨ min_i |reference_i − target_j| ⟩ over targets j (reference sorted)."""
    k = np.clip(np.searchsorted(reference, targets), 1, reference.size - 1)
    if reference.size == 1:
        return float(np.mean(np.abs(targets - reference[0])))
    nearest = np.minimum(np.abs(targets - reference[k - 1]), np.abs(targets - reference[k]))
    return float(np.mean(nearest))

"""The Kuramoto order parameter r e^{iψ} = (1/N) Σ_j e^{iΦ_j} (paper eq. (op)).

Φ_j is a rotator phase, not the pendulum angle. Two ways to get it:

* analytic: Φ = atan2(−θ̇/ω, θ), from the state of a nearly harmonic swing;
* crossing-interpolated (the experiment's method, paper §2): keep one pass per
  period in one direction, and let Φ rise linearly from 0 to 2π between consecutive
  kept passes. It is defined only between a metronome's first and last kept pass.

Functions here are pure and work on arrays; shapes are in each docstring.
"""

from __future__ import annotations

import numpy as np


def analytic_phase(theta, theta_dot, omega):
    """Φ = atan2(−θ̇/ω, θ); arrays broadcast together."""
    return np.arctan2(-np.asarray(theta_dot) / omega, theta)


def order_parameter(phases, axis: int = -1):
    """r = |mean_j e^{iΦ_j}| along ``axis``; NaN wherever any phase is NaN."""
    return np.abs(np.mean(np.exp(1j * np.asarray(phases)), axis=axis))


def crossing_phase(crossing_times, grid):
    """Phase on ``grid`` interpolated between kept passes.

    Parameters
    ----------
    crossing_times : (K,) increasing times of one metronome's kept passes.
    grid : (T,) times.

    Returns
    -------
    (T,) phase in [0, 2π); NaN before the first and from the last pass on.
    """
    times = np.asarray(crossing_times, dtype=float)
    grid = np.asarray(grid, dtype=float)
    out = np.full(grid.shape, np.nan)
    if times.size < 2:
        return out
    k = np.searchsorted(times, grid, side="right") - 1
    inside = (k >= 0) & (k < times.size - 1)
    t0 = times[k[inside]]
    t1 = times[k[inside] + 1]
    out[inside] = 2 * np.pi * (grid[inside] - t0) / (t1 - t0)
    return out


def crossing_order(crossings, grid):
    """r(t) from crossing-interpolated phases of several metronomes.

    crossings : sequence of N arrays of kept-pass times.   grid : (T,).
    Returns (T,) r, NaN where some metronome has no phase.
    """
    phases = np.stack([crossing_phase(c, grid) for c in crossings])
    return order_parameter(phases, axis=0)


def common_span(crossings) -> tuple[float, float]:
    """[start, end) of the span where every metronome has an interpolated phase."""
    starts = [c[0] for c in crossings if len(c) >= 2]
    ends = [c[-1] for c in crossings if len(c) >= 2]
    if len(starts) < len(crossings):
        return (np.nan, np.nan)
    return (max(starts), min(ends))


def equilibrium_order(r, time, window: float):
    """Time average of r over the final ``window`` seconds, ignoring NaN.

    r : (T, B) or (T,).   time : (T,).
    Returns (B,) or scalar; NaN where the window holds no finite value.
    """
    r = np.asarray(r, dtype=float)
    time = np.asarray(time, dtype=float)
    mask = time >= time[-1] - window
    tail = r[mask]
    finite = np.isfinite(tail)
    count = finite.sum(axis=0)
    total = np.where(finite, tail, 0.0).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def ensemble_statistics(r_eq) -> tuple[float, float]:
    """Mean equilibrium r and its spread σ_r (sample std) across runs, ignoring NaN."""
    r_eq = np.asarray(r_eq, dtype=float)
    finite = r_eq[np.isfinite(r_eq)]
    if finite.size == 0:
        return (np.nan, np.nan)
    spread = float(np.std(finite, ddof=1)) if finite.size > 1 else 0.0
    return (float(np.mean(finite)), spread)

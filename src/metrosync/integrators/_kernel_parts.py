"""Compiled pieces shared by every fixed-step kernel: crossing-phase bookkeeping and
the per-record observables. They run once per crossing or per record, never in the
vectorized hot loop."""

from __future__ import annotations

import math

import numba as nb

TWO_PI = 2.0 * math.pi


@nb.njit(cache=True, inline="always")
def add_crossing_phase(cross_re, cross_im, cross_count, b, t_prev, t_next, grid_dt, n_rec):
    """Add e^{iΦ} for grid times in [t_prev, t_next), Φ rising linearly 0 → 2π."""
    period = t_next - t_prev
    g0 = int(math.ceil(t_prev / grid_dt))
    g1 = min(int(math.ceil(t_next / grid_dt)), n_rec)
    for g in range(g0, g1):
        ph = TWO_PI * (g * grid_dt - t_prev) / period
        cross_re[b, g] += math.cos(ph)
        cross_im[b, g] += math.sin(ph)
        cross_count[b, g] += 1


@nb.njit(cache=True, inline="always")
def upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec):
    """Book an upward zero crossing of metronome ``i`` of run ``b`` at ``t_cross``."""
    if last_up[b, i] >= 0.0:
        add_crossing_phase(
            cross_re, cross_im, cross_count, b, last_up[b, i], t_cross, grid_dt, n_rec
        )
    last_up[b, i] = t_cross


@nb.njit(cache=True, inline="always")
def analytic_order(theta_row, theta_dot_row, omega_row):
    """r from the analytic phases Φ = atan2(−θ̇/ω, θ) of one run's metronomes."""
    n = theta_row.shape[0]
    re = 0.0
    im = 0.0
    for i in range(n):
        x = theta_row[i]
        y = -theta_dot_row[i] / omega_row[i]
        rho = math.sqrt(x * x + y * y)
        if rho > 0.0:
            re += x / rho
            im += y / rho
    return math.sqrt(re * re + im * im) / n

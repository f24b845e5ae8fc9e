"""Compiled pieces shared by every fixed-step kernel: the scheme's updates (see
`verlet`), crossing-phase bookkeeping and the per-record observables. The CPU layouts
inline them; `kernel_cuda` compiles the same source as CUDA device functions, with
the sums' update (`accumulate`) made atomic and a run's order parameter
(`analytic_order`, from `phase_vector` and `resultant`) summed over a thread block.

Groups of metronomes (`metrosync.ensemble`) are contiguous: group g holds metronomes
``group_start[g]`` to ``group_start[g + 1] - 1``. The crossing-phase sums are kept per
group, (B, n_rec, G), so that both the global and each group's order parameter follow
from them; an ungrouped ensemble is one group.

The forces are not here but in `_physics`. `drift` and `velocity` run in the
vectorized hot loop (``inline="always"``, arithmetic only); the bookkeeping runs once
per crossing or per record.
"""

from __future__ import annotations

import math

import numba as nb

from ._physics import disk_acceleration
from .trig import sincos

TWO_PI = 2.0 * math.pi


@nb.njit(cache=True, inline="always")
def drift(x, v, a, dt, dt2):
    """Step 1 of the scheme: the new position x + v dt + a dt²/2 and the predicted
    velocity v + a dt at which the forces are evaluated."""
    return x + v * dt + 0.5 * a * dt2, v + a * dt


@nb.njit(cache=True, inline="always")
def velocity(v, a, a_next, dt):
    """Step 4: the velocity after the step, v + (a + a') dt/2."""
    return v + 0.5 * (a + a_next) * dt


@nb.njit(cache=True, inline="always")
def momentum(p_phi, force, force_next, dt, pinned):
    """Step 5: the disk's angular momentum after the step, dp_φ/dt = F by the trapezoid
    rule; a pinned disk keeps it (its mount takes the torque)."""
    return p_phi if pinned else p_phi + 0.5 * (force + force_next) * dt


@nb.njit(cache=True, inline="always")
def upward(theta, theta_next):
    """True when the step from ``theta`` to ``theta_next`` crosses 0 upwards."""
    return (theta < 0.0) & (theta_next > 0.0)


@nb.njit(cache=True, inline="always")
def group_of(i, group_start):
    """The group of metronome ``i`` (a short scan: there are few groups)."""
    g = 0
    while i >= group_start[g + 1]:
        g += 1
    return g


@nb.njit(cache=True, inline="always")
def add_crossing_phase(cross_re, cross_im, cross_count, b, t_prev, t_next, grid_dt, n_rec, grp):
    """Add e^{iΦ} for grid times in [t_prev, t_next), Φ rising linearly 0 → 2π, to the
    sums of group ``grp``.

    Φ advances by the same angle from one grid time to the next, so e^{iΦ} is
    rotated by a complex factor instead of calling sin and cos at every grid time
    (rounding grows by about an ulp per grid time, a few within one period).
    """
    period = t_next - t_prev
    g0 = int(math.ceil(t_prev / grid_dt))
    g1 = min(int(math.ceil(t_next / grid_dt)), n_rec)
    if g1 <= g0:
        return
    phase0 = TWO_PI * (g0 * grid_dt - t_prev) / period
    step = TWO_PI * grid_dt / period
    im, re = sincos(phase0)
    rot_im, rot_re = sincos(step)
    for g in range(g0, g1):
        accumulate(cross_re, (b, g, grp), re)
        accumulate(cross_im, (b, g, grp), im)
        accumulate(cross_count, (b, g, grp), 1)
        re, im = re * rot_re - im * rot_im, re * rot_im + im * rot_re


@nb.njit(cache=True, inline="always")
def upward_crossing(
    last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec, group_start
):
    """Book an upward zero crossing of metronome ``i`` of run ``b`` at ``t_cross``."""
    if last_up[b, i] >= 0.0:
        add_crossing_phase(
            cross_re,
            cross_im,
            cross_count,
            b,
            last_up[b, i],
            t_cross,
            grid_dt,
            n_rec,
            group_of(i, group_start),
        )
    last_up[b, i] = t_cross


@nb.njit(cache=True, inline="always")
def save_state(
    b, k, theta, theta_dot, phi, phi_dot, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot
):
    """Copy run ``b``'s state into record ``k`` of the trajectory buffers."""
    for i in range(theta.shape[1]):
        traj_theta[b, k, i] = theta[b, i]
        traj_theta_dot[b, k, i] = theta_dot[b, i]
    traj_phi[b, k] = phi[b]
    traj_phi_dot[b, k] = phi_dot[b]


@nb.njit(cache=True, inline="always")
def analytic_order(theta_row, theta_dot_row, omega_row):
    """r from the analytic phases Φ = atan2(−θ̇/ω, θ) of one run's metronomes."""
    n = theta_row.shape[0]
    re = 0.0
    im = 0.0
    for i in range(n):  # branch-free, so that it vectorizes
        x, y = phase_vector(theta_row[i], theta_dot_row[i], omega_row[i])
        re += x
        im += y
    return resultant(re, im, n)


@nb.njit(cache=True, inline="always")
def group_orders(r_group, b, k, theta_row, theta_dot_row, omega_row, group_start):
    """r of each group's analytic phases into ``r_group[b, k, :]`` (`analytic_order` on
    each group's contiguous slice of the run's metronomes)."""
    for g in range(group_start.shape[0] - 1):
        lo = group_start[g]
        hi = group_start[g + 1]
        r_group[b, k, g] = analytic_order(theta_row[lo:hi], theta_dot_row[lo:hi], omega_row[lo:hi])


@nb.njit(cache=True, inline="always")
def record_run(
    b,
    k,
    theta,
    theta_dot,
    phi,
    phi_dot,
    omega_row,
    r,
    r_group,
    group_start,
    traj_theta,
    traj_theta_dot,
    traj_phi,
    traj_phi_dot,
):
    """Record ``k`` of run ``b`` (metronomes innermost): r, each group's r when there are
    several groups, and the state when trajectories are kept."""
    r[b, k] = analytic_order(theta[b], theta_dot[b], omega_row)
    if group_start.shape[0] > 2:  # several groups
        group_orders(r_group, b, k, theta[b], theta_dot[b], omega_row, group_start)
    if traj_theta.shape[0] > 0:
        save_state(
            b, k, theta, theta_dot, phi, phi_dot, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot
        )


@nb.njit(cache=True, inline="always")
def accumulate(sums, index, value):
    """``sums[index] += value``: the one update of the crossing-phase sums. The GPU
    kernel compiles it as an atomic add, since a block's threads book crossings of the
    same run at once."""
    sums[index] += value


@nb.njit(cache=True, inline="always")
def phase_vector(theta, theta_dot, omega):
    """e^{iΦ} of a metronome's analytic phase Φ = atan2(−θ̇/ω, θ), as (cos Φ, sin Φ);
    (0, 0) for a pendulum at rest, which has no phase. Branch-free, so that a loop of it
    vectorizes."""
    y = -theta_dot / omega
    rho = math.sqrt(theta * theta + y * y)
    inv = 1.0 / rho if rho > 0.0 else 0.0
    return theta * inv, y * inv


@nb.njit(cache=True, inline="always")
def resultant(re, im, count):
    """The order parameter r = |Σ e^{iΦ}| / ``count`` from the sums of `phase_vector`."""
    return math.sqrt(re * re + im * im) / count


@nb.njit(cache=True, inline="always")
def kicked(theta_dot, theta_next, rest, after, half, dv, jrest):
    """A pendulum after its own impulse inside the step (``located``; ``dv``, ``jrest``
    from `_located_parts.kick`, ``after`` the time left in the step, ``half`` = dt/2):
    its velocity, net of the change of its forces that the second pass adds for dt/2;
    its new angle, moved on by the jump for ``after``; and its ρ."""
    return theta_dot + (dv + (after - half) * jrest), theta_next + after * dv, rest + jrest


@nb.njit(cache=True, inline="always")
def disk_jumps(c, r, jumps, sum_den):
    """The disk's share of a step's impulses, from their sums ``jumps`` (the layouts'
    ``add_jump``) and the step's denominator sum: its velocity jump Δφ̇, the shift of
    its angle (each jump travelling for the time left after it), and the change of φ̈.
    Every pendulum j then jumps by ``theta_ddot(c, j, r, 0, q_j, Δφ̇)`` and moves by
    the same of the shift."""
    return (
        disk_acceleration(c, r, jumps[0], sum_den, jumps[1]),
        disk_acceleration(c, r, jumps[2], sum_den, jumps[3]),
        disk_acceleration(c, r, jumps[4], sum_den, 0.0),
    )

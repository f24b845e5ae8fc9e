"""Accurate reference integrator: an 8th-order Dormand–Prince solver between impulses.

Between escapement events the equations are smooth, so scipy's DOP853 integrates them
to a tight tolerance. After every accepted step each pendulum's angle is checked for
a strict crossing of its escapement angle δ_i (0 in the paper, ``escapement_offset``
otherwise); the earliest crossing is located on the step's dense output (Brent's
method), the state is taken there, the crossing pendulum's angle is set to exactly
δ_i, and the escapement impulse is applied: angular momentum M·sign(θ̇) to the
pendulum and the matching reaction on the disk (unless ``escapement_reaction`` is
off), i.e. the kick-linear part of eqs. (eqm1)–(eqm2) integrated over the delta
function. Integration then restarts. The upward zero crossings that define the
crossing phase are the events themselves when δ_i = 0, and are located on the dense
output (without a restart) otherwise.

It is slow (Python-level stepping) and meant for checking the fixed-step scheme on
small ensembles and short horizons.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from ..equations import SystemArrays, accelerations
from ..observables.order import analytic_phase, crossing_order, order_parameter
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._state import Records

RTOL = 1e-11
ATOL = 1e-12


def integrate(
    sys: SystemArrays,
    theta0: np.ndarray,
    theta_dot0: np.ndarray,
    phi_dot0: np.ndarray,
    *,
    duration: float,
    grid_dt: float,
    n_records: int,
    trajectories: bool,
    overturn_angle: float,
    on_run_done: Callable[[], None] | None = None,
    group_start: np.ndarray | None = None,
) -> Records:
    """Integrate every run to ``duration``, sampling on a grid of step ``grid_dt``;
    ``group_start`` bounds the groups of metronomes (default: one group)."""
    runs, n = theta0.shape
    grid = np.arange(n_records) * grid_dt
    shape = (runs, n_records)
    bounds = [0, n] if group_start is None else [int(k) for k in group_start]
    groups = list(zip(bounds[:-1], bounds[1:], strict=True))
    out = Records(
        r=np.full(shape, np.nan),
        r_crossing=np.full(shape, np.nan),
        status=np.zeros(runs, dtype=np.int8),
        theta=np.full(shape + (n,), np.nan) if trajectories else None,
        theta_dot=np.full(shape + (n,), np.nan) if trajectories else None,
        phi=np.full(shape, np.nan) if trajectories else None,
        phi_dot=np.full(shape, np.nan) if trajectories else None,
        crossings=[],
        r_group=np.full(shape + (len(groups),), np.nan),
        r_crossing_group=np.full(shape + (len(groups),), np.nan),
    )
    for b in range(runs):
        samples, upcrossings, status = _integrate_run(
            sys.run(b), theta0[b], theta_dot0[b], phi_dot0[b], grid, duration, overturn_angle
        )
        out.status[b] = status
        out.crossings.append(upcrossings)
        th, thd = samples[:, 1 : n + 1], samples[:, n + 2 :]
        phase = analytic_phase(th, thd, sys.omega[b])
        out.r[b] = order_parameter(phase)
        out.r_crossing[b] = crossing_order(upcrossings, grid)
        for g, (lo, hi) in enumerate(groups):
            out.r_group[b, :, g] = order_parameter(phase[:, lo:hi])
            out.r_crossing_group[b, :, g] = crossing_order(upcrossings[lo:hi], grid)
        if trajectories:
            out.theta[b], out.theta_dot[b] = th, thd
            out.phi[b], out.phi_dot[b] = samples[:, 0], samples[:, n + 1]
        if on_run_done is not None:
            on_run_done()
    return out


def _integrate_run(sys, theta0, theta_dot0, phi_dot0, grid, duration, overturn_angle):
    """One run. Returns grid samples (T, 2N+2) of [φ, θ, φ̇, θ̇], upward-crossing times
    per metronome, and the status bits."""
    n = theta0.size
    offset = sys.escapement_offset[0]
    off_zero = np.nonzero(offset != 0.0)[0]  # their zero crossings are not events
    zero_kick = np.zeros((1, n))
    rigid = bool(np.isinf(sys.total_inertia[0]))
    period = 2 * np.pi / sys.omega.max()

    def rhs(t, y):
        th, thd, phd = y[None, 1 : n + 1], y[None, n + 2 :], y[n + 1 : n + 2]
        phdd, thdd = accelerations(sys, th, thd, phd, zero_kick, t)
        return np.concatenate(([y[n + 1]], y[n + 2 :], phdd, thdd[0]))

    y = np.concatenate(([0.0], theta0, [0.0 if rigid else phi_dot0], theta_dot0))
    samples = np.full((grid.size, y.size), np.nan)
    samples[0] = y
    next_sample = 1
    upcrossings: list[list[float]] = [[] for _ in range(n)]
    status = 0
    t = 0.0
    while t < duration:
        solver = DOP853(rhs, t, y, duration, rtol=RTOL, atol=ATOL, max_step=period / 8)
        restarted = False
        while solver.status == "running":
            y_old = solver.y.copy()
            solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                return samples, upcrossings, status | STATUS_DIVERGED
            dense = solver.dense_output()
            th_old, th_new = y_old[1 : n + 1], solver.y[1 : n + 1]
            crossing = np.nonzero((th_old - offset) * (th_new - offset) < 0)[0]
            t_end = solver.t
            event = None
            if crossing.size:
                roots = [_crossing(dense, 1 + i, offset[i], dense.t) for i in crossing]
                k = int(np.argmin(roots))
                event, t_end = int(crossing[k]), roots[k]
            if off_zero.size:
                th_end = th_new if event is None else dense(t_end)[1 : n + 1]
                for i in off_zero[(th_old[off_zero] < 0) & (th_end[off_zero] > 0)]:
                    upcrossings[i].append(_crossing(dense, 1 + i, 0.0, t_end))
            while next_sample < grid.size and grid[next_sample] <= t_end:
                samples[next_sample] = dense(grid[next_sample])
                next_sample += 1
            if np.any(np.abs(th_new) > overturn_angle):
                status |= STATUS_OVERTURNED
            if event is not None:
                y = dense(t_end)
                y[1 + event] = offset[event]
                direction = np.sign(y[n + 2 + event])
                if direction > 0 and offset[event] == 0.0:
                    upcrossings[event].append(t_end)
                y = _apply_impulse(sys, y, n, event, direction, rigid)
                t = t_end
                restarted = True
                break
        if not restarted:
            t = duration
    return samples, [np.asarray(c) for c in upcrossings], status


def _crossing(dense, k, level, t_end):
    """When component ``k`` of the dense output crosses ``level`` in (t_old, t_end)."""
    return brentq(lambda s: dense(s)[k] - level, dense.t_old, t_end, xtol=1e-14)


def _apply_impulse(sys, y, n, event, direction, rigid):
    """Jump of the velocities under an impulse M·direction on pendulum ``event``: the
    kick-linear part of eqs. (eqm1)–(eqm2), which is exact for a delta-function torque."""
    impulse = np.zeros((1, n))
    impulse[0, event] = direction * sys.drive[0, event]
    th, thd, phd = y[None, 1 : n + 1], y[None, n + 2 :], y[n + 1 : n + 2]
    with_kick = accelerations(sys, th, thd, phd, impulse)
    without = accelerations(sys, th, thd, phd, np.zeros((1, n)))
    y = y.copy()
    y[n + 1] += 0.0 if rigid else (with_kick[0] - without[0])[0]
    y[n + 2 :] += (with_kick[1] - without[1])[0]
    return y

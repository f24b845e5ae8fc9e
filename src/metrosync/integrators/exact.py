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

Dry friction on the disk (T = ``disk_dry_friction`` > 0) is event-driven too. The run
is in one of three modes, each with a smooth right-hand side: slipping forwards or
backwards (friction ∓T), or stuck (φ̇ ≡ 0, the friction being the `holding_torque`,
which keeps φ̈ = 0 exactly, so the pendulums move as on a rigid support). A slipping
disk's φ̇ = 0 and a stuck disk's |holding torque| = T are events, located like the
crossings: at rest the disk sticks if |holding torque| ≤ T, else slips the way the
other torques push it. An escapement impulse always jolts the disk (no finite
friction holds an impulse); it then slips the way it was jolted.

It is slow (Python-level stepping) and meant for checking the fixed-step scheme on
small ensembles and short horizons.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from ..equations import SystemArrays, accelerations, holding_torque
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
    rest_since: float = 0.0,
) -> Records:
    """Integrate every run to ``duration``, sampling on a grid of step ``grid_dt``;
    ``group_start`` bounds the groups of metronomes (default: one group). The records'
    ``rest_time`` is the time the disk was stuck from ``rest_since`` to the end."""
    runs, n = theta0.shape
    p = sys.coordinates
    grid = np.arange(n_records) * grid_dt
    shape = (runs, n_records)
    platform = shape if p == 1 else shape + (p,)  # as `_state.platform_records`
    phi_dot0 = np.asarray(phi_dot0, dtype=float)
    if phi_dot0.ndim == 1:
        phi_dot0 = np.broadcast_to(phi_dot0[:, None], (runs, p))
    bounds = [0, n] if group_start is None else [int(k) for k in group_start]
    groups = list(zip(bounds[:-1], bounds[1:], strict=True))
    out = Records(
        r=np.full(shape, np.nan),
        r_crossing=np.full(shape, np.nan),
        status=np.zeros(runs, dtype=np.int8),
        theta=np.full(shape + (n,), np.nan) if trajectories else None,
        theta_dot=np.full(shape + (n,), np.nan) if trajectories else None,
        phi=np.full(platform, np.nan) if trajectories else None,
        phi_dot=np.full(platform, np.nan) if trajectories else None,
        crossings=[],
        r_group=np.full(shape + (len(groups),), np.nan),
        r_crossing_group=np.full(shape + (len(groups),), np.nan),
        last_kick=np.full((runs, n), -1.0),
        rest_time=np.zeros(runs),
    )
    for b in range(runs):
        samples, upcrossings, status, out.last_kick[b], out.rest_time[b] = _integrate_run(
            sys.run(b),
            theta0[b],
            theta_dot0[b],
            phi_dot0[b],
            grid,
            duration,
            overturn_angle,
            rest_since,
        )
        out.status[b] = status
        out.crossings.append(upcrossings)
        th, thd = samples[:, p : n + p], samples[:, n + 2 * p :]
        phase = analytic_phase(th, thd, sys.omega[b])
        out.r[b] = order_parameter(phase)
        out.r_crossing[b] = crossing_order(upcrossings, grid)
        for g, (lo, hi) in enumerate(groups):
            out.r_group[b, :, g] = order_parameter(phase[:, lo:hi])
            out.r_crossing_group[b, :, g] = crossing_order(upcrossings[lo:hi], grid)
        if trajectories:
            out.theta[b], out.theta_dot[b] = th, thd
            phi, phi_dot = samples[:, :p], samples[:, n + p : n + 2 * p]
            out.phi[b], out.phi_dot[b] = (phi[:, 0], phi_dot[:, 0]) if p == 1 else (phi, phi_dot)
        if on_run_done is not None:
            on_run_done()
    return out


def _integrate_run(sys, theta0, theta_dot0, phi_dot0, grid, duration, overturn_angle, rest_since):
    """One run. Returns grid samples (T, 2N+2P) of [φ, θ, φ̇, θ̇], upward-crossing times
    per metronome, the status bits, each metronome's last impulse time (−1 if none) and
    the time the disk was stuck after ``rest_since``."""
    n = theta0.size
    p = sys.coordinates
    offset = sys.escapement_offset[0]
    off_zero = np.nonzero(offset != 0.0)[0]  # their zero crossings are not events
    zero_kick = np.zeros((1, n))
    rigid = bool(np.any(np.isinf(sys.total_inertia[0])))
    limit = 0.0 if rigid else float(sys.dry_friction[0])
    period = 2 * np.pi / sys.omega.max()

    def split(y):
        # One coordinate: φ̇ per run, (1,), as ever; more: (1, P).
        phi_dot = y[n + 1 : n + 2] if p == 1 else y[None, n + p : n + 2 * p]
        return y[None, p : n + p], y[None, n + 2 * p :], phi_dot

    def holding(t, y):
        return holding_torque(sys, *split(y), zero_kick, t)

    def friction(t, y, mode):
        """The dry friction of a mode: none, ∓T slipping, or the holding torque stuck."""
        if limit == 0.0:
            return np.zeros(1)
        return holding(t, y) if mode == 0 else np.array([-mode * limit])

    def rhs(t, y, mode):
        th, thd, phd = split(y)
        phdd, thdd = accelerations(sys, th, thd, phd, zero_kick, t, friction=friction(t, y, mode))
        return np.concatenate((y[n + p : n + 2 * p], y[n + 2 * p :], np.ravel(phdd), thdd[0]))

    still = np.zeros(p)
    y = np.concatenate((still, theta0, still if rigid else phi_dot0, theta_dot0))
    mode = _disk_mode(limit, y[n + p], holding(0.0, y))
    samples = np.full((grid.size, y.size), np.nan)
    samples[0] = y
    next_sample = 1
    upcrossings: list[list[float]] = [[] for _ in range(n)]
    last_kick = np.full(n, -1.0)
    rest = 0.0
    status = 0
    t = 0.0

    def stuck_for(start, end):  # the part of [start, end] after `rest_since`, if stuck
        return max(0.0, end - max(start, rest_since)) if mode == 0 else 0.0

    def result(bits):
        crossings = [np.asarray(c) for c in upcrossings]
        return samples, crossings, bits, last_kick, rest

    while t < duration:
        solver = DOP853(
            lambda s, u, m=mode: rhs(s, u, m),
            t,
            y,
            duration,
            rtol=RTOL,
            atol=ATOL,
            max_step=period / 8,
        )
        restarted = False
        while solver.status == "running":
            y_old = solver.y.copy()
            solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                return result(status | STATUS_DIVERGED)
            dense = solver.dense_output()
            events = _crossings(dense, y_old, solver.y, offset, n, p)
            if limit > 0.0:
                events += _disk_events(dense, mode, limit, n + p - 1, holding)
            t_end = solver.t
            event = None
            if events:
                t_end, event = min(events, key=lambda e: e[0])
            if off_zero.size:  # upward zero crossings that are not events
                th_old = y_old[p : n + p]
                th_end = solver.y[p : n + p] if event is None else dense(t_end)[p : n + p]
                for i in off_zero[(th_old[off_zero] < 0) & (th_end[off_zero] > 0)]:
                    upcrossings[i].append(_crossing(dense, p + i, 0.0, t_end))
            while next_sample < grid.size and grid[next_sample] <= t_end:
                samples[next_sample] = dense(grid[next_sample])
                next_sample += 1
            if np.any(np.abs(solver.y[p : n + p]) > overturn_angle):
                status |= STATUS_OVERTURNED
            if event is not None:
                rest += stuck_for(t, t_end)
                y = dense(t_end)
                if event == "break":  # |holding torque| reached T: slip against it
                    mode = -int(np.sign(holding(t_end, y)[0]))
                elif event == "stop":  # φ̇ reached 0: stick, or slip the other way
                    y[n + p] = 0.0
                    mode = _disk_mode(limit, 0.0, holding(t_end, y))
                else:
                    y[p + event] = offset[event]
                    direction = np.sign(y[n + 2 * p + event])
                    if direction > 0 and offset[event] == 0.0:
                        upcrossings[event].append(t_end)
                    y = _apply_impulse(sys, y, n, event, direction, rigid)
                    last_kick[event] = t_end
                    mode = _disk_mode(limit, y[n + p], holding(t_end, y))
                t = t_end
                restarted = True
                break
        if not restarted:
            rest += stuck_for(t, duration)
            t = duration
    return result(status)


def _crossings(dense, y_old, y_new, offset, n, p):
    """(time, pendulum) of each strict crossing of a pendulum's escapement angle in the step."""
    th_old, th_new = y_old[p : n + p] - offset, y_new[p : n + p] - offset
    return [
        (_crossing(dense, p + i, offset[i], dense.t), int(i))
        for i in np.nonzero(th_old * th_new < 0)[0]
    ]


def _crossing(dense, k, level, t_end):
    """When component ``k`` of the dense output crosses ``level`` in (t_old, t_end)."""
    return brentq(lambda s: dense(s)[k] - level, dense.t_old, t_end, xtol=1e-14)


def _disk_events(dense, mode, limit, n, holding):
    """A dry-friction event in the step, as [(time, "stop" or "break")], or []: a
    slipping disk's φ̇ reaching 0, a stuck disk's |holding torque| reaching T (φ̇ is
    component n + 1 of the state: one coordinate)."""
    if mode == 0:

        def margin(s):
            return limit - abs(holding(s, dense(s))[0])

        kind = "break"
    else:

        def margin(s):
            return mode * dense(s)[n + 1]

        kind = "stop"
    if margin(dense.t) > 0:
        return []
    if margin(dense.t_old) <= 0:  # the mode began at this event's edge: take it at the end
        return [(dense.t, kind)]
    return [(brentq(margin, dense.t_old, dense.t, xtol=1e-14), kind)]


def _disk_mode(limit, phi_dot, holding):
    """The disk's mode at a state: None without dry friction, the sign of φ̇ when it
    moves, 0 (stuck) at rest when |holding torque| ≤ T, else the way it starts to slip."""
    if limit == 0.0:
        return None
    if phi_dot != 0.0:
        return int(np.sign(phi_dot))
    return 0 if abs(holding[0]) <= limit else -int(np.sign(holding[0]))


def _apply_impulse(sys, y, n, event, direction, rigid):
    """Jump of the velocities under an impulse M·direction on pendulum ``event``: the
    kick-linear part of eqs. (eqm1)–(eqm2), which is exact for a delta-function torque."""
    p = sys.coordinates
    impulse = np.zeros((1, n))
    impulse[0, event] = direction * sys.drive[0, event]
    phd = y[n + 1 : n + 2] if p == 1 else y[None, n + p : n + 2 * p]
    th, thd = y[None, p : n + p], y[None, n + 2 * p :]
    # Dry friction is bounded, so it takes no part in an impulse.
    no_friction = np.zeros(1)
    with_kick = accelerations(sys, th, thd, phd, impulse, friction=no_friction)
    without = accelerations(sys, th, thd, phd, np.zeros((1, n)), friction=no_friction)
    y = y.copy()
    y[n + p : n + 2 * p] += 0.0 if rigid else np.ravel(with_kick[0] - without[0])
    y[n + 2 * p :] += (with_kick[1] - without[1])[0]
    return y

"""Plain NumPy implementation of the fixed-step scheme in `verlet` (same steps, same
records), vectorised over runs and metronomes.

It is the oracle the compiled kernel is tested against, and the baseline that the
benchmarks compare it with. Its forces come from `equations.accelerations`, the one
vectorised statement of eqs. (eqm1)–(eqm2).
"""

from __future__ import annotations

import numpy as np

from ..equations import (
    SystemArrays,
    accelerations,
    disk_torque,
    dry_friction,
    effective_inertia,
    escapement,
    holding_torque,
)
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._state import StepState


def advance_state(
    state: StepState,
    sys: SystemArrays,
    *,
    dt: float,
    step0: int,
    n_steps: int,
    record_every: int,
    overturn_angle: float,
) -> None:
    """Advance every run by ``n_steps`` steps from step ``step0``, in place."""
    n_rec = state.r.shape[1]
    rigid = np.isinf(sys.total_inertia)
    dry = (sys.dry_friction > 0) & ~rigid
    grid_dt = record_every * dt
    if step0 == 0:
        _record(state, 0, sys.omega, (state.status & STATUS_DIVERGED) == 0)
    with np.errstate(over="ignore", invalid="ignore"):
        _steps(state, sys, dt, step0, n_steps, record_every, overturn_angle, rigid, dry, grid_dt, n_rec)  # fmt: skip  # noqa: E501


def _steps(state, sys, dt, step0, n_steps, record_every, overturn_angle, rigid, dry, grid_dt, n_rec):  # fmt: skip  # noqa: E501
    for s in range(step0, step0 + n_steps):
        alive = (state.status & STATUS_DIVERGED) == 0
        if not alive.any():
            break
        t_old = s * dt
        th, acc = state.theta, state.acc_theta
        th_new = th + state.theta_dot * dt + 0.5 * acc * dt * dt
        vel_pred = state.theta_dot + acc * dt
        phd_pred = state.phi_dot + state.acc_phi * dt
        kick = np.where(alive[:, None], escapement(sys, th, th_new, dt), 0.0)
        state.last_kick[kick != 0.0] = (s + 1) * dt
        up = (th < 0) & (th_new > 0) & alive[:, None]  # the phase's crossings, at 0
        for b, i in zip(*np.nonzero(up), strict=True):
            t_cross = t_old + dt * th[b, i] / (th[b, i] - th_new[b, i])
            if state.last_up[b, i] >= 0:
                grp = np.searchsorted(state.group_start, i, side="right") - 1
                _add_crossing_phase(state, b, grp, state.last_up[b, i], t_cross, grid_dt, n_rec)
            state.last_up[b, i] = t_cross
        overturned = np.any(np.abs(th_new) > overturn_angle, axis=1) & alive
        state.status[overturned] |= STATUS_OVERTURNED
        t_new = (s + 1) * dt
        forces = (sys, th_new, vel_pred, phd_pred, kick, t_new)
        others = disk_torque(sys, phd_pred, kick, t_new)
        friction, held = _dry_friction(sys, dry, state.phi_dot, forces)
        phdd, thdd = accelerations(*forces, friction=friction)
        diverged = ~np.isfinite(phdd) & alive
        state.status[diverged] |= STATUS_DIVERGED
        ok = alive & ~diverged
        force = others + friction
        new_theta_dot = state.theta_dot + 0.5 * (acc + thdd) * dt
        new_p = state.p_phi + 0.5 * (state.force_phi + force) * dt
        stopping = dry & ~held & (friction * _disk_velocity(sys, new_p, th_new, new_theta_dot) >= 0)
        if stopping.any():  # rare: the disk's velocity reached 0 within the step
            end, stops = _friction_at_stop(sys, friction, new_p, th_new, new_theta_dot, dt)
            end = np.where(stopping, end, friction)
            stops &= stopping
            mean_phdd, mean_thdd = accelerations(*forces, friction=end)
            new_theta_dot = state.theta_dot + 0.5 * (acc + mean_thdd) * dt
            new_p = state.p_phi + 0.5 * (state.force_phi + others + end) * dt
            at_rest, _ = _dry_friction(sys, dry, np.zeros_like(state.phi_dot), forces)
            friction = np.where(stops, at_rest, end)
            phdd, thdd = accelerations(*forces, friction=friction)
            force = others + friction
            held |= stops
        coupling = sys.radius * np.sum(sys.mh * np.cos(th_new) * new_theta_dot, axis=1)
        new_p = np.where(held, coupling, new_p)  # a disk at rest: p_φ = R Σ m h cos θ θ̇
        state.rest_steps[held & ok] += 1
        with np.errstate(invalid="ignore"):
            new_phi_dot = np.where(rigid, 0.0, (new_p - coupling) / sys.total_inertia)
        ok2 = ok[:, None]
        phi_new = state.phi + state.phi_dot * dt + 0.5 * state.acc_phi * dt * dt
        state.phi[ok] = phi_new[ok]
        state.theta[...] = np.where(ok2, th_new, th)
        state.theta_dot[...] = np.where(ok2, new_theta_dot, state.theta_dot)
        state.acc_theta[...] = np.where(ok2, thdd, acc)
        state.p_phi[ok] = np.where(rigid, state.p_phi, new_p)[ok]
        state.phi_dot[ok] = new_phi_dot[ok]
        state.force_phi[ok] = force[ok]
        state.acc_phi[ok] = phdd[ok]
        if (s + 1) % record_every == 0:
            _record(state, (s + 1) // record_every, sys.omega, ok)


def _dry_friction(sys, dry, phi_dot, forces):
    """The disk's dry friction as a step starts resolving the disk, (B,), and where it
    holds the disk at rest (the twin of `_physics.disk_friction`); 0 where ``dry`` is off."""
    if not dry.any():
        return np.zeros_like(phi_dot), np.zeros(phi_dot.shape, dtype=bool)
    holding = holding_torque(*forces)
    friction = np.where(dry, dry_friction(sys, phi_dot, holding), 0.0)
    return friction, dry & (phi_dot == 0) & (np.abs(holding) <= sys.dry_friction)


def _disk_velocity(sys, p_phi, theta, theta_dot):
    coupling = sys.radius * np.sum(sys.mh * np.cos(theta) * theta_dot, axis=1)
    with np.errstate(invalid="ignore"):
        return (p_phi - coupling) / sys.total_inertia


def _friction_at_stop(sys, friction, p_phi, theta, theta_dot, dt):
    """The twin of `_physics.disk_friction_stop`: the friction's end value that brings the
    disk to rest, where it is within ±T (then True), else the reversed friction."""
    stop = friction - 2.0 * effective_inertia(sys, theta) * _disk_velocity(sys, p_phi, theta, theta_dot) / dt  # fmt: skip  # noqa: E501
    stops = np.abs(stop) <= sys.dry_friction
    return np.where(stops, stop, -friction), stops


def _add_crossing_phase(state, b, grp, t_prev, t_next, grid_dt, n_rec):
    g = np.arange(int(np.ceil(t_prev / grid_dt)), min(int(np.ceil(t_next / grid_dt)), n_rec))
    phase = 2 * np.pi * (g * grid_dt - t_prev) / (t_next - t_prev)
    state.cross_re[b, g, grp] += np.cos(phase)
    state.cross_im[b, g, grp] += np.sin(phase)
    state.cross_count[b, g, grp] += 1


def _record(state: StepState, k: int, omega: np.ndarray, which: np.ndarray) -> None:
    x = state.theta
    y = -state.theta_dot / omega
    rho = np.hypot(x, y)
    safe = np.where(rho > 0, rho, 1.0)
    unit = np.where(rho > 0, (x + 1j * y) / safe, 0.0)
    r = np.abs(unit.sum(axis=1)) / x.shape[1]
    state.r[which, k] = r[which]
    if state.group_start.size > 2:  # several groups
        bounds = state.group_start
        for g, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
            state.r_group[which, k, g] = (np.abs(unit[:, lo:hi].sum(axis=1)) / (hi - lo))[which]
    if state.traj_theta.shape[0]:
        state.traj_theta[which, k] = x[which]
        state.traj_theta_dot[which, k] = state.theta_dot[which]
        state.traj_phi[which, k] = state.phi[which]
        state.traj_phi_dot[which, k] = state.phi_dot[which]

"""Plain NumPy implementation of the kick-located scheme in `located` (same steps, same
records), vectorised over runs and metronomes.

It is the oracle the compiled ``located`` kernels are tested against. Its smooth
forces come from `equations.accelerations` and `equations.disk_torque`; the impulse
and its interpolated geometry are written out as the kernels compute them (see
`located` for the scheme).
"""

from __future__ import annotations

import numpy as np

from ..equations import SystemArrays, accelerations, disk_torque
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._state import StepState
from .located import kick_state
from .reference import _add_crossing_phase, _record


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
    kicks = kick_state(state, sys)
    if step0 == 0:
        _record(state, 0, sys.omega, (state.status & STATUS_DIVERGED) == 0)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for s in range(step0, step0 + n_steps):
            if not _step(state, kicks, sys, dt, s, overturn_angle, record_every):
                break


def _step(state, kicks, sys, dt, s, overturn_angle, record_every) -> bool:
    alive = (state.status & STATUS_DIVERGED) == 0
    if not alive.any():
        return False
    n_rec = state.r.shape[1]
    rigid = np.isinf(sys.total_inertia)
    inv = 1.0 / sys.inertia
    t_old, t_new = s * dt, (s + 1) * dt
    th, thd, acc = state.theta, state.theta_dot, state.acc_theta
    th_new = th + thd * dt + 0.5 * acc * (dt * dt)
    vel_pred = thd + acc * dt
    phd_pred = state.phi_dot + state.acc_phi * dt
    phi_new = state.phi + state.phi_dot * dt + 0.5 * state.acc_phi * (dt * dt)

    # The escapement, as `_physics.escapement`: ±M/dt when θ crosses 0; here only
    # its impulse (that torque times dt) is used, applied at the crossing instant.
    up = (th < 0) & (th_new > 0) & alive[:, None]
    down = (th > 0) & (th_new < 0) & alive[:, None]
    rate = sys.drive / dt
    impulse = np.where(up, rate, np.where(down, -rate, 0.0)) * dt
    kicked = impulse != 0.0
    sigma = np.where(kicked, crossing_time(th, thd, acc, th_new, dt), 0.0)
    overturned = np.any(np.abs(th_new) > overturn_angle, axis=1) & alive
    state.status[overturned] |= STATUS_OVERTURNED

    no_kick = np.zeros_like(th)
    phdd, thdd = accelerations(sys, th_new, vel_pred, phd_pred, no_kick, t_new)
    diverged = ~np.isfinite(phdd) & alive
    state.status[diverged] |= STATUS_DIVERGED
    ok = alive & ~diverged
    force = disk_torque(sys, phd_pred, no_kick, t_new)
    for b, i in zip(*np.nonzero(up & ok[:, None]), strict=True):
        t_cross = t_old + sigma[b, i]
        if state.last_up[b, i] >= 0:
            _add_crossing_phase(state, b, state.last_up[b, i], t_cross, record_every * dt, n_rec)
        state.last_up[b, i] = t_cross
    q_new = sys.mh * np.cos(th_new)
    den_new = np.sum(q_new * q_new * inv, axis=1)

    # The impulse of each crossing at its instant t_old + sigma: the kick-linear part
    # of eqs. (eqm1)-(eqm2) with the kicked pendulum at the escapement's angle (0) and
    # the others' geometry interpolated between the step's ends.
    frac = sigma / dt
    rest_jump = impulse * inv
    num_jump = -(sys.mh * 1.0) * rest_jump
    force_jump = np.zeros_like(th)
    for i in range(th.shape[1]):
        force_jump[:, i] = disk_torque(sys, 0.0, impulse[:, i : i + 1]) - disk_torque(
            sys, 0.0, no_kick[:, i : i + 1]
        )
    den_c = kicks.den[:, None] + frac * (den_new - kicks.den)[:, None]
    radius = sys.radius[:, None]
    with np.errstate(invalid="ignore"):
        disk_jump = (radius * num_jump + force_jump) / (
            sys.total_inertia[:, None] - radius * radius * den_c
        )
    disk_jump = np.where(kicked, np.where(rigid[:, None], 0.0, disk_jump), 0.0)
    rest_after = np.where(kicked, dt - sigma, 0.0)
    # What the jump changes in the velocity-dependent forces (friction, θ̇² sin θ) over
    # the rest of the step: the kicked pendulum's and the disk's, at the step's end.
    own_jump = rest_jump - radius * inv * q_new * disk_jump
    j_phi = np.zeros(th.shape[0])  # the jump in the accelerations and the disk torque ...
    j_theta = np.zeros_like(th)
    j_force = np.zeros(th.shape[0])
    j_theta_rest = np.zeros_like(th)  # ... and its integral over the rest of the step
    for i in np.nonzero(kicked.any(axis=0))[0]:
        vel = vel_pred.copy()
        vel[:, i] += own_jump[:, i]
        phdd_k, thdd_k = accelerations(sys, th_new, vel, phd_pred + disk_jump[:, i], no_kick, t_new)
        kicked_i = kicked[:, i]
        j_phi += np.where(kicked_i, phdd_k - phdd, 0.0)
        j_theta += np.where(kicked_i[:, None], thdd_k - thdd, 0.0)
        j_theta_rest += rest_after[:, i, None] * np.where(kicked_i[:, None], thdd_k - thdd, 0.0)
        force_k = disk_torque(sys, phd_pred + disk_jump[:, i], no_kick, t_new)
        j_force += np.where(kicked_i, force_k - force, 0.0)
        force_jump[:, i] += np.where(kicked_i, rest_after[:, i] * (force_k - force), 0.0)
    early = np.sum((1.0 - frac) * disk_jump, axis=1)
    late = np.sum(disk_jump, axis=1) - early
    shift = np.sum(rest_after * disk_jump, axis=1)
    momentum_jump = np.sum(force_jump, axis=1)

    # Finish the step: the velocity jumps (direct, and through the disk at the crossing's
    # geometry), their effect on the forces over the rest of the step, and the distance
    # they travel in it.
    coupling = radius * inv
    new_theta_dot = (
        thd + rest_jump + 0.5 * (acc + thdd) * dt + j_theta_rest
        - coupling * q_new * late[:, None] - coupling * kicks.q * early[:, None]
    )  # fmt: skip
    new_theta = th_new + rest_after * rest_jump - coupling * q_new * shift[:, None]
    sum_p = sys.radius * np.sum(q_new * new_theta_dot, axis=1)
    new_p = state.p_phi + 0.5 * (state.force_phi + force) * dt + momentum_jump
    with np.errstate(invalid="ignore"):
        new_phi_dot = np.where(rigid, 0.0, (new_p - sum_p) / sys.total_inertia)

    ok2 = ok[:, None]
    state.phi[ok] = (phi_new + shift)[ok]
    state.theta[...] = np.where(ok2, new_theta, th)
    state.theta_dot[...] = np.where(ok2, new_theta_dot, thd)
    state.acc_theta[...] = np.where(ok2, thdd + j_theta, acc)
    state.p_phi[ok] = np.where(rigid, state.p_phi, new_p)[ok]
    state.phi_dot[ok] = new_phi_dot[ok]
    state.force_phi[ok] = (force + j_force)[ok]
    state.acc_phi[ok] = (phdd + j_phi)[ok]
    kicks.q[...] = np.where(ok2, q_new, kicks.q)
    kicks.den[ok] = den_new[ok]
    if (s + 1) % record_every == 0:
        _record(state, (s + 1) // record_every, sys.omega, ok)
    return True


def crossing_time(th, thd, acc, th_new, dt):
    """Time from the step's start at which θ crosses 0, (B, N): linear interpolation
    between the step's ends."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return dt * th / (th - th_new)

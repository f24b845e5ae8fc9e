"""Plain NumPy implementation of the kick-located scheme in `located` (same steps, same
records), vectorised over runs and metronomes.

It is the oracle the compiled ``located`` kernels are tested against: the same
arithmetic in plain loops and whole-array expressions, so that a kernel's indexing,
memory layout or parallel writes cannot go wrong unnoticed. Its smooth forces come
from `equations.accelerations` and `equations.disk_torque`; each impulse's pieces
from the compiled scalar `_located_parts.kick` and `_physics.disk_acceleration`,
called once per impulse (the physics of an impulse is checked against ``exact``
instead, tests/integrators/test_located.py).
"""

from __future__ import annotations

import numpy as np

from ..capabilities import require
from ..equations import SystemArrays, accelerations, disk_torque, escapement
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._abi import constants_of
from ._located_parts import kick
from ._physics import disk_acceleration
from ._state import StepState
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
    require("located/numpy", sys)
    c = constants_of(sys, dt)
    if step0 == 0:
        _record(state, 0, sys.omega, (state.status & STATUS_DIVERGED) == 0)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for s in range(step0, step0 + n_steps):
            if not _step(state, sys, c, dt, s, overturn_angle, record_every):
                break


def _step(state, sys, c, dt, s, overturn_angle, record_every) -> bool:
    alive = (state.status & STATUS_DIVERGED) == 0
    if not alive.any():
        return False
    n_rec = state.r.shape[1]
    rigid = np.isinf(sys.total_inertia)
    inv = 1.0 / sys.inertia
    half = 0.5 * dt
    t_old, t_new = s * dt, (s + 1) * dt
    th, thd, acc = state.theta, state.theta_dot, state.acc_theta
    th_new = th + thd * dt + 0.5 * acc * (dt * dt)
    vel_pred = thd + acc * dt
    phd_pred = state.phi_dot + state.acc_phi * dt
    phi_new = state.phi + state.phi_dot * dt + 0.5 * state.acc_phi * (dt * dt)
    # The escapement: ±M/dt where θ crosses its angle in the step; the scheme applies
    # that torque times dt as an impulse.
    fire = escapement(sys, th, th_new, dt)
    overturned = np.any(np.abs(th_new) > overturn_angle, axis=1) & alive
    state.status[overturned] |= STATUS_OVERTURNED

    no_kick = np.zeros_like(th)
    phdd, thdd = accelerations(sys, th_new, vel_pred, phd_pred, no_kick, t_new)
    diverged = ~np.isfinite(phdd) & alive
    state.status[diverged] |= STATUS_DIVERGED
    ok = alive & ~diverged
    force = disk_torque(sys, phd_pred, no_kick, t_new)
    q_new = sys.mh * np.cos(th_new)
    den_new = np.sum(q_new * q_new * inv, axis=1)

    # Each impulse at its instant: `_located_parts.kick` gives its pieces, summed here
    # as the kernels sum them; the disk's jumps follow from the sums.
    kicked = (fire != 0.0) & ok[:, None]
    state.last_kick[kicked] = t_new
    offset = sys.escapement_offset
    frac = np.where(kicked, (th - offset) / (th - th_new), 0.0)
    sigma = frac * dt
    after = np.where(kicked, dt - sigma, 0.0)
    # The phase's upward zero crossings (the upward kicks when the escapement acts at 0).
    up = (th < 0) & (th_new > 0) & ok[:, None]
    for b, i in zip(*np.nonzero(up), strict=True):
        t_cross = t_old + th[b, i] / (th[b, i] - th_new[b, i]) * dt
        if state.last_up[b, i] >= 0:
            grp = np.searchsorted(state.group_start, i, side="right") - 1
            _add_crossing_phase(state, b, grp, state.last_up[b, i], t_cross, record_every * dt, n_rec)  # fmt: skip  # noqa: E501
        state.last_up[b, i] = t_cross
    own = np.zeros_like(th)  # the pendulum's own jump, and its forces' change
    own_change = np.zeros_like(th)
    sums = np.zeros((th.shape[0], 5))
    for b, i in zip(*np.nonzero(kicked), strict=True):
        dv, dnum, dforce, jrest, jnum = kick(c, (b, i), b, fire[b, i] * dt, thd[b, i])
        own[b, i] = dv
        own_change[b, i] = jrest
        a = after[b, i]
        sums[b] += [dnum + (a - half) * jnum, dforce, a * dnum, a * dforce, jnum]
    jump, shift, change = (np.zeros(th.shape[0]) for _ in range(3))
    for b in np.nonzero(kicked.any(axis=1))[0]:
        den = den_new[b]
        jump[b] = disk_acceleration(c, b, sums[b, 0], den, sums[b, 1])
        shift[b] = disk_acceleration(c, b, sums[b, 2], den, sums[b, 3])
        change[b] = disk_acceleration(c, b, sums[b, 4], den, 0.0)
    momentum_jump = sums[:, 1]

    # Finish the step. Every pendulum's jump through the disk, −R q Δφ̇/I (eq. (eqm2)
    # for an impulse), with q at the step's end.
    through_disk = sys.radius[:, None] * inv
    acc_new = thdd + own_change - through_disk * q_new * change[:, None]
    new_theta_dot = (
        thd + own + (after - half) * own_change + 0.5 * (acc + acc_new) * dt
        - through_disk * q_new * jump[:, None]
    )  # fmt: skip
    new_theta = th_new + after * own - through_disk * q_new * shift[:, None]
    sum_p = sys.radius * np.sum(q_new * new_theta_dot, axis=1)
    new_p = state.p_phi + 0.5 * (state.force_phi + force) * dt + momentum_jump
    with np.errstate(invalid="ignore"):
        new_phi_dot = np.where(rigid, 0.0, (new_p - sum_p) / sys.total_inertia)

    ok2 = ok[:, None]
    state.phi[ok] = (phi_new + shift)[ok]
    state.theta[...] = np.where(ok2, new_theta, th)
    state.theta_dot[...] = np.where(ok2, new_theta_dot, thd)
    state.acc_theta[...] = np.where(ok2, acc_new, acc)
    state.p_phi[ok] = np.where(rigid, state.p_phi, new_p)[ok]
    state.phi_dot[ok] = new_phi_dot[ok]
    state.force_phi[ok] = force[ok]
    state.acc_phi[ok] = (phdd + change)[ok]
    if (s + 1) % record_every == 0:
        _record(state, (s + 1) // record_every, sys.omega, ok)
    return True

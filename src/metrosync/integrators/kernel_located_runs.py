"""The ``located`` scheme with the runs innermost: for small N.

The memory order and passes of `kernel_runs` (read it first): runs in blocks of
`LANES`, every arithmetic line of a step acting on a block's lanes at once. A step
without kick torque in the forces; the escapements that fire are counted per lane
in the first pass, each impulse is handled in a scalar pass over the lanes that have
one (`_located_parts.kick`), and when a block has any, its second pass adds what
they give every pendulum through the disk, per lane.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import drift, momentum, upward_crossing, velocity
from ._located_parts import crossing_fraction, kick
from ._physics import (
    applied_torque,
    disk_acceleration,
    disk_torque,
    disk_velocity,
    escapement,
    forced,
    pendulum_terms,
    theta_ddot,
)
from .kernel_oscillators import FASTMATH
from .kernel_runs import LANES, _record, arrange, load_block, store_block  # noqa: F401  (same memory order)
from .trig import REDUCTION_LIMIT, libm_sincos, sincos


# Reassociated and contracted like `kernel_oscillators` (within 1e-10 of the NumPy twin,
# as tested): without it the scalar impulse pass costs 0.80 of verlet's rate at (100, 7).
@nb.njit(parallel=True, cache=True, fastmath=FASTMATH)
def advance(st, c, settings, rec):
    """Same contract as `kernel_located_oscillators.advance`; ``c`` comes from `arrange`."""
    # Unpacked before the parallel loop: numba may lose writes through a tuple field there.
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status, last_kick, rest_steps = st  # fmt: skip  # noqa: E501
    r, cross_re, cross_im, cross_count, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot, r_group, group_start = rec  # fmt: skip  # noqa: E501
    dt, step0, n_steps, record_every, overturn_angle = settings
    n_runs, n = theta.shape
    n_blocks = (n_runs + LANES - 1) // LANES
    n_rec = r.shape[1]
    save = traj_theta.shape[0] > 0
    dt2 = dt * dt
    half = 0.5 * dt
    grid_dt = record_every * dt
    for blk in nb.prange(n_blocks):
        b0 = blk * LANES
        lanes = min(LANES, n_runs - b0)
        th, thd, acc, ph, phd, aph, pp, fph, alive = load_block(theta, theta_dot, acc_theta, phi, phi_dot, acc_phi, p_phi, force_phi, status, b0, lanes)  # fmt: skip  # noqa: E501
        tn_s = np.empty((n, LANES))
        rest = np.empty((n, LANES))
        q = np.empty((n, LANES))
        fired = np.empty((n, LANES))
        ph_new = np.empty(LANES)
        phd_pred = np.empty(LANES)
        s_num = np.empty(LANES)
        s_den = np.empty(LANES)
        s_p = np.empty(LANES)
        phdd = np.empty(LANES)
        force = np.empty(LANES)
        tau = np.zeros(LANES)  # applied torque, computed only for a forced block
        block_forced = False
        # With an escapement off the vertical, the phase's upward zero crossings are no
        # longer the upward kicks: the block then scans for them apart.
        block_shifted = False
        for w in range(LANES):
            block_forced |= forced(c, (blk, w))
            for i in range(n):
                block_shifted |= c.escapement_offset[blk, i, w] != 0.0
        jump = np.zeros(LANES)  # per lane, as in `kernel_located_oscillators`
        shift = np.zeros(LANES)
        jump_p = np.zeros(LANES)
        kicks = np.empty(LANES, dtype=np.int64)  # per-lane counts: scan only lanes that need it
        overs = np.empty(LANES, dtype=np.int64)
        until_record = record_every - step0 % record_every
        if step0 == 0:
            for w in range(lanes):
                if alive[w] > 0.0:
                    _record(b0 + w, blk, w, 0, th, thd, ph, phd, c, r, save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot, r_group, group_start)  # fmt: skip  # noqa: E501
        for s in range(step0, step0 + n_steps):
            n_far = _first_pass(c, blk, th, thd, acc, dt, dt2, overturn_angle, tn_s, rest, q, fired, s_num, s_den, kicks, overs, sincos)  # fmt: skip  # noqa: E501
            if n_far > 0:  # rare: redo the pass with libm trig
                _first_pass(c, blk, th, thd, acc, dt, dt2, overturn_angle, tn_s, rest, q, fired, s_num, s_den, kicks, overs, libm_sincos)  # fmt: skip  # noqa: E501
            t_new = (s + 1) * dt
            if block_forced:  # a sine per lane: kept out of the vectorized loop below
                for w in range(LANES):
                    tau[w] = applied_torque(c, (blk, w), t_new)
            for w in range(LANES):
                ph_new[w], phd_pred[w] = drift(ph[w], phd[w], aph[w], dt, dt2)
                force[w] = disk_torque(c, (blk, w), phd_pred[w], 0.0) + tau[w]
                phdd[w] = disk_acceleration(c, (blk, w), s_num[w], s_den[w], force[w])
                s_p[w] = 0.0
            any_kick = False
            t_old = s * dt
            for w in range(lanes):
                if alive[w] == 0.0:
                    continue
                if overs[w] > 0:
                    status[b0 + w] |= STATUS_OVERTURNED
                if not math.isfinite(phdd[w]):
                    status[b0 + w] |= STATUS_DIVERGED
                    alive[w] = 0.0
                    continue
                if block_shifted:
                    for i in range(n):
                        if th[i, w] < 0.0 < tn_s[i, w]:
                            t_cross = t_old + th[i, w] / (th[i, w] - tn_s[i, w]) * dt
                            upward_crossing(last_up, cross_re, cross_im, cross_count, b0 + w, i, t_cross, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
                if kicks[w] == 0:
                    continue
                any_kick = True
                num_jump = 0.0  # as in `kernel_located_oscillators`
                force_jump = 0.0
                num_shift = 0.0
                force_shift = 0.0
                num_change = 0.0
                for i in range(n):
                    if fired[i, w] == 0.0:
                        continue
                    last_kick[b0 + w, i] = t_new
                    frac = crossing_fraction(c, (blk, i, w), th[i, w], tn_s[i, w])
                    sigma = frac * dt
                    after = dt - sigma
                    if fired[i, w] > 0.0 and not block_shifted:  # the kick is the crossing
                        upward_crossing(last_up, cross_re, cross_im, cross_count, b0 + w, i, t_old + sigma, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
                    dv, dnum, dforce, jrest, jnum = kick(c, (blk, i, w), (blk, w), fired[i, w] * dt, thd[i, w])  # fmt: skip  # noqa: E501
                    thd[i, w] += dv + (after - half) * jrest
                    tn_s[i, w] += after * dv
                    rest[i, w] += jrest
                    num_jump += dnum + (after - half) * jnum
                    force_jump += dforce
                    num_shift += after * dnum
                    force_shift += after * dforce
                    num_change += jnum
                    jump_p[w] += dforce
                    kicks[w] -= 1
                    if kicks[w] == 0:
                        break
                jump[w] = disk_acceleration(c, (blk, w), num_jump, s_den[w], force_jump)
                shift[w] = disk_acceleration(c, (blk, w), num_shift, s_den[w], force_shift)
                phdd[w] += disk_acceleration(c, (blk, w), num_change, s_den[w], 0.0)
            if any_kick:
                for i in range(n):
                    for w in range(LANES):  # vectorized across runs
                        keep = alive[w] > 0.0
                        m = (blk, i, w)
                        thdd = theta_ddot(c, m, (blk, w), rest[i, w], q[i, w], phdd[w])
                        v = velocity(thd[i, w], acc[i, w], thdd, dt)
                        v += theta_ddot(c, m, (blk, w), 0.0, q[i, w], jump[w])
                        moved = tn_s[i, w] + theta_ddot(c, m, (blk, w), 0.0, q[i, w], shift[w])
                        thd[i, w] = v if keep else thd[i, w]
                        th[i, w] = moved if keep else th[i, w]
                        acc[i, w] = thdd if keep else acc[i, w]
                        s_p[w] += q[i, w] * v
            else:
                for i in range(n):
                    for w in range(LANES):  # vectorized across runs
                        keep = alive[w] > 0.0
                        thdd = theta_ddot(c, (blk, i, w), (blk, w), rest[i, w], q[i, w], phdd[w])
                        v = velocity(thd[i, w], acc[i, w], thdd, dt)
                        thd[i, w] = v if keep else thd[i, w]
                        th[i, w] = tn_s[i, w] if keep else th[i, w]
                        acc[i, w] = thdd if keep else acc[i, w]
                        s_p[w] += q[i, w] * v
            for w in range(LANES):
                if alive[w] > 0.0:
                    pinned = math.isinf(c.total_inertia[blk, w])
                    ph[w] = ph_new[w] + shift[w]
                    pp[w] = momentum(pp[w], fph[w], force[w], dt, pinned)
                    pp[w] += 0.0 if pinned else jump_p[w]
                    phd[w] = disk_velocity(c, (blk, w), pp[w], s_p[w])
                    fph[w] = force[w]
                    aph[w] = phdd[w]
                jump[w] = 0.0
                shift[w] = 0.0
                jump_p[w] = 0.0
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                for w in range(lanes):
                    if alive[w] > 0.0:
                        _record(b0 + w, blk, w, k, th, thd, ph, phd, c, r, save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot, r_group, group_start)  # fmt: skip  # noqa: E501
        store_block(theta, theta_dot, acc_theta, phi, phi_dot, acc_phi, p_phi, force_phi, b0, lanes, th, thd, acc, ph, phd, aph, pp, fph)  # fmt: skip  # noqa: E501


@nb.njit(cache=True, inline="always")
def _first_pass(c, blk, th, thd, acc, dt, dt2, overturn_angle, tn_s, rest, q, fired, s_num, s_den, kicks, overs, trig):  # fmt: skip  # noqa: E501
    """New angles, escapement torques (0 where none fires) and the per-lane sums of
    eqs. (eqm1)–(eqm2) without kick torque for block ``blk``, with ``trig`` = `sincos`
    or libm's. Fills the per-lane counts of escapements that fire and of overturns;
    returns the number of far-wound angles."""
    n_far = 0
    for w in range(th.shape[1]):
        kicks[w] = 0
        overs[w] = 0
        s_num[w] = 0.0
        s_den[w] = 0.0
    for i in range(th.shape[0]):
        for w in range(th.shape[1]):  # vectorized across runs
            t0 = th[i, w]
            tn, vp = drift(t0, thd[i, w], acc[i, w], dt, dt2)
            fire = escapement(c, (blk, i, w), t0, tn)
            kicks[w] += 1 if fire != 0.0 else 0
            fired[i, w] = fire
            overs[w] += 1 if abs(tn) > overturn_angle else 0
            n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
            sn, cs = trig(tn)
            res, qi, num, den = pendulum_terms(c, (blk, i, w), 0.0, sn, cs, vp)
            s_num[w] += num
            s_den[w] += den
            tn_s[i, w] = tn
            rest[i, w] = res
            q[i, w] = qi
    return n_far

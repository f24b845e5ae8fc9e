"""Fixed-step kernel with the runs innermost: for small N.

With N = 2…10 a loop over the metronomes is too short to fill a vector register, so
runs are grouped in blocks of `LANES` and each vector lane holds one run: the state
is transposed to (block, N, LANES) and every arithmetic line of a step acts on a
whole block at once. Sums over metronomes are per lane, so they are not reassociated
and each run gets exactly the arithmetic of a scalar loop. Blocks are spread over
threads. Rare events (crossings, overturns, far-wound angles) are detected by
per-block reductions and handled in a scalar pass.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import analytic_order, upward_crossing
from .trig import REDUCTION_LIMIT, sincos

#: Runs per block: 8 doubles fill an AVX-512 register (two AVX2 registers).
LANES = 32


@nb.njit(parallel=True, cache=True)
def advance(
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status,
    mh, mgh, inertia, c_theta, drive, omega, radius, c_phi, total_inertia,
    dt, step0, n_steps, record_every, overturn_angle,
    r, cross_re, cross_im, cross_count,
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot,
):  # fmt: skip
    """Same contract as the other kernels; arrays use the usual (B, N) layout and are
    transposed into blocks here, once per call."""
    n_runs, n = theta.shape
    n_blocks = (n_runs + LANES - 1) // LANES
    n_rec = r.shape[1]
    save = traj_theta.shape[0] > 0
    dt2 = dt * dt
    grid_dt = record_every * dt
    for blk in nb.prange(n_blocks):
        b0 = blk * LANES
        lanes = min(LANES, n_runs - b0)
        # Block-local copies; missing lanes repeat the last run and are never written back.
        th = np.empty((n, LANES))
        thd = np.empty((n, LANES))
        acc = np.empty((n, LANES))
        c_mh = np.empty((n, LANES))
        c_mgh = np.empty((n, LANES))
        c_inv = np.empty((n, LANES))
        c_cth = np.empty((n, LANES))
        c_kick = np.empty((n, LANES))
        for i in range(n):
            for w in range(LANES):
                b = b0 + min(w, lanes - 1)
                th[i, w] = theta[b, i]
                thd[i, w] = theta_dot[b, i]
                acc[i, w] = acc_theta[b, i]
                c_mh[i, w] = mh[b, i]
                c_mgh[i, w] = mgh[b, i]
                c_inv[i, w] = 1.0 / inertia[b, i]
                c_cth[i, w] = c_theta[b, i]
                c_kick[i, w] = drive[b, i] / dt
        ph = np.empty(LANES)
        phd = np.empty(LANES)
        aph = np.empty(LANES)
        pp = np.empty(LANES)
        fph = np.empty(LANES)
        rad = np.empty(LANES)
        cph = np.empty(LANES)
        jt = np.empty(LANES)
        alive = np.empty(LANES)
        for w in range(LANES):
            b = b0 + min(w, lanes - 1)
            ph[w] = phi[b]
            phd[w] = phi_dot[b]
            aph[w] = acc_phi[b]
            pp[w] = p_phi[b]
            fph[w] = force_phi[b]
            rad[w] = radius[b]
            cph[w] = c_phi[b]
            jt[w] = total_inertia[b]
            alive[w] = 0.0 if status[b] & STATUS_DIVERGED else 1.0
        tn_s = np.empty((n, LANES))
        rest = np.empty((n, LANES))
        q = np.empty((n, LANES))
        phd_pred = np.empty(LANES)
        s_num = np.empty(LANES)
        s_den = np.empty(LANES)
        s_kick = np.empty(LANES)
        s_p = np.empty(LANES)
        phdd = np.empty(LANES)
        force = np.empty(LANES)
        ups = np.empty(LANES, dtype=np.int64)  # per-lane counts: scan only lanes that need it
        overs = np.empty(LANES, dtype=np.int64)
        until_record = record_every - step0 % record_every
        if step0 == 0:
            for w in range(lanes):
                if alive[w] > 0.0:
                    _record(b0 + w, w, 0, th, thd, ph, phd, omega, r, save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501
        for s in range(step0, step0 + n_steps):
            n_far = 0
            for w in range(LANES):
                ups[w] = 0
                overs[w] = 0
                phd_pred[w] = phd[w] + aph[w] * dt
                s_num[w] = 0.0
                s_den[w] = 0.0
                s_kick[w] = 0.0
            for i in range(n):
                for w in range(LANES):  # vectorized across runs
                    t0 = th[i, w]
                    a = acc[i, w]
                    tn = t0 + thd[i, w] * dt + 0.5 * a * dt2
                    vp = thd[i, w] + a * dt
                    up = (t0 < 0.0) & (tn > 0.0)
                    down = (t0 > 0.0) & (tn < 0.0)
                    kick = c_kick[i, w] if up else (-c_kick[i, w] if down else 0.0)
                    ups[w] += 1 if up else 0
                    overs[w] += 1 if abs(tn) > overturn_angle else 0
                    n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
                    sn, cs = sincos(tn)
                    res = (kick - c_mgh[i, w] * sn - c_cth[i, w] * vp) * c_inv[i, w]
                    qi = c_mh[i, w] * cs
                    s_num[w] += c_mh[i, w] * vp * vp * sn - qi * res
                    s_den[w] += qi * qi * c_inv[i, w]
                    s_kick[w] += kick
                    tn_s[i, w] = tn
                    rest[i, w] = res
                    q[i, w] = qi
            if n_far > 0:  # rare: redo the sums with libm trig
                _libm_pass(n, th, thd, acc, tn_s, c_mh, c_mgh, c_cth, c_inv, c_kick, dt, rest, q, s_num, s_den)  # fmt: skip  # noqa: E501
            t_old = s * dt
            for w in range(lanes):
                if ups[w] > 0 or overs[w] > 0:
                    if alive[w] == 0.0:
                        continue
                    if overs[w] > 0:
                        status[b0 + w] |= STATUS_OVERTURNED
                    for i in range(n):
                        if ups[w] == 0:
                            break
                        t0 = th[i, w]
                        tn = tn_s[i, w]
                        if t0 < 0.0 and tn > 0.0:
                            t_cross = t_old + dt * t0 / (t0 - tn)
                            upward_crossing(last_up, cross_re, cross_im, cross_count, b0 + w, i, t_cross, grid_dt, n_rec)  # fmt: skip  # noqa: E501
                            ups[w] -= 1
            for w in range(LANES):
                force[w] = -cph[w] * phd_pred[w] - s_kick[w]
                phdd[w] = (rad[w] * s_num[w] + force[w]) / (jt[w] - rad[w] * rad[w] * s_den[w])
                s_p[w] = 0.0
            for w in range(lanes):
                if alive[w] > 0.0 and not math.isfinite(phdd[w]):
                    status[b0 + w] |= STATUS_DIVERGED
                    alive[w] = 0.0
            for i in range(n):
                for w in range(LANES):  # vectorized across runs
                    keep = alive[w] > 0.0
                    thdd = rest[i, w] - rad[w] * q[i, w] * c_inv[i, w] * phdd[w]
                    v = thd[i, w] + 0.5 * (acc[i, w] + thdd) * dt
                    thd[i, w] = v if keep else thd[i, w]
                    th[i, w] = tn_s[i, w] if keep else th[i, w]
                    acc[i, w] = thdd if keep else acc[i, w]
                    s_p[w] += q[i, w] * v
            for w in range(LANES):
                if alive[w] > 0.0:
                    ph[w] += phd[w] * dt + 0.5 * aph[w] * dt2
                    if math.isinf(jt[w]):
                        phd[w] = 0.0
                    else:
                        pp[w] += 0.5 * (fph[w] + force[w]) * dt
                        phd[w] = (pp[w] - rad[w] * s_p[w]) / jt[w]
                    fph[w] = force[w]
                    aph[w] = phdd[w]
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                for w in range(lanes):
                    if alive[w] > 0.0:
                        _record(b0 + w, w, k, th, thd, ph, phd, omega, r, save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501
        for w in range(lanes):
            b = b0 + w
            for i in range(n):
                theta[b, i] = th[i, w]
                theta_dot[b, i] = thd[i, w]
                acc_theta[b, i] = acc[i, w]
            phi[b] = ph[w]
            phi_dot[b] = phd[w]
            acc_phi[b] = aph[w]
            p_phi[b] = pp[w]
            force_phi[b] = fph[w]


@nb.njit(cache=True)
def _libm_pass(n, th, thd, acc, tn_s, c_mh, c_mgh, c_cth, c_inv, c_kick, dt, rest, q, s_num, s_den):  # fmt: skip  # noqa: E501
    """Redo the first pass's trig and sums with libm, for far-wound angles."""
    for w in range(th.shape[1]):
        s_num[w] = 0.0
        s_den[w] = 0.0
    for i in range(n):
        for w in range(th.shape[1]):
            t0 = th[i, w]
            tn = tn_s[i, w]
            vp = thd[i, w] + acc[i, w] * dt
            kick = c_kick[i, w] if (t0 < 0.0 and tn > 0.0) else (-c_kick[i, w] if (t0 > 0.0 and tn < 0.0) else 0.0)  # fmt: skip  # noqa: E501
            sn = math.sin(tn)
            cs = math.cos(tn)
            res = (kick - c_mgh[i, w] * sn - c_cth[i, w] * vp) * c_inv[i, w]
            qi = c_mh[i, w] * cs
            s_num[w] += c_mh[i, w] * vp * vp * sn - qi * res
            s_den[w] += qi * qi * c_inv[i, w]
            rest[i, w] = res
            q[i, w] = qi


@nb.njit(cache=True, inline="always")
def _record(b, w, k, th, thd, ph, phd, omega, r, save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot):  # fmt: skip  # noqa: E501
    r[b, k] = analytic_order(th[:, w], thd[:, w], omega[b])
    if save:
        for i in range(th.shape[0]):
            traj_theta[b, k, i] = th[i, w]
            traj_theta_dot[b, k, i] = thd[i, w]
        traj_phi[b, k] = ph[w]
        traj_phi_dot[b, k] = phd[w]

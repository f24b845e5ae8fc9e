"""Fixed-step kernel with the metronomes innermost: for large N.

Runs are spread over threads; within a run, each step is two passes over the N
metronomes that LLVM vectorizes: the first computes new angles, predicted velocities,
kicks (selects, not branches), the polynomial `sincos`, and the sums of eqs.
(eqm1)–(eqm2); the second applies φ̈ and updates velocities. Rare events (a zero
crossing to book, an overturn, an angle beyond the trig reduction's range) are
detected by cheap reductions in the first pass and handled in a scalar pass after
it. Reductions may be reassociated (``fastmath`` reassoc): the result differs from
the plain reference by rounding only, and is the same for any thread count.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import analytic_order, save_state, upward_crossing
from .trig import REDUCTION_LIMIT, sincos

FASTMATH = {"reassoc", "contract"}


@nb.njit(parallel=True, cache=True, fastmath=FASTMATH)
def advance(
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status,
    mh, mgh, inertia, c_theta, drive, omega, radius, c_phi, total_inertia,
    dt, step0, n_steps, record_every, overturn_angle,
    r, cross_re, cross_im, cross_count,
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot,
):  # fmt: skip
    n_runs, n = theta.shape
    n_rec = r.shape[1]
    save = traj_theta.shape[0] > 0
    dt2 = dt * dt
    grid_dt = record_every * dt
    for b in nb.prange(n_runs):
        th_new = np.empty(n)
        rest = np.empty(n)
        q = np.empty(n)
        crossed = np.empty(n, dtype=np.bool_)
        inv_i = np.empty(n)
        kick_dt = np.empty(n)
        for i in range(n):
            inv_i[i] = 1.0 / inertia[b, i]
            kick_dt[i] = drive[b, i] / dt
        rigid = math.isinf(total_inertia[b])
        rad = radius[b]
        until_record = record_every - step0 % record_every
        if step0 == 0 and not status[b] & STATUS_DIVERGED:
            r[b, 0] = analytic_order(theta[b], theta_dot[b], omega[b])
            if save:
                save_state(b, 0, theta, theta_dot, phi, phi_dot, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501
        for s in range(step0, step0 + n_steps):
            if status[b] & STATUS_DIVERGED:
                break
            phd_pred = phi_dot[b] + acc_phi[b] * dt
            sum_num = 0.0
            sum_den = 0.0
            sum_kick = 0.0
            n_up = 0
            n_over = 0
            n_far = 0
            for i in range(n):  # vectorized pass
                th = theta[b, i]
                a = acc_theta[b, i]
                tn = th + theta_dot[b, i] * dt + 0.5 * a * dt2
                vp = theta_dot[b, i] + a * dt
                up = (th < 0.0) & (tn > 0.0)
                down = (th > 0.0) & (tn < 0.0)
                kick = kick_dt[i] if up else (-kick_dt[i] if down else 0.0)
                n_up += 1 if up else 0
                crossed[i] = up
                n_over += 1 if abs(tn) > overturn_angle else 0
                n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
                sn, cs = sincos(tn)
                res = (kick - mgh[b, i] * sn - c_theta[b, i] * vp) * inv_i[i]
                qi = mh[b, i] * cs
                sum_num += mh[b, i] * vp * vp * sn - qi * res
                sum_den += qi * qi * inv_i[i]
                sum_kick += kick
                th_new[i] = tn
                rest[i] = res
                q[i] = qi
            if n_far > 0:  # rare: far-wound angles, or inf (then φ̈ is NaN)
                sum_num, sum_den = _libm_pass(b, n, th_new, dt, kick_dt, theta, theta_dot, acc_theta, mh, mgh, c_theta, inv_i, rest, q)  # fmt: skip  # noqa: E501
            if n_over > 0:
                status[b] |= STATUS_OVERTURNED
            if n_up > 0:
                t_old = s * dt
                for i in range(n):  # stops at the last of the n_up crossings
                    if crossed[i]:
                        th = theta[b, i]
                        t_cross = t_old + dt * th / (th - th_new[i])
                        upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec)  # fmt: skip  # noqa: E501
                        n_up -= 1
                        if n_up == 0:
                            break
            force = -c_phi[b] * phd_pred - sum_kick
            phdd = (rad * sum_num + force) / (total_inertia[b] - rad * rad * sum_den)
            if not math.isfinite(phdd):
                status[b] |= STATUS_DIVERGED
                break
            phi[b] += phi_dot[b] * dt + 0.5 * acc_phi[b] * dt2
            sum_p = 0.0
            for i in range(n):  # vectorized pass
                thdd = rest[i] - rad * q[i] * inv_i[i] * phdd
                v = theta_dot[b, i] + 0.5 * (acc_theta[b, i] + thdd) * dt
                theta_dot[b, i] = v
                theta[b, i] = th_new[i]
                acc_theta[b, i] = thdd
                sum_p += q[i] * v
            if rigid:
                phi_dot[b] = 0.0
            else:
                p_phi[b] += 0.5 * (force_phi[b] + force) * dt
                phi_dot[b] = (p_phi[b] - rad * sum_p) / total_inertia[b]
            force_phi[b] = force
            acc_phi[b] = phdd
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                r[b, k] = analytic_order(theta[b], theta_dot[b], omega[b])
                if save:
                    save_state(b, k, theta, theta_dot, phi, phi_dot, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501


@nb.njit(cache=True)
def _libm_pass(b, n, th_new, dt, kick_dt, theta, theta_dot, acc_theta, mh, mgh, c_theta, inv_i, rest, q):  # fmt: skip  # noqa: E501
    """Redo the first pass with libm trig, for angles beyond the fast reduction."""
    sum_num = 0.0
    sum_den = 0.0
    for i in range(n):
        th = theta[b, i]
        tn = th_new[i]
        vp = theta_dot[b, i] + acc_theta[b, i] * dt
        kick = kick_dt[i] if (th < 0.0 and tn > 0.0) else (-kick_dt[i] if (th > 0.0 and tn < 0.0) else 0.0)  # fmt: skip  # noqa: E501
        sn = math.sin(tn)
        cs = math.cos(tn)
        res = (kick - mgh[b, i] * sn - c_theta[b, i] * vp) * inv_i[i]
        qi = mh[b, i] * cs
        sum_num += mh[b, i] * vp * vp * sn - qi * res
        sum_den += qi * qi * inv_i[i]
        rest[i] = res
        q[i] = qi
    return sum_num, sum_den

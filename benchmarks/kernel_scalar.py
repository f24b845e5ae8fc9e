"""The first compiled kernel, kept as the baseline `kernel.py` compares the package's
kernels with: one run per thread, the metronomes in a scalar loop with libm trig and
branches, all 32 arrays and settings as positional arguments.

It is frozen as it was (not a layout of the package, and not kept in step with the
model): `advance_state` has the package kernels' calling convention so that the
benchmark can time it the same way (it follows the package's record buffers, whose
crossing sums are per group, and books its crossings through the shared
`upward_crossing`). Compiled without numba's disk cache, so that a change in the
package's shared pieces can never load a stale copy.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from metrosync.integrators._kernel_parts import analytic_order, save_state, upward_crossing
from metrosync.status import STATUS_DIVERGED, STATUS_OVERTURNED


@nb.njit(parallel=True)
def advance(
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status,
    mh, mgh, inertia, c_theta, drive, omega, radius, c_phi, total_inertia,
    dt, step0, n_steps, record_every, overturn_angle,
    r, cross_re, cross_im, cross_count,
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot, group_start,
):  # fmt: skip
    """Advance every run from step ``step0`` by ``n_steps`` steps, in place."""
    n_runs, n = theta.shape
    n_rec = r.shape[1]
    save = traj_theta.shape[0] > 0
    dt2 = dt * dt
    grid_dt = record_every * dt
    for b in nb.prange(n_runs):
        th_new = np.empty(n)
        vel_pred = np.empty(n)
        rest = np.empty(n)
        coupling = np.empty(n)
        rigid = math.isinf(total_inertia[b])
        rad = radius[b]
        if step0 == 0:
            _record(b, 0, theta, theta_dot, phi, phi_dot, omega, r, save,
                    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip
        for s in range(step0, step0 + n_steps):
            if status[b] & STATUS_DIVERGED:
                break
            t_old = s * dt
            phd_pred = phi_dot[b] + acc_phi[b] * dt
            phi_new = phi[b] + phi_dot[b] * dt + 0.5 * acc_phi[b] * dt2
            sum_num = 0.0
            sum_den = 0.0
            sum_kick = 0.0
            for i in range(n):
                th = theta[b, i]
                a = acc_theta[b, i]
                tn = th + theta_dot[b, i] * dt + 0.5 * a * dt2
                vp = theta_dot[b, i] + a * dt
                kick = 0.0
                if th < 0.0 and tn > 0.0:
                    kick = drive[b, i] / dt
                    t_cross = t_old + dt * th / (th - tn)
                    upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
                elif th > 0.0 and tn < 0.0:
                    kick = -drive[b, i] / dt
                if abs(tn) > overturn_angle:
                    status[b] |= STATUS_OVERTURNED
                sn = math.sin(tn)
                cs = math.cos(tn)
                inv_i = 1.0 / inertia[b, i]
                res = (kick - mgh[b, i] * sn - c_theta[b, i] * vp) * inv_i
                q = mh[b, i] * cs
                sum_num += mh[b, i] * vp * vp * sn - q * res
                sum_den += q * q * inv_i
                sum_kick += kick
                th_new[i] = tn
                vel_pred[i] = vp
                rest[i] = res
                coupling[i] = q * inv_i
            force = -c_phi[b] * phd_pred - sum_kick
            phdd = (rad * sum_num + force) / (total_inertia[b] - rad * rad * sum_den)
            if not math.isfinite(phdd):
                status[b] |= STATUS_DIVERGED
                break
            phi[b] = phi_new
            sum_p = 0.0
            for i in range(n):
                thdd = rest[i] - rad * coupling[i] * phdd
                theta_dot[b, i] += 0.5 * (acc_theta[b, i] + thdd) * dt
                theta[b, i] = th_new[i]
                acc_theta[b, i] = thdd
                sum_p += mh[b, i] * math.cos(th_new[i]) * theta_dot[b, i]
            if rigid:
                phi_dot[b] = 0.0
            else:
                p_phi[b] += 0.5 * (force_phi[b] + force) * dt
                phi_dot[b] = (p_phi[b] - rad * sum_p) / total_inertia[b]
            force_phi[b] = force
            acc_phi[b] = phdd
            if (s + 1) % record_every == 0:
                _record(b, (s + 1) // record_every, theta, theta_dot, phi, phi_dot, omega, r,
                        save, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip


@nb.njit(inline="always")
def _record(b, k, theta, theta_dot, phi, phi_dot, omega, r, save,
            traj_theta, traj_theta_dot, traj_phi, traj_phi_dot):  # fmt: skip
    """Store r from the analytic phase and, if asked, the state."""
    r[b, k] = analytic_order(theta[b], theta_dot[b], omega[b])
    if save:
        save_state(b, k, theta, theta_dot, phi, phi_dot, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501


def advance_state(state, sys, *, dt, step0, n_steps, record_every, overturn_angle):
    """Advance a `StepState` in place, as the package's fixed-step backends do."""
    advance(
        state.theta, state.theta_dot, state.phi, state.phi_dot, state.acc_theta,
        state.acc_phi, state.p_phi, state.force_phi, state.last_up, state.status,
        sys.mh, sys.mgh, sys.inertia, sys.c_theta, sys.drive, sys.omega, sys.radius,
        sys.c_phi, sys.total_inertia,
        float(dt), int(step0), int(n_steps), int(record_every), float(overturn_angle),
        state.r, state.cross_re, state.cross_im, state.cross_count,
        state.traj_theta, state.traj_theta_dot, state.traj_phi, state.traj_phi_dot,
        state.group_start,
    )  # fmt: skip

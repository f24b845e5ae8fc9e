"""Fixed-step kernel with the metronomes innermost: for large N.

Runs are spread over threads; within a run, each step is two passes over the N
metronomes that LLVM vectorizes: the first computes new angles, predicted velocities,
kicks (selects, not branches), the polynomial `sincos`, and the sums of eqs.
(eqm1)–(eqm2); the second applies φ̈ and updates velocities. Rare events (a zero
crossing to book, an overturn, an angle beyond the trig reduction's range) are
detected by cheap reductions in the first pass and handled in a scalar pass after
it. Reductions may be reassociated (``fastmath`` reassoc): the result differs from
the plain reference by rounding only, and is the same for any thread count.

Only loops and memory order live here: the forces come from `_physics`, the scheme's
updates and the bookkeeping from `_kernel_parts`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import (
    drift,
    momentum,
    record_run,
    upward,
    upward_crossing,
    velocity,
)
from ._physics import (
    applied_torque,
    disk_acceleration,
    disk_friction,
    disk_friction_stop,
    disk_torque,
    disk_velocity,
    escapement,
    momentum_at_rest,
    pendulum_terms,
    theta_ddot,
)
from .trig import REDUCTION_LIMIT, libm_sincos, sincos

FASTMATH = {"reassoc", "contract"}


def arrange(constants):
    """The constants in this layout's memory order: as built, (B, N) and (B,)."""
    return constants


@nb.njit(parallel=True, cache=True, fastmath=FASTMATH)
def advance(st, c, settings, rec):
    """Advance every run from step ``settings.step0`` by ``settings.n_steps``, in place."""
    # Unpacked before the parallel loop: numba may lose writes through a tuple field there.
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status, last_kick, rest_steps = st  # fmt: skip  # noqa: E501
    r, cross_re, cross_im, cross_count, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot, r_group, group_start = rec  # fmt: skip  # noqa: E501
    dt, step0, n_steps, record_every, overturn_angle = settings
    n_runs, n = theta.shape
    n_rec = r.shape[1]
    dt2 = dt * dt
    grid_dt = record_every * dt
    for b in nb.prange(n_runs):
        th_new = np.empty(n)
        rest = np.empty(n)
        q = np.empty(n)
        crossed = np.empty(n, dtype=np.bool_)
        pinned = math.isinf(c.total_inertia[b])
        dry = c.dry_friction[b] > 0.0 and not pinned
        until_record = record_every - step0 % record_every
        if step0 == 0 and not status[b] & STATUS_DIVERGED:
            record_run(b, 0, theta, theta_dot, phi, phi_dot, c.omega[b], r, r_group, group_start, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501
        for s in range(step0, step0 + n_steps):
            if status[b] & STATUS_DIVERGED:
                break
            t_new = (s + 1) * dt
            sums = _first_pass(c, b, theta[b], theta_dot[b], acc_theta[b], dt, dt2, overturn_angle, th_new, rest, q, crossed, last_kick[b], t_new, sincos)  # fmt: skip  # noqa: E501
            if sums[5] > 0:  # rare: far-wound angles, or inf (then φ̈ is NaN)
                sums = _first_pass(c, b, theta[b], theta_dot[b], acc_theta[b], dt, dt2, overturn_angle, th_new, rest, q, crossed, last_kick[b], t_new, libm_sincos)  # fmt: skip  # noqa: E501
            sum_num, sum_den, sum_kick, n_up, n_over, _ = sums
            if n_over > 0:
                status[b] |= STATUS_OVERTURNED
            if n_up > 0:
                t_old = s * dt
                for i in range(n):  # stops at the last of the n_up crossings
                    if crossed[i]:
                        th = theta[b, i]
                        t_cross = t_old + dt * th / (th - th_new[i])
                        upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
                        n_up -= 1
                        if n_up == 0:
                            break
            phi_next, phd_pred = drift(phi[b], phi_dot[b], acc_phi[b], dt, dt2)
            force = disk_torque(c, b, phd_pred, sum_kick) + applied_torque(c, b, t_new)
            others = force
            friction = 0.0
            held = False
            if dry:
                friction, held = disk_friction(c, b, phi_dot[b], sum_num, others)
                force = others + friction
            phdd = 0.0 if held else disk_acceleration(c, b, sum_num, sum_den, force)
            if not math.isfinite(phdd):
                status[b] |= STATUS_DIVERGED
                break
            phi[b] = phi_next
            sum_p = 0.0
            for i in range(n):  # vectorized pass
                thdd = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
                theta_dot[b, i] = v
                theta[b, i] = th_new[i]
                acc_theta[b, i] = thdd
                sum_p += q[i] * v
            p_phi[b] = momentum(p_phi[b], force_phi[b], force, dt, pinned)
            phi_dot[b] = disk_velocity(c, b, p_phi[b], sum_p)
            if dry and not held and friction * phi_dot[b] >= 0.0:
                # Rare: the disk's velocity reached 0 within the step (`verlet`).
                end, held = disk_friction_stop(c, b, friction, phi_dot[b], sum_den, dt)
                p_phi[b] += 0.5 * dt * (end - friction)
                mean_phdd = disk_acceleration(c, b, sum_num, sum_den, others + end)
                force = others + end
                phdd = mean_phdd
                if held:  # at rest at the end of the step: store the forces at rest
                    friction, rests = disk_friction(c, b, 0.0, sum_num, others)
                    force = others + friction
                    phdd = 0.0 if rests else disk_acceleration(c, b, sum_num, sum_den, force)
                sum_p = 0.0
                for i in range(n):
                    thdd = theta_ddot(c, (b, i), b, rest[i], q[i], mean_phdd)
                    theta_dot[b, i] += 0.5 * dt * (thdd - acc_theta[b, i])
                    acc_theta[b, i] = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                    sum_p += q[i] * theta_dot[b, i]
                phi_dot[b] = disk_velocity(c, b, p_phi[b], sum_p)
            if held:  # at rest: φ̇ = 0 exactly, p_φ = R Σ q θ̇
                p_phi[b] = momentum_at_rest(c, b, sum_p)
                phi_dot[b] = 0.0  # not from p_φ: a fused multiply-add would leave ~1e-20
                rest_steps[b] += 1
            force_phi[b] = force
            acc_phi[b] = phdd
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                record_run(b, k, theta, theta_dot, phi, phi_dot, c.omega[b], r, r_group, group_start, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501


@nb.njit(cache=True, inline="always")
def _first_pass(c, b, theta, theta_dot, acc, dt, dt2, overturn_angle, th_new, rest, q, crossed, last_kick, t_new, trig):  # fmt: skip  # noqa: E501
    """New angles, kicks and the sums of eqs. (eqm1)–(eqm2) over run ``b``'s metronomes
    (rows ``theta``, ``theta_dot``, ``acc``), with ``trig`` = the vectorizable `sincos`
    or, for far-wound angles, libm's; ``t_new`` into ``last_kick`` (the run's row) where
    an escapement fires. Returns the three sums and the counts of upward crossings,
    overturned and far-wound angles."""
    sum_num = 0.0
    sum_den = 0.0
    sum_kick = 0.0
    n_up = 0
    n_over = 0
    n_far = 0
    for i in range(theta.shape[0]):  # vectorized
        th = theta[i]
        tn, vp = drift(th, theta_dot[i], acc[i], dt, dt2)
        kick = escapement(c, (b, i), th, tn)
        last_kick[i] = t_new if kick != 0.0 else last_kick[i]  # a select: it vectorizes
        up = upward(th, tn)
        n_up += 1 if up else 0
        crossed[i] = up  # stored, not recomputed later: measurably faster (!)
        n_over += 1 if abs(tn) > overturn_angle else 0
        n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
        sn, cs = trig(tn)
        res, qi, num, den = pendulum_terms(c, (b, i), kick, sn, cs, vp)
        sum_num += num
        sum_den += den
        sum_kick += kick
        th_new[i] = tn
        rest[i] = res
        q[i] = qi
    return sum_num, sum_den, sum_kick, n_up, n_over, n_far

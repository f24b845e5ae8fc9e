"""The ``located`` scheme with the metronomes innermost: for large N.

The memory order and passes of `kernel_oscillators` (read it first): a vectorized
first pass over a run's metronomes (new angles, trig, the sums of eqs.
(eqm1)–(eqm2), here without any kick torque, and a count of the escapements that
fire), φ̈, and a vectorized second pass. A step in which some escapement fires
handles each impulse in a scalar pass between the two (`_located_parts.kick`), and
its second pass also adds what the impulses give every pendulum through the disk.
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
    upward_crossing,
    velocity,
)
from ._located_parts import crossing_fraction, kick
from ._physics import (
    applied_torque,
    disk_acceleration,
    disk_torque,
    disk_velocity,
    escapement,
    pendulum_terms,
    theta_ddot,
)
from .kernel_oscillators import FASTMATH, arrange  # noqa: F401  (same memory order)
from .trig import REDUCTION_LIMIT, libm_sincos, sincos


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
    half = 0.5 * dt
    grid_dt = record_every * dt
    for b in nb.prange(n_runs):
        th_new = np.empty(n)
        rest = np.empty(n)
        q = np.empty(n)
        fired = np.empty(n)
        pinned = math.isinf(c.total_inertia[b])
        # With an escapement off the vertical, the phase's upward zero crossings are no
        # longer the upward kicks: the run then scans for them apart.
        shifted = False
        for i in range(n):
            shifted |= c.escapement_offset[b, i] != 0.0
        until_record = record_every - step0 % record_every
        if step0 == 0 and not status[b] & STATUS_DIVERGED:
            record_run(b, 0, theta, theta_dot, phi, phi_dot, c.omega[b], r, r_group, group_start, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501
        for s in range(step0, step0 + n_steps):
            if status[b] & STATUS_DIVERGED:
                break
            sums = _first_pass(c, b, theta[b], theta_dot[b], acc_theta[b], dt, dt2, overturn_angle, th_new, rest, q, fired, sincos)  # fmt: skip  # noqa: E501
            if sums[4] > 0:  # rare: far-wound angles, or inf (then φ̈ is NaN)
                sums = _first_pass(c, b, theta[b], theta_dot[b], acc_theta[b], dt, dt2, overturn_angle, th_new, rest, q, fired, libm_sincos)  # fmt: skip  # noqa: E501
            sum_num, sum_den, n_kick, n_over, _ = sums
            if n_over > 0:
                status[b] |= STATUS_OVERTURNED
            phi_next, phd_pred = drift(phi[b], phi_dot[b], acc_phi[b], dt, dt2)
            force = disk_torque(c, b, phd_pred, 0.0) + applied_torque(c, b, (s + 1) * dt)
            phdd = disk_acceleration(c, b, sum_num, sum_den, force)
            if not math.isfinite(phdd):
                status[b] |= STATUS_DIVERGED
                break
            sum_p = 0.0
            t_old = s * dt
            if shifted:
                for i in range(n):
                    if theta[b, i] < 0.0 < th_new[i]:
                        t_cross = t_old + theta[b, i] / (theta[b, i] - th_new[i]) * dt
                        upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_cross, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
            if n_kick == 0:
                for i in range(n):  # vectorized pass, as in `kernel_oscillators`
                    thdd = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                    v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
                    theta_dot[b, i] = v
                    theta[b, i] = th_new[i]
                    acc_theta[b, i] = thdd
                    sum_p += q[i] * v
                phi[b] = phi_next
                p_phi[b] = momentum(p_phi[b], force_phi[b], force, dt, pinned)
            else:
                # Sums over the impulses of the step; the disk's jumps are linear in them.
                num_jump = 0.0  # Σ impulse k, and (τ_k − dt/2) × its forces' change
                force_jump = 0.0
                num_shift = 0.0  # Σ τ_k × impulse k: the distance the disk's jumps travel
                force_shift = 0.0
                num_change = 0.0  # the change of the forces on the disk
                jump_p = 0.0  # the disk's momentum jump
                for i in range(n):  # scalar pass; stops at the last of the n_kick impulses
                    if fired[i] == 0.0:
                        continue
                    last_kick[b, i] = (s + 1) * dt
                    frac = crossing_fraction(c, (b, i), theta[b, i], th_new[i])
                    sigma = frac * dt
                    after = dt - sigma
                    if fired[i] > 0.0 and not shifted:  # the kick is the crossing
                        upward_crossing(last_up, cross_re, cross_im, cross_count, b, i, t_old + sigma, grid_dt, n_rec, group_start)  # fmt: skip  # noqa: E501
                    impulse = fired[i] * dt
                    dv, dnum, dforce, jrest, jnum = kick(c, (b, i), b, impulse, theta_dot[b, i])
                    # The second pass's velocity update adds dt/2 of the new accelerations,
                    # which include the forces' change: its terms are net of that.
                    theta_dot[b, i] += dv + (after - half) * jrest
                    th_new[i] += after * dv
                    rest[i] += jrest
                    num_jump += dnum + (after - half) * jnum
                    force_jump += dforce
                    num_shift += after * dnum
                    force_shift += after * dforce
                    num_change += jnum
                    jump_p += dforce
                    n_kick -= 1
                    if n_kick == 0:
                        break
                jump = disk_acceleration(c, b, num_jump, sum_den, force_jump)
                shift = disk_acceleration(c, b, num_shift, sum_den, force_shift)
                phdd += disk_acceleration(c, b, num_change, sum_den, 0.0)
                for i in range(n):  # vectorized pass, with the jumps through the disk
                    thdd = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                    v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
                    v += theta_ddot(c, (b, i), b, 0.0, q[i], jump)
                    theta_dot[b, i] = v
                    theta[b, i] = th_new[i] + theta_ddot(c, (b, i), b, 0.0, q[i], shift)
                    acc_theta[b, i] = thdd
                    sum_p += q[i] * v
                phi[b] = phi_next + shift
                p_phi[b] = momentum(p_phi[b], force_phi[b], force, dt, pinned)
                p_phi[b] += 0.0 if pinned else jump_p
            phi_dot[b] = disk_velocity(c, b, p_phi[b], sum_p)
            force_phi[b] = force
            acc_phi[b] = phdd
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                record_run(b, k, theta, theta_dot, phi, phi_dot, c.omega[b], r, r_group, group_start, traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)  # fmt: skip  # noqa: E501


@nb.njit(cache=True, inline="always")
def _first_pass(c, b, theta, theta_dot, acc, dt, dt2, overturn_angle, th_new, rest, q, fired, trig):  # fmt: skip  # noqa: E501
    """New angles and the sums of eqs. (eqm1)–(eqm2) without kick torque over run
    ``b``'s metronomes, and the escapement torque of each (0 where it does not fire),
    with ``trig`` = `sincos` or libm's. Returns the two sums and the counts of
    escapements that fire, of overturned and of far-wound angles."""
    sum_num = 0.0
    sum_den = 0.0
    n_kick = 0
    n_over = 0
    n_far = 0
    for i in range(theta.shape[0]):  # vectorized
        th = theta[i]
        tn, vp = drift(th, theta_dot[i], acc[i], dt, dt2)
        fire = escapement(c, (b, i), th, tn)
        n_kick += 1 if fire != 0.0 else 0
        fired[i] = fire
        n_over += 1 if abs(tn) > overturn_angle else 0
        n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
        sn, cs = trig(tn)
        res, qi, num, den = pendulum_terms(c, (b, i), 0.0, sn, cs, vp)
        sum_num += num
        sum_den += den
        th_new[i] = tn
        rest[i] = res
        q[i] = qi
    return sum_num, sum_den, n_kick, n_over, n_far

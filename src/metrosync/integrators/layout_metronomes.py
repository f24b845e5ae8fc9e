"""The fixed-step loop nest with the metronomes innermost: for large N.

Runs are spread over threads; within a run, each step is two passes over the N
metronomes that LLVM vectorizes: the first computes new angles, predicted velocities,
the escapement (selects, not branches), the polynomial `sincos`, and the sums of eqs.
(eqm1)–(eqm2); the second applies φ̈ and updates velocities. Rare events (a zero
crossing to book, an impulse to apply, an overturn, an angle beyond the trig
reduction's range) are detected by cheap reductions in the first pass and handled in a
scalar pass after it. Reductions may be reassociated (``fastmath`` reassoc): the
result differs from the NumPy twin by rounding only, and is the same for any thread
count.

Only loops and memory order live here. The forces come from `_physics`; the scheme
comes in as two hooks (see `schemes` for their contract): ``begin`` per metronome in
the first pass (new angle, predicted velocity, and the escapement as a torque over the
step or as an impulse) and ``impulse`` per impulse in the scalar pass (where in the
step it acts and what it changes). A scheme's kernel is `loop` inlined into a compiled
function of its own (`schemes.compile_layouts`), so numba specialises the loop for it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import (
    disk_jumps,
    drift,
    kicked,
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
    momentum_at_rest,
    pendulum_terms,
    theta_ddot,
)
from .trig import REDUCTION_LIMIT, libm_sincos, sincos

FASTMATH = {"reassoc", "contract"}
#: Bits of a metronome's events in a step: an upward zero crossing, an impulse.
UP = 1
KICK = 2


def arrange(constants):
    """The constants in this layout's memory order: as built, (B, N) and (B,)."""
    return constants


@nb.njit(inline="always")
def loop(st, c, settings, rec, begin, impulse, impulsive):
    """Advance every run from step ``settings.step0`` by ``settings.n_steps``, in place,
    with the scheme's hooks ``begin`` and ``impulse`` and its constant ``impulsive``."""
    # Unpacked before the parallel loop: numba may lose writes through a tuple field there.
    (
        theta,
        theta_dot,
        phi,
        phi_dot,
        acc_theta,
        acc_phi,
        p_phi,
        force_phi,
        last_up,
        status,
        last_kick,
        rest_steps,
    ) = st
    (
        r,
        cross_re,
        cross_im,
        cross_count,
        traj_theta,
        traj_theta_dot,
        traj_phi,
        traj_phi_dot,
        r_group,
        group_start,
    ) = rec
    dt, step0, n_steps, record_every, overturn_angle = settings
    n_runs, n = theta.shape
    n_rec = r.shape[1]
    dt2 = dt * dt
    half = 0.5 * dt
    grid_dt = record_every * dt
    for b in nb.prange(n_runs):
        scratch = _scratch(n)
        th_new, rest, q, events = scratch
        # Bundles: a tuple is unpacked where it is compiled, at no cost. The loop's arrays
        # are written through a bundle only in called functions (`_record`,
        # `_settle_disk`): such a write inlined into `prange` was lost (`layout_runs._save`).
        rows = (theta[b], theta_dot[b], acc_theta[b])
        out = (theta, theta_dot, phi, phi_dot, r, r_group, group_start)
        trajectories = (traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)
        pinned = math.isinf(c.total_inertia[b])
        dry = c.dry_friction[b] > 0.0 and not pinned
        until_record = record_every - step0 % record_every
        if step0 == 0 and not status[b] & STATUS_DIVERGED:
            _record(b, 0, c.omega[b], out, trajectories)
        for s in range(step0, step0 + n_steps):
            if status[b] & STATUS_DIVERGED:
                break
            t_old = s * dt
            t_new = (s + 1) * dt
            now = (t_new, dt, overturn_angle)
            sums = _first_pass(c, b, rows, last_kick[b], scratch, now, begin, impulsive, sincos)
            if sums[6] > 0:  # rare: far-wound angles, or inf (then φ̈ is NaN)
                sums = _first_pass(
                    c, b, rows, last_kick[b], scratch, now, begin, impulsive, libm_sincos
                )
            sum_num, sum_den, sum_kick, n_up, n_imp, n_over, _ = sums
            if n_over > 0:
                status[b] |= STATUS_OVERTURNED
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
                if impulsive:  # the escapements fired all the same
                    kick_times(last_kick[b], events, t_new)
                status[b] |= STATUS_DIVERGED
                break
            # The scalar pass: crossings to book, impulses to apply (summed as the disk's
            # jumps are linear in them: `schemes`).
            jumps = (0.0, 0.0, 0.0, 0.0, 0.0)
            impulses = False
            if n_up > 0 or n_imp > 0:
                for i in range(n):  # stops after the last crossing and impulse
                    event = events[i]
                    if event == 0:
                        continue
                    if event & UP:
                        th = theta[b, i]
                        t_cross = t_old + dt * th / (th - th_new[i])
                        upward_crossing(
                            last_up,
                            cross_re,
                            cross_im,
                            cross_count,
                            b,
                            i,
                            t_cross,
                            grid_dt,
                            n_rec,
                            group_start,
                        )
                        n_up -= 1
                    if impulsive and event & KICK:  # never for a scheme without impulses
                        last_kick[b, i] = t_new
                        kick, after, dv, dnum, dforce, jrest, jnum = impulse(
                            c, (b, i), b, theta[b, i], th_new[i], theta_dot[b, i], dt
                        )
                        if kick != 0.0:
                            # The second pass adds dt/2 of the new accelerations, which
                            # include the forces' change: the velocity's terms are net of it.
                            theta_dot[b, i], th_new[i], rest[i] = kicked(
                                theta_dot[b, i], th_new[i], rest[i], after, half, dv, jrest
                            )
                            jumps = add_jump(jumps, after, half, dnum, dforce, jnum)
                            impulses = True
                        n_imp -= 1
                    if n_up == 0 and n_imp == 0:
                        break
            sum_p = 0.0
            jump_p = jumps[1]  # the disk's momentum jump
            if impulses:
                jump, shift, change = disk_jumps(c, b, jumps, sum_den)
                phdd += change
                for i in range(n):  # vectorized pass, with the jumps through the disk
                    thdd = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                    v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
                    v += theta_ddot(c, (b, i), b, 0.0, q[i], jump)
                    theta_dot[b, i] = v
                    theta[b, i] = th_new[i] + theta_ddot(c, (b, i), b, 0.0, q[i], shift)
                    acc_theta[b, i] = thdd
                    sum_p += q[i] * v
                phi[b] = phi_next + shift
            else:
                for i in range(n):  # vectorized pass
                    thdd = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
                    v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
                    theta_dot[b, i] = v
                    theta[b, i] = th_new[i]
                    acc_theta[b, i] = thdd
                    sum_p += q[i] * v
                phi[b] = phi_next
            p_phi[b] = momentum(p_phi[b], force_phi[b], force, dt, pinned)
            if not pinned:
                p_phi[b] += jump_p
            phi_dot[b] = disk_velocity(c, b, p_phi[b], sum_p)
            if dry:
                torques = (others, friction, force, phdd, held)
                disk = (p_phi, phi_dot)
                force, phdd, held, sum_p = _settle_disk(
                    c, b, rows, scratch, disk, (sum_num, sum_den, sum_p), torques, dt
                )
                if held:
                    rest_steps[b] += 1
            force_phi[b] = force
            acc_phi[b] = phdd
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                _record(b, k, c.omega[b], out, trajectories)


@nb.njit(inline="always")
def _scratch(n):
    """A run's scratch arrays, (N,) each: new angles, ρ_i and q_i of the step, and its
    events (`UP` | `KICK` bits)."""
    return np.empty(n), np.empty(n), np.empty(n), np.empty(n, dtype=np.uint8)


@nb.njit(cache=True, fastmath=FASTMATH)
def _record(b, k, omega_row, out, trajectories):
    """Record ``k`` of run ``b`` (`_kernel_parts.record_run`) from ``out`` = (θ, θ̇, φ, φ̇,
    r, r_group, group_start) into them and the ``trajectories``. Called, not inlined, as
    it writes through bundles; with the loop's fastmath, so that r is summed as there."""
    theta, theta_dot, phi, phi_dot, r, r_group, group_start = out
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot = trajectories
    record_run(
        b,
        k,
        theta,
        theta_dot,
        phi,
        phi_dot,
        omega_row,
        r,
        r_group,
        group_start,
        traj_theta,
        traj_theta_dot,
        traj_phi,
        traj_phi_dot,
    )


@nb.njit(cache=True)
def kick_times(last_kick, events, t_new):
    """``t_new`` into ``last_kick`` (a run's row) for each metronome with a `KICK` event
    in ``events``: the escapements of a scheme with impulses, in a step whose scalar pass
    does not run (the run diverged). Called, not inlined: it is rare."""
    for i in range(events.shape[0]):
        if events[i] & KICK:
            last_kick[i] = t_new


@nb.njit(inline="always")
def add_jump(jumps, after, half, dnum, dforce, jnum):
    """Add one impulse to the step's sums: (Σ dnum + (τ − dt/2) jnum, Σ dforce,
    Σ τ dnum, Σ τ dforce, Σ jnum), τ the time left after the impulse."""
    num_jump, force_jump, num_shift, force_shift, num_change = jumps
    return (
        num_jump + dnum + (after - half) * jnum,
        force_jump + dforce,
        num_shift + after * dnum,
        force_shift + after * dforce,
        num_change + jnum,
    )


@nb.njit(inline="always")
def _first_pass(c, b, rows, last_kick, scratch, now, begin, impulsive, trig):
    """New angles, the escapement and the sums of eqs. (eqm1)–(eqm2) over run ``b``'s
    metronomes (``rows`` = its θ, θ̇, θ̈), with the scheme's ``begin`` and
    ``impulsive``, and ``trig`` = the vectorizable `sincos` or, for far-wound angles,
    libm's; ``now`` = (t_new, dt, overturn angle). Where an escapement fires: without
    impulses, ``t_new`` into ``last_kick`` (the run's row) and its torque into the
    sums; with them, a `KICK` event (the scalar pass books both). Returns the three
    sums and the counts of upward crossings, escapements to visit in the scalar pass,
    overturned and far-wound angles."""
    theta, theta_dot, acc = rows
    th_new, rest, q, events = scratch
    t_new, dt, overturn_angle = now
    dt2 = dt * dt
    sum_num = 0.0
    sum_den = 0.0
    sum_kick = 0.0
    n_up = 0
    n_imp = 0
    n_over = 0
    n_far = 0
    for i in range(theta.shape[0]):  # vectorized
        th = theta[i]
        tn, vp, fires, torque, kick = begin(c, (b, i), th, theta_dot[i], acc[i], dt, dt2)
        if not impulsive:  # every branch on ``impulsive`` is folded where it is compiled
            last_kick[i] = t_new if fires != 0.0 else last_kick[i]  # a select: it vectorizes
        up = upward(th, tn)
        kicked = (fires != 0.0) if impulsive else (kick != 0.0)  # constant False for verlet
        n_up += 1 if up else 0
        n_imp += 1 if kicked else 0
        # Stored, not recomputed in the scalar pass, which visits only the metronomes
        # with an event: measurably faster (benchmarks/located.py).
        events[i] = (UP if up else 0) | (KICK if kicked else 0)
        n_over += 1 if abs(tn) > overturn_angle else 0
        n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
        sn, cs = trig(tn)
        res, qi, num, den = pendulum_terms(c, (b, i), torque, sn, cs, vp)
        sum_num += num
        sum_den += den
        if not impulsive:  # a scheme with impulses gives no torque
            sum_kick += torque
        th_new[i] = tn
        rest[i] = res
        q[i] = qi
    return sum_num, sum_den, sum_kick, n_up, n_imp, n_over, n_far


@nb.njit(cache=True)
def _settle_disk(c, b, rows, scratch, disk, sums, torques, dt):
    """Run ``b``'s disk after a step with dry friction: held at rest, or, when its
    velocity reached 0 within the step, stopped or reversed (the scheme is in
    `verlet`'s docstring). ``disk`` = (p_φ, φ̇), ``sums`` = (Σ num, Σ den, Σ q θ̇) and
    ``torques`` = (the torque without the friction, the friction, the torque, φ̈, held).
    Returns the torque and φ̈ to store, whether the disk ends the step held, and
    Σ q θ̇. Called, not inlined: one call per step at most, and code of this in the
    step's loop slows the loop without the feature."""
    _, theta_dot, acc = rows
    _, rest, q, _ = scratch
    p_phi, phi_dot = disk
    sum_num, sum_den, sum_p = sums
    others, friction, force, phdd, held = torques
    if not held and friction * phi_dot[b] >= 0.0:  # rare: φ̇ reached 0 within the step
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
        for i in range(theta_dot.shape[0]):
            thdd = theta_ddot(c, (b, i), b, rest[i], q[i], mean_phdd)
            theta_dot[i] += 0.5 * dt * (thdd - acc[i])
            acc[i] = theta_ddot(c, (b, i), b, rest[i], q[i], phdd)
            sum_p += q[i] * theta_dot[i]
        phi_dot[b] = disk_velocity(c, b, p_phi[b], sum_p)
    if held:  # at rest: φ̇ = 0 exactly, p_φ = R Σ q θ̇
        p_phi[b] = momentum_at_rest(c, b, sum_p)
        phi_dot[b] = 0.0  # not from p_φ: a fused multiply-add would leave ~1e-20
    return force, phdd, held, sum_p

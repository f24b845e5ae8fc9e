"""The fixed-step loop nest with the runs innermost: for small N.

With N = 2…10 a loop over the metronomes is too short to fill a vector register, so
runs are grouped in blocks of `LANES` and each vector lane holds one run: the state
is transposed to (block, N, LANES) and every arithmetic line of a step acts on a
whole block at once. Sums over metronomes are per lane, so they are not reassociated
and each run gets exactly the arithmetic of a scalar loop. Blocks are spread over
threads. Rare events (crossings, impulses, overturns, far-wound angles) are detected
by per-block reductions and handled in a scalar pass over the lanes that have them.

Only loops and memory order live here: the forces come from `_physics`, the
bookkeeping from `_kernel_parts`, and the scheme as the hooks ``begin`` and
``impulse`` (`schemes`), as in `layout_metronomes`. The constants are blocked once per
call by `arrange`, (block, N, LANES) and (block, LANES), so that `_physics` reads them
at (block, i, lane) and (block, lane) with unit stride across the lanes.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._kernel_parts import (
    analytic_order,
    disk_jumps,
    drift,
    group_orders,
    kicked,
    momentum,
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
    forced,
    momentum_at_rest,
    pendulum_terms,
    theta_ddot,
)
from .layout_metronomes import KICK, UP, add_jump, kick_times
from .trig import REDUCTION_LIMIT, libm_sincos, sincos

#: Runs per block: 8 doubles fill an AVX-512 register (two AVX2 registers).
LANES = 32


def arrange(constants):
    """The constants blocked for this layout: per-metronome (B, N) → (block, N, LANES),
    per-run (B,) → (block, LANES). Missing lanes of the last block repeat its last run
    (they are computed, never written back)."""
    runs = constants.lever.shape[0]
    n_blocks = (runs + LANES - 1) // LANES
    rows = np.minimum(np.arange(n_blocks * LANES), runs - 1)
    blocked = {}
    for name, values in constants._asdict().items():
        padded = values[rows]
        if values.ndim == 1:
            blocked[name] = np.ascontiguousarray(padded.reshape(n_blocks, LANES))
        else:
            shape = (n_blocks, LANES, values.shape[1])
            blocked[name] = np.ascontiguousarray(padded.reshape(shape).transpose(0, 2, 1))
    return type(constants)(**blocked)


@nb.njit(inline="always")
def loop(st, c, settings, rec, begin, impulse, impulsive):
    """Advance every run from step ``settings.step0`` by ``settings.n_steps``, in place,
    with the scheme's hooks and its constant ``impulsive`` (`layouts`); the state uses
    the usual (B, N) layout and is transposed into blocks here, once per call; ``c``
    comes from `arrange`."""
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
    n_blocks = (n_runs + LANES - 1) // LANES
    n_rec = r.shape[1]
    dt2 = dt * dt
    half = 0.5 * dt
    grid_dt = record_every * dt
    for blk in nb.prange(n_blocks):
        b0 = blk * LANES
        lanes = min(LANES, n_runs - b0)
        # Bundles of arrays, made here from the unpacked names: a tuple is unpacked where it
        # is compiled, at no cost. The block's own arrays are written through bundles in
        # inlined code; the loop's arguments only directly or in called functions (`_save`).
        kept = (theta, theta_dot, acc_theta, phi, phi_dot, acc_phi, p_phi, force_phi)
        trajectories = (traj_theta, traj_theta_dot, traj_phi, traj_phi_dot)
        swing, disk, alive = load_block(kept, status, b0, lanes)
        th, thd, acc = swing
        ph, phd, aph, pp, fph = disk
        step, sums, stick = _scratch(n)
        tn_s, rest, q, events = step
        s_num, s_den, s_kick, s_p = sums
        dry_lane, others, friction, held = stick
        ph_new = np.empty(LANES)
        phd_pred = np.empty(LANES)
        phdd = np.empty(LANES)
        force = np.empty(LANES)
        tau = np.zeros(LANES)  # applied torque, computed only for a forced block
        block_forced = False
        for w in range(LANES):
            block_forced |= forced(c, (blk, w))
        # Per-lane counts of the step's upward crossings, impulses and overturns: scan only
        # the lanes that need it. Rows of one array: as three arrays, the located loop ran
        # at 0.56 of verlet's rate at (100, 7), as rows at 0.97 (benchmarks/located.py).
        counts = np.empty((3, LANES), dtype=np.int64)
        ups, imps, overs = counts[0], counts[1], counts[2]
        lk = load_last_kick(last_kick, b0, lanes)
        for w in range(LANES):
            dry_lane[w] = c.dry_friction[blk, w] > 0.0 and not math.isinf(c.total_inertia[blk, w])
        dry = dry_lane.any()
        jump = np.zeros(LANES)  # the disk's jumps from the step's impulses, per lane
        shift = np.zeros(LANES)
        jump_p = np.zeros(LANES)
        until_record = record_every - step0 % record_every
        if step0 == 0:
            for w in range(lanes):
                if alive[w] > 0.0:
                    _record(c, r, r_group, group_start, blk, w, 0, swing, disk, trajectories)
        for s in range(step0, step0 + n_steps):
            t_old = s * dt
            t_new = (s + 1) * dt
            now = (t_new, dt, overturn_angle)
            n_far = _first_pass(
                c, blk, swing, step, sums, counts, lk, alive, now, begin, impulsive, sincos
            )
            if n_far > 0:  # rare: redo the pass with libm trig
                _first_pass(
                    c, blk, swing, step, sums, counts, lk, alive, now, begin, impulsive, libm_sincos
                )
            if block_forced:  # a sine per lane: kept out of the vectorized loop below
                for w in range(LANES):
                    tau[w] = applied_torque(c, (blk, w), t_new)
            for w in range(LANES):
                ph_new[w], phd_pred[w] = drift(ph[w], phd[w], aph[w], dt, dt2)
                force[w] = disk_torque(c, (blk, w), phd_pred[w], s_kick[w]) + tau[w]
                phdd[w] = disk_acceleration(c, (blk, w), s_num[w], s_den[w], force[w])
                s_p[w] = 0.0
            if dry:  # the block has a run with dry friction on the disk (`verlet`)
                _dry_friction(c, blk, phd, sums, force, phdd, stick)
            any_impulse = False
            for w in range(lanes):
                if alive[w] == 0.0:
                    continue
                if overs[w] > 0:
                    status[b0 + w] |= STATUS_OVERTURNED
                if not math.isfinite(phdd[w]):
                    if impulsive:  # the escapements fired all the same
                        kick_times(lk[:, w], events[:, w], t_new)
                    status[b0 + w] |= STATUS_DIVERGED
                    alive[w] = 0.0
                    continue
                if ups[w] == 0 and imps[w] == 0:
                    continue
                # The scalar pass: crossings to book, impulses to apply (`layout_metronomes`),
                # at the metronomes the first pass marked.
                impulses = False
                jumps = (0.0, 0.0, 0.0, 0.0, 0.0)
                for i in range(n):
                    t0 = th[i, w]
                    tn = tn_s[i, w]
                    event = events[i, w] if impulsive else (UP if upward(t0, tn) else 0)
                    if event == 0:
                        continue
                    if event & UP:
                        t_cross = t_old + dt * t0 / (t0 - tn)
                        upward_crossing(
                            last_up,
                            cross_re,
                            cross_im,
                            cross_count,
                            b0 + w,
                            i,
                            t_cross,
                            grid_dt,
                            n_rec,
                            group_start,
                        )
                        ups[w] -= 1
                    if event & KICK:
                        lk[i, w] = t_new
                        kick, after, dv, dnum, dforce, jrest, jnum = impulse(
                            c, (blk, i, w), (blk, w), t0, tn, thd[i, w], dt
                        )
                        if kick != 0.0:
                            thd[i, w], tn_s[i, w], rest[i, w] = kicked(
                                thd[i, w], tn_s[i, w], rest[i, w], after, half, dv, jrest
                            )
                            jumps = add_jump(jumps, after, half, dnum, dforce, jnum)
                            impulses = True
                        imps[w] -= 1
                    if ups[w] == 0 and imps[w] == 0:
                        break
                any_impulse |= impulses
                if impulses:
                    jump[w], shift[w], change = disk_jumps(c, (blk, w), jumps, s_den[w])
                    phdd[w] += change
                    jump_p[w] = jumps[1]
            if any_impulse:
                for i in range(n):
                    for w in range(LANES):  # vectorized across runs, with the disk's jumps
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
            if any_impulse:
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
            else:
                for w in range(LANES):
                    if alive[w] > 0.0:
                        ph[w] = ph_new[w]
                        pp[w] = momentum(
                            pp[w], fph[w], force[w], dt, math.isinf(c.total_inertia[blk, w])
                        )
                        phd[w] = disk_velocity(c, (blk, w), pp[w], s_p[w])
                        fph[w] = force[w]
                        aph[w] = phdd[w]
            if dry:
                _settle_disks(
                    c, blk, b0, lanes, alive, swing, disk, step, sums, stick, dt, rest_steps
                )
            until_record -= 1
            if until_record == 0:
                until_record = record_every
                k = (s + 1) // record_every
                for w in range(lanes):
                    if alive[w] > 0.0:
                        _record(c, r, r_group, group_start, blk, w, k, swing, disk, trajectories)
        store_block(kept, b0, lanes, swing, disk)
        for w in range(lanes):
            for i in range(n):
                last_kick[b0 + w, i] = lk[i, w]


@nb.njit(inline="always")
def _scratch(n):
    """A block's scratch bundles, runs innermost: the step's new angles, ρ_i, q_i and
    events (`layout_metronomes.UP` | ``KICK`` bits), (n, LANES) each; the per-lane sums
    of eqs. (eqm1)–(eqm2), Σ num, Σ den, Σ torque, and Σ q θ̇ after the step; and for
    the disk's dry friction (`_dry_friction`), the lanes that have it, the torque
    without it, the friction and whether it holds."""
    step = (
        np.empty((n, LANES)),
        np.empty((n, LANES)),
        np.empty((n, LANES)),
        np.empty((n, LANES), dtype=np.uint8),
    )
    sums = (np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES))
    stick = (
        np.empty(LANES, dtype=np.bool_),
        np.empty(LANES),
        np.empty(LANES),
        np.empty(LANES, dtype=np.bool_),
    )
    return step, sums, stick


@nb.njit(inline="always")
def _first_pass(c, blk, swing, step, sums, counts, lk, alive, now, begin, impulsive, trig):
    """New angles, the escapement and the per-lane sums of eqs. (eqm1)–(eqm2) for block
    ``blk`` (the bundles of `load_block` and `_scratch`), with the scheme's ``begin``
    and ``impulsive``, and ``trig`` = the vectorizable `sincos` or, for far-wound angles,
    libm's; ``now`` = (t_new, dt, overturn angle). Fills the per-lane counts of upward
    crossings, escapements to visit in the scalar pass and overturns (``counts``' rows);
    returns the number of far-wound angles. Where an escapement fires: without
    impulses, ``t_new`` into ``lk`` (for a live lane) and its torque into the sums;
    with them, a `KICK` event (the scalar pass books both)."""
    th, thd, acc = swing
    tn_s, rest, q, events = step
    s_num, s_den, s_kick, _ = sums
    ups, imps, overs = counts[0], counts[1], counts[2]
    t_new, dt, overturn_angle = now
    dt2 = dt * dt
    n_far = 0
    for w in range(th.shape[1]):
        ups[w] = 0
        imps[w] = 0
        overs[w] = 0
        s_num[w] = 0.0
        s_den[w] = 0.0
        s_kick[w] = 0.0
    for i in range(th.shape[0]):
        for w in range(th.shape[1]):  # vectorized across runs
            t0 = th[i, w]
            tn, vp, fires, torque, _ = begin(c, (blk, i, w), t0, thd[i, w], acc[i, w], dt, dt2)
            up = upward(t0, tn)
            ups[w] += 1 if up else 0
            if impulsive:  # every branch on ``impulsive`` is folded where it is compiled
                fired = fires != 0.0
                imps[w] += 1 if fired else 0
                events[i, w] = (UP if up else 0) | (KICK if fired else 0)
            else:
                fired = (fires != 0.0) & (alive[w] > 0.0)
                lk[i, w] = t_new if fired else lk[i, w]  # a select: it vectorizes
            overs[w] += 1 if abs(tn) > overturn_angle else 0
            n_far += 1 if abs(tn) > REDUCTION_LIMIT else 0
            sn, cs = trig(tn)
            res, qi, num, den = pendulum_terms(c, (blk, i, w), torque, sn, cs, vp)
            s_num[w] += num
            s_den[w] += den
            if not impulsive:  # a scheme with impulses gives no torque
                s_kick[w] += torque
            tn_s[i, w] = tn
            rest[i, w] = res
            q[i, w] = qi
    return n_far


@nb.njit(cache=True, inline="always")
def load_last_kick(last_kick, b0, lanes):
    """Block-local copy (n, LANES) of the runs' last impulse times (as `load_block`)."""
    n = last_kick.shape[1]
    lk = np.empty((n, LANES))
    for i in range(n):
        for w in range(LANES):
            lk[i, w] = last_kick[b0 + min(w, lanes - 1), i]
    return lk


@nb.njit(cache=True)
def _dry_friction(c, blk, phd, sums, force, phdd, stick):
    """The dry friction of each lane with it as the step starts resolving the disk
    (`_physics.disk_friction`); adds it to ``force`` and recomputes ``phdd``. Called,
    not inlined, like `_settle_disks`."""
    s_num, s_den, _, _ = sums
    dry_lane, others, friction, held = stick
    for w in range(phd.shape[0]):
        others[w] = force[w]
        friction[w] = 0.0
        held[w] = False
        if dry_lane[w]:
            friction[w], held[w] = disk_friction(c, (blk, w), phd[w], s_num[w], others[w])
            force[w] = others[w] + friction[w]
            phdd[w] = (
                0.0 if held[w] else disk_acceleration(c, (blk, w), s_num[w], s_den[w], force[w])
            )


@nb.njit(cache=True)
def _settle_disks(c, blk, b0, lanes, alive, swing, disk, step, sums, stick, dt, rest_steps):
    """The disks with dry friction after a step (`_settle_disk`); counts the steps that
    end with a disk held in ``rest_steps``. One call per step, and two levels deep:
    code of this in the step's loop slows the kernel without the feature by about 6 %
    (benchmarks/kernel.py at (100, 7))."""
    dry_lane = stick[0]
    for w in range(lanes):
        if alive[w] > 0.0 and dry_lane[w]:
            if _settle_disk(c, blk, w, swing, disk, step, sums, stick, dt):
                rest_steps[b0 + w] += 1


@nb.njit(cache=True)
def _settle_disk(c, blk, w, swing, disk, step, sums, stick, dt):
    """Lane ``w``'s disk after a step with dry friction: held at rest, or, when its
    velocity reached 0 within the step, stopped or reversed (`verlet`). Returns whether
    it ends the step held at rest."""
    _, thd, acc = swing
    _, phd, aph, pp, fph = disk
    _, rest, q, _ = step
    s_num, s_den, s_p = sums[0][w], sums[1][w], sums[3][w]
    others, friction, held = stick[1][w], stick[2][w], stick[3][w]
    if not held and friction * phd[w] >= 0.0:  # rare: φ̇ reached 0 within the step
        end, held = disk_friction_stop(c, (blk, w), friction, phd[w], s_den, dt)
        pp[w] += 0.5 * dt * (end - friction)
        mean_phdd = disk_acceleration(c, (blk, w), s_num, s_den, others + end)
        fph[w] = others + end
        aph[w] = mean_phdd
        if held:  # at rest at the end of the step: store the forces at rest
            at_rest, rests = disk_friction(c, (blk, w), 0.0, s_num, others)
            fph[w] = others + at_rest
            aph[w] = 0.0 if rests else disk_acceleration(c, (blk, w), s_num, s_den, fph[w])
        s_p = 0.0
        for i in range(thd.shape[0]):
            thdd = theta_ddot(c, (blk, i, w), (blk, w), rest[i, w], q[i, w], mean_phdd)
            thd[i, w] += 0.5 * dt * (thdd - acc[i, w])
            acc[i, w] = theta_ddot(c, (blk, i, w), (blk, w), rest[i, w], q[i, w], aph[w])
            s_p += q[i, w] * thd[i, w]
        phd[w] = disk_velocity(c, (blk, w), pp[w], s_p)
    if held:  # at rest: φ̇ = 0 exactly, p_φ = R Σ q θ̇
        pp[w] = momentum_at_rest(c, (blk, w), s_p)
        phd[w] = 0.0
    return held


@nb.njit(cache=True, inline="always")
def _record(c, r, r_group, group_start, blk, w, k, swing, disk, trajectories):
    """Record ``k`` of lane ``w`` of block ``blk``: r and, with several groups, each
    group's r; the state into ``trajectories`` when they are kept (`_save`). Inlined,
    so that r is summed with the loop's own fastmath flags (a scheme's choice)."""
    b = blk * LANES + w
    th, thd = swing[0], swing[1]
    r[b, k] = analytic_order(th[:, w], thd[:, w], c.omega[blk, :, w])
    if group_start.shape[0] > 2:  # several groups
        group_orders(r_group, b, k, th[:, w], thd[:, w], c.omega[blk, :, w], group_start)
    if trajectories[0].shape[0] > 0:
        _save(trajectories, b, k, w, swing, disk)


@nb.njit(cache=True)
def _save(trajectories, b, k, w, swing, disk):
    """Lane ``w``'s state into record ``k`` of run ``b`` of the ``trajectories`` (θ, θ̇,
    φ, φ̇). Called, not inlined: a write through a bundle of the loop's arrays, inlined
    into `prange`, was lost (the trajectories of φ stayed NaN; numba issue 7135)."""
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot = trajectories
    th, thd, _ = swing
    ph, phd, _, _, _ = disk
    for i in range(th.shape[0]):
        traj_theta[b, k, i] = th[i, w]
        traj_theta_dot[b, k, i] = thd[i, w]
    traj_phi[b, k] = ph[w]
    traj_phi_dot[b, k] = phd[w]


@nb.njit(cache=True, inline="always")
def load_block(kept, status, b0, lanes):
    """Block-local copies of runs ``b0`` … ``b0 + lanes − 1`` of the state ``kept`` =
    (θ, θ̇, θ̈, φ, φ̇, φ̈, p_φ, the disk's torque), runs innermost: (n, LANES) per
    metronome, ``swing`` = (θ, θ̇, θ̈); (LANES,) per run, ``disk`` = (φ, φ̇, φ̈, p_φ,
    torque); and 1.0 for each lane still alive. Missing lanes repeat the last run and
    are never written back (`store_block`)."""
    theta, theta_dot, acc_theta, phi, phi_dot, acc_phi, p_phi, force_phi = kept
    n = theta.shape[1]
    th = np.empty((n, LANES))
    thd = np.empty((n, LANES))
    acc = np.empty((n, LANES))
    for i in range(n):
        for w in range(LANES):
            b = b0 + min(w, lanes - 1)
            th[i, w] = theta[b, i]
            thd[i, w] = theta_dot[b, i]
            acc[i, w] = acc_theta[b, i]
    ph = np.empty(LANES)
    phd = np.empty(LANES)
    aph = np.empty(LANES)
    pp = np.empty(LANES)
    fph = np.empty(LANES)
    alive = np.empty(LANES)
    for w in range(LANES):
        b = b0 + min(w, lanes - 1)
        ph[w] = phi[b]
        phd[w] = phi_dot[b]
        aph[w] = acc_phi[b]
        pp[w] = p_phi[b]
        fph[w] = force_phi[b]
        alive[w] = 0.0 if status[b] & STATUS_DIVERGED else 1.0
    return (th, thd, acc), (ph, phd, aph, pp, fph), alive


@nb.njit(cache=True)
def store_block(kept, b0, lanes, swing, disk):
    """Write a block's real lanes back into ``kept`` (the inverse of `load_block`).
    Called, not inlined, as `_save`: it writes through a bundle."""
    theta, theta_dot, acc_theta, phi, phi_dot, acc_phi, p_phi, force_phi = kept
    th, thd, acc = swing
    ph, phd, aph, pp, fph = disk
    for w in range(lanes):
        b = b0 + w
        for i in range(theta.shape[1]):
            theta[b, i] = th[i, w]
            theta_dot[b, i] = thd[i, w]
            acc_theta[b, i] = acc[i, w]
        phi[b] = ph[w]
        phi_dot[b] = phd[w]
        acc_phi[b] = aph[w]
        p_phi[b] = pp[w]
        force_phi[b] = fph[w]

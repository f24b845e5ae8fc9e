"""Fixed-step kernels for NVIDIA GPUs (numba.cuda): the same schemes and records.

One thread block per run; its threads stride over the metronomes, each thread always
over the same ones. Each step is the passes of the CPU loops (`layout_metronomes`):
the first, with the sums of eqs. (eqm1)–(eqm2) reduced in shared memory, after which
thread 0 computes φ̈; the impulses inside the step, when a scheme gives any; the
second, the velocities and the disk's update.

Nothing of the scheme, the physics or the bookkeeping is written here: `device_function`
compiles the CPU functions again, from the same Python source, as CUDA device
functions, and so, at any depth, the compiled functions they call. A scheme's kernel
(`scheme_kernel`) calls its hooks ``begin`` and ``impulse`` (`layouts`), the updates
of `_kernel_parts`, the forces of `_physics`, `_kernel_parts.upward_crossing` for a
crossing and `_kernel_parts.record_run` for a record. Where the GPU must do otherwise,
`GPU_VERSIONS` stands in for a CPU function wherever it is called: the crossing-phase
sums are added atomically (`_kernel_parts.accumulate`: a block's threads book
crossings at once), the trig is libm's, and a run's order parameter is summed over the
block from `_kernel_parts.phase_vector` (`_kernel_parts.analytic_order`). What is left
here is the loop over a block's threads, its reductions, and which thread writes what.
The kernel takes the CPU kernels' argument list (`_abi`: State, Constants, Settings,
Recording) plus three scratch arrays. Everything is float64.

Status: verified in numba's CUDA simulator against the NumPy twin (see
tests/integrators/test_kernel_cuda.py); not yet run or timed on a GPU. Known limits:
one run per block (for small N most threads idle), the state travels between host and
device once per chunk of steps, no trajectories, and no dry friction on the platform
(both refused by the capability table, `metrosync.capabilities`).
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass
from typing import Any

from numba import cuda, float64
from numba.core.registry import CPUDispatcher

from ..capabilities import require
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from . import _kernel_parts, _physics, layout_metronomes, located, trig, verlet
from ._abi import Constants, Recording, State, constants_of, settings_of
from ._state import StepState

#: Threads per block, a power of two; a block holds one run.
MAX_THREADS = 256
#: Rows of a block's sums: the first pass's (numerator, denominator, escapement torque,
#: overturned, impulses), then the five sums of the impulses' jumps (``add_jump``).
SUMS = 5
#: What thread 0 computes for the block, in a shared array of `N_DISK`: φ̈, the disk's
#: torque, its new angle before the impulses, the denominator sum, the impulses'
#: count, and the disk's velocity jump, angle shift and momentum jump from them.
PHDD, FORCE, PHI_NEXT, DEN, KICKS, JUMP, SHIFT, JUMP_P = range(8)
N_DISK = 8

#: Device functions compiled so far, by the CPU function they come from.
_compiled: dict = {}
#: What a device function calls in place of a CPU function (filled below).
GPU_VERSIONS: dict = {}


def device_function(fn, **callees):
    """The CUDA device function compiled from the Python source of the CPU function
    ``fn`` (a compiled function of `_physics`, `_kernel_parts`, a scheme's hook …).

    The compiled functions it calls are replaced, at any depth, by their
    `GPU_VERSIONS`, or else by device functions compiled from their own source;
    ``callees`` (name → device function) replace ``fn``'s own calls by name."""
    if not callees and fn in _compiled:
        return _compiled[fn]
    source = fn.py_func
    names = {}
    for name in source.__code__.co_names:
        called = source.__globals__.get(name)
        if isinstance(called, CPUDispatcher):
            names[name] = (
                GPU_VERSIONS[called] if called in GPU_VERSIONS else device_function(called)
            )
    names.update(callees)
    rebound = types.FunctionType(
        source.__code__,
        {**source.__globals__, **names},
        source.__name__,
        source.__defaults__,
        source.__closure__,
    )
    compiled = cuda.jit(device=True)(rebound)
    if not callees:
        _compiled[fn] = compiled
    return compiled


@cuda.jit(device=True)
def atomic_add(sums, index, value):
    """`_kernel_parts.accumulate` on the GPU."""
    cuda.atomic.add(sums, index, value)


@cuda.jit(device=True)
def block_sum(sums, rows, tid, nt):
    """Tree reduction of the first ``rows`` rows of ``sums`` (rows × threads) over the
    block; each row's total in its column 0. Every thread of the block calls it."""
    cuda.syncthreads()
    stride = nt // 2
    while stride > 0:
        if tid < stride:
            for k in range(rows):
                sums[k, tid] += sums[k, tid + stride]
        cuda.syncthreads()
        stride //= 2


phase_vector = device_function(_kernel_parts.phase_vector)
resultant = device_function(_kernel_parts.resultant)


@cuda.jit(device=True)
def block_order(theta_row, theta_dot_row, omega_row):
    """`_kernel_parts.analytic_order` on the GPU: the same terms, summed over the block.
    Every thread of the block calls it, and every one gets r."""
    tid = cuda.threadIdx.x
    nt = cuda.blockDim.x
    sums = cuda.shared.array((2, MAX_THREADS), float64)
    re = 0.0
    im = 0.0
    for i in range(tid, theta_row.shape[0], nt):
        x, y = phase_vector(theta_row[i], theta_dot_row[i], omega_row[i])
        re += x
        im += y
    sums[0, tid] = re
    sums[1, tid] = im
    block_sum(sums, 2, tid, nt)
    r = resultant(sums[0, 0], sums[1, 0], theta_row.shape[0])
    cuda.syncthreads()  # every thread has read the sums before a next call reuses them
    return r


GPU_VERSIONS.update(
    {
        _kernel_parts.accumulate: atomic_add,
        trig.sincos: device_function(trig.libm_sincos),
        _kernel_parts.analytic_order: block_order,
    }
)

drift = device_function(_kernel_parts.drift)
velocity = device_function(_kernel_parts.velocity)
momentum = device_function(_kernel_parts.momentum)
upward = device_function(_kernel_parts.upward)
upward_crossing = device_function(_kernel_parts.upward_crossing)
record_run = device_function(_kernel_parts.record_run)
kicked = device_function(_kernel_parts.kicked)
disk_jumps = device_function(_kernel_parts.disk_jumps)
add_jump = device_function(layout_metronomes.add_jump)
pendulum_terms = device_function(_physics.pendulum_terms)
disk_torque = device_function(_physics.disk_torque)
applied_torque = device_function(_physics.applied_torque)
disk_acceleration = device_function(_physics.disk_acceleration)
theta_ddot = device_function(_physics.theta_ddot)
disk_velocity = device_function(_physics.disk_velocity)


def gpu_available() -> bool:
    """True when numba finds a CUDA device (or runs its CUDA simulator)."""
    try:
        return bool(cuda.is_available())
    except Exception:  # a broken driver install reports itself here
        return False


def threads_for(n: int) -> int:
    t = 32
    while t < n and t < MAX_THREADS:
        t *= 2
    return t


@cuda.jit(device=True)
def record(b, k, st, c, rec):
    """Record ``k`` of run ``b`` (`_kernel_parts.record_run`). A run that has diverged
    records nothing, as in every other backend (the test is the same for all threads of
    the block, so none waits alone at a barrier)."""
    if st.status[b] & STATUS_DIVERGED:
        return
    record_run(
        b,
        k,
        st.theta,
        st.theta_dot,
        st.phi,
        st.phi_dot,
        c.omega[b],
        rec.r,
        rec.r_group,
        rec.group_start,
        rec.traj_theta,
        rec.traj_theta_dot,
        rec.traj_phi,
        rec.traj_phi_dot,
    )


def scheme_kernel(begin, impulse):
    """The kernel of the scheme whose hooks are ``begin`` and ``impulse`` (device
    functions, `layouts`), called ``kernel[runs, threads](state, constants, settings,
    recording, scratch)``."""

    @cuda.jit
    def advance(st, c, settings, rec, scratch):
        dt, step0, n_steps, record_every, overturn_angle = settings
        th_new, rest, q = scratch
        theta = st.theta
        theta_dot = st.theta_dot
        acc = st.acc_theta
        status = st.status
        b = cuda.blockIdx.x
        tid = cuda.threadIdx.x
        nt = cuda.blockDim.x
        n = theta.shape[1]
        n_rec = rec.r.shape[1]
        sums = cuda.shared.array((SUMS, MAX_THREADS), float64)
        disk = cuda.shared.array(N_DISK, float64)
        dt2 = dt * dt
        half = 0.5 * dt
        grid_dt = record_every * dt
        if step0 == 0:
            record(b, 0, st, c, rec)
        for s in range(step0, step0 + n_steps):
            cuda.syncthreads()
            if status[b] & STATUS_DIVERGED:
                break
            t_old = s * dt
            t_new = (s + 1) * dt
            sum_num = 0.0
            sum_den = 0.0
            sum_torque = 0.0
            over = 0.0
            kicks = 0.0
            for i in range(tid, n, nt):
                th = theta[b, i]
                tn, vp, fires, torque, kick = begin(
                    c, (b, i), th, theta_dot[b, i], acc[b, i], dt, dt2
                )
                if fires != 0.0:
                    st.last_kick[b, i] = t_new
                if upward(th, tn):
                    t_cross = t_old + dt * th / (th - tn)
                    upward_crossing(
                        st.last_up,
                        rec.cross_re,
                        rec.cross_im,
                        rec.cross_count,
                        b,
                        i,
                        t_cross,
                        grid_dt,
                        n_rec,
                        rec.group_start,
                    )
                over += 1.0 if abs(tn) > overturn_angle else 0.0
                kicks += 1.0 if kick != 0.0 else 0.0
                res, qi, num, den = pendulum_terms(
                    c, (b, i), torque, math.sin(tn), math.cos(tn), vp
                )
                sum_num += num
                sum_den += den
                sum_torque += torque
                th_new[b, i] = tn
                rest[b, i] = res
                q[b, i] = qi
            sums[0, tid] = sum_num
            sums[1, tid] = sum_den
            sums[2, tid] = sum_torque
            sums[3, tid] = over
            sums[4, tid] = kicks
            block_sum(sums, SUMS, tid, nt)
            if tid == 0:
                phi_next, phd_pred = drift(st.phi[b], st.phi_dot[b], st.acc_phi[b], dt, dt2)
                force = disk_torque(c, b, phd_pred, sums[2, 0]) + applied_torque(c, b, t_new)
                phdd = disk_acceleration(c, b, sums[0, 0], sums[1, 0], force)
                disk[PHDD] = phdd
                disk[FORCE] = force
                disk[PHI_NEXT] = phi_next
                disk[DEN] = sums[1, 0]
                disk[KICKS] = sums[4, 0]
                if sums[3, 0] > 0.0:
                    status[b] |= STATUS_OVERTURNED
                if not math.isfinite(phdd):
                    status[b] |= STATUS_DIVERGED
            cuda.syncthreads()
            if status[b] & STATUS_DIVERGED:
                break
            impulses = disk[KICKS] > 0.0  # the same for the whole block
            if impulses:  # each thread applies its metronomes' impulses, then the disk's
                jumps = (0.0, 0.0, 0.0, 0.0, 0.0)
                for i in range(tid, n, nt):
                    given, after, dv, dnum, dforce, jrest, jnum = impulse(
                        c, (b, i), b, theta[b, i], th_new[b, i], theta_dot[b, i], dt
                    )
                    if given != 0.0:
                        theta_dot[b, i], th_new[b, i], rest[b, i] = kicked(
                            theta_dot[b, i], th_new[b, i], rest[b, i], after, half, dv, jrest
                        )
                        jumps = add_jump(jumps, after, half, dnum, dforce, jnum)
                sums[0, tid], sums[1, tid], sums[2, tid], sums[3, tid], sums[4, tid] = jumps
                block_sum(sums, SUMS, tid, nt)
                if tid == 0:
                    totals = (sums[0, 0], sums[1, 0], sums[2, 0], sums[3, 0], sums[4, 0])
                    jump, shift, change = disk_jumps(c, b, totals, disk[DEN])
                    disk[JUMP] = jump
                    disk[SHIFT] = shift
                    disk[PHDD] += change
                    disk[JUMP_P] = sums[1, 0]
                cuda.syncthreads()
            phdd = disk[PHDD]
            sum_p = 0.0
            for i in range(tid, n, nt):
                thdd = theta_ddot(c, (b, i), b, rest[b, i], q[b, i], phdd)
                v = velocity(theta_dot[b, i], acc[b, i], thdd, dt)
                moved = th_new[b, i]
                if impulses:  # the jumps through the disk
                    v += theta_ddot(c, (b, i), b, 0.0, q[b, i], disk[JUMP])
                    moved += theta_ddot(c, (b, i), b, 0.0, q[b, i], disk[SHIFT])
                theta_dot[b, i] = v
                theta[b, i] = moved
                acc[b, i] = thdd
                sum_p += q[b, i] * v
            sums[0, tid] = sum_p
            block_sum(sums, 1, tid, nt)
            if tid == 0:
                pinned = math.isinf(c.total_inertia[b])
                p_phi = momentum(st.p_phi[b], st.force_phi[b], disk[FORCE], dt, pinned)
                st.phi[b] = disk[PHI_NEXT]
                if impulses:
                    st.phi[b] += disk[SHIFT]
                    if not pinned:
                        p_phi += disk[JUMP_P]
                st.p_phi[b] = p_phi
                st.phi_dot[b] = disk_velocity(c, b, p_phi, sums[0, 0])
                st.force_phi[b] = disk[FORCE]
                st.acc_phi[b] = phdd
            cuda.syncthreads()
            if (s + 1) % record_every == 0:
                record(b, (s + 1) // record_every, st, c, rec)

    return advance


@dataclass(frozen=True)
class GpuScheme:
    """A fixed-step scheme on the GPU: its name (its consumer in the capability table is
    ``<name>/gpu``) and its kernel (`scheme_kernel`)."""

    name: str
    kernel: Any

    def advance_state(
        self,
        state: StepState,
        sys,
        *,
        dt,
        step0,
        n_steps,
        record_every,
        overturn_angle,
        threads=None,
    ):
        """Advance ``state`` on the GPU by ``n_steps`` steps; same contract as the CPU
        kernels. ``threads`` per block defaults to `threads_for` N."""
        if state.traj_theta.shape[0]:
            raise NotImplementedError("trajectories are not recorded by the GPU backend yet")
        require(f"{self.name}/gpu", sys)
        b, n = state.theta.shape
        st = State(*(cuda.to_device(a) for a in state.kernel_state()))
        constants = Constants(*(cuda.to_device(a) for a in constants_of(sys)))
        kept = state.kernel_recording()
        grouped = state.group_start.size > 2
        # Trajectories, and r_group of one group: placeholders the kernel never reads.
        rec = Recording(
            *(cuda.to_device(a) for a in kept[:4]),
            *(cuda.device_array(a.shape, a.dtype) for a in kept[4:8]),
            cuda.to_device(kept.r_group) if grouped else cuda.device_array((1, 1, 1)),
            cuda.to_device(kept.group_start),
        )
        scratch = tuple(cuda.device_array((b, n)) for _ in range(3))
        settings = settings_of(
            dt=dt,
            step0=step0,
            n_steps=n_steps,
            record_every=record_every,
            overturn_angle=overturn_angle,
        )
        self.kernel[b, threads or threads_for(n)](st, constants, settings, rec, scratch)
        back = st + rec[:4] + ((rec.r_group,) if grouped else ())
        hosts = state.kernel_state() + kept[:4] + ((kept.r_group,) if grouped else ())
        for device, host in zip(back, hosts, strict=True):
            device.copy_to_host(host)


def _scheme(module) -> GpuScheme:
    hooks = (device_function(module.begin), device_function(module.impulse))
    return GpuScheme(module.__name__.rsplit(".", 1)[1], scheme_kernel(*hooks))


VERLET = _scheme(verlet)
LOCATED = _scheme(located)
#: ``verlet`` on the GPU, the registry's default scheme.
advance_state = VERLET.advance_state

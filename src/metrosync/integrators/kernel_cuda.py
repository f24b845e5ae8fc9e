"""Fixed-step kernel for NVIDIA GPUs (numba.cuda): the same scheme and records.

One thread block per run; its threads stride over the metronomes. Each step is the
two passes of the CPU kernels, with the sums of eqs. (eqm1)–(eqm2) reduced in shared
memory; thread 0 then computes φ̈ and the disk's update. A crossing's phase is added
to the shared records with atomic adds. Everything is float64.

The physics is not written here: the functions of `_physics`, the updates of
`_kernel_parts` and ``verlet``'s hook ``begin`` (the one the CPU loops call) are
compiled again, from the same Python source, as CUDA device functions
(`device_function`). The kernel takes the CPU kernels' argument list
(`_abi`: State, Constants, Settings, Recording) plus three scratch arrays.

Status: verified in numba's CUDA simulator against the NumPy reference (see
tests/integrators/test_kernel_cuda.py); not yet run or timed on a GPU. Known limits of
this first version: one run per block (for small N most threads idle), the state
travels between host and device once per chunk of steps, no trajectories, and no dry
friction on the disk (refused with a `ParameterError`).
"""

from __future__ import annotations

import math
import types

import numpy as np
from numba import cuda, float64

from ..capabilities import require
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from . import _kernel_parts, _physics, verlet
from ._abi import Constants, Recording, State, constants_of, settings_of
from ._state import StepState

#: Threads per block, a power of two; a block holds one run.
MAX_THREADS = 256
TWO_PI = 2.0 * math.pi


def device_function(fn, **callees):
    """The CUDA device function compiled from the Python source of the CPU function
    ``fn``: a leaf of `_physics` or `_kernel_parts`, or a scheme's hook, whose calls
    ``callees`` (name → device function) then stand for the CPU functions it calls."""
    source = fn.py_func
    if callees:
        source = types.FunctionType(
            source.__code__, {**source.__globals__, **callees}, source.__name__,
            source.__defaults__, source.__closure__,
        )  # fmt: skip
    return cuda.jit(device=True)(source)


escapement = device_function(_physics.escapement)
pendulum_terms = device_function(_physics.pendulum_terms)
disk_torque = device_function(_physics.disk_torque)
applied_torque = device_function(_physics.applied_torque)
disk_acceleration = device_function(_physics.disk_acceleration)
theta_ddot = device_function(_physics.theta_ddot)
disk_velocity = device_function(_physics.disk_velocity)
drift = device_function(_kernel_parts.drift)
#: ``verlet``'s first-pass hook, the one the CPU loops call (`layouts`).
begin = device_function(verlet.begin, drift=drift, escapement=escapement)
velocity = device_function(_kernel_parts.velocity)
momentum = device_function(_kernel_parts.momentum)
upward = device_function(_kernel_parts.upward)
group_of = device_function(_kernel_parts.group_of)


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
def _add_crossing_phase(cross_re, cross_im, cross_count, b, t_prev, t_next, grid_dt, n_rec, grp):
    period = t_next - t_prev
    g0 = int(math.ceil(t_prev / grid_dt))
    g1 = min(int(math.ceil(t_next / grid_dt)), n_rec)
    for g in range(g0, g1):
        ph = TWO_PI * (g * grid_dt - t_prev) / period
        cuda.atomic.add(cross_re, (b, g, grp), math.cos(ph))
        cuda.atomic.add(cross_im, (b, g, grp), math.sin(ph))
        cuda.atomic.add(cross_count, (b, g, grp), 1)


@cuda.jit(device=True)
def _block_sum(red, k, tid, nt):
    """Tree reduction of row ``k`` of ``red`` over the block; result in red[k, 0]."""
    stride = nt // 2
    while stride > 0:
        if tid < stride:
            red[k, tid] += red[k, tid + stride]
        cuda.syncthreads()
        stride //= 2


@cuda.jit
def advance(st, c, settings, rec, scratch):
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status, last_kick, rest_steps = st  # fmt: skip  # noqa: E501
    r, cross_re, cross_im, cross_count = rec[:4]  # no trajectories on the GPU yet
    r_group, group_start = rec[8:10]
    dt, step0, n_steps, record_every, overturn_angle = settings
    th_new, rest, q = scratch
    b = cuda.blockIdx.x
    tid = cuda.threadIdx.x
    nt = cuda.blockDim.x
    n = theta.shape[1]
    n_rec = r.shape[1]
    red = cuda.shared.array((4, MAX_THREADS), float64)
    shared = cuda.shared.array(3, float64)
    dt2 = dt * dt
    grid_dt = record_every * dt
    if step0 == 0:
        _record(b, 0, theta, theta_dot, c.omega, r, red, tid, nt, status, r_group, group_start)
    for s in range(step0, step0 + n_steps):
        cuda.syncthreads()
        if status[b] & STATUS_DIVERGED:
            break
        t_old = s * dt
        sum_num = 0.0
        sum_den = 0.0
        sum_kick = 0.0
        over = 0.0
        for i in range(tid, n, nt):
            th = theta[b, i]
            tn, vp, fires, kick, _ = begin(c, (b, i), th, theta_dot[b, i], acc_theta[b, i], dt, dt2)
            if fires != 0.0:
                last_kick[b, i] = (s + 1) * dt
            if upward(th, tn):
                t_cross = t_old + dt * th / (th - tn)
                if last_up[b, i] >= 0.0:
                    _add_crossing_phase(cross_re, cross_im, cross_count, b, last_up[b, i], t_cross, grid_dt, n_rec, group_of(i, group_start))  # fmt: skip  # noqa: E501
                last_up[b, i] = t_cross
            if abs(tn) > overturn_angle:
                over = 1.0
            res, qi, num, den = pendulum_terms(c, (b, i), kick, math.sin(tn), math.cos(tn), vp)
            sum_num += num
            sum_den += den
            sum_kick += kick
            th_new[b, i] = tn
            rest[b, i] = res
            q[b, i] = qi
        red[0, tid] = sum_num
        red[1, tid] = sum_den
        red[2, tid] = sum_kick
        red[3, tid] = over
        cuda.syncthreads()
        for k in range(4):
            _block_sum(red, k, tid, nt)
        if tid == 0:
            phi_next, phd_pred = drift(phi[b], phi_dot[b], acc_phi[b], dt, dt2)
            force = disk_torque(c, b, phd_pred, red[2, 0]) + applied_torque(c, b, (s + 1) * dt)
            phdd = disk_acceleration(c, b, red[0, 0], red[1, 0], force)
            shared[0] = phdd
            shared[1] = force
            shared[2] = phi_next
            if red[3, 0] > 0.0:
                status[b] |= STATUS_OVERTURNED
            if not math.isfinite(phdd):
                status[b] |= STATUS_DIVERGED
        cuda.syncthreads()
        if status[b] & STATUS_DIVERGED:
            break
        phdd = shared[0]
        sum_p = 0.0
        for i in range(tid, n, nt):
            thdd = theta_ddot(c, (b, i), b, rest[b, i], q[b, i], phdd)
            v = velocity(theta_dot[b, i], acc_theta[b, i], thdd, dt)
            theta_dot[b, i] = v
            theta[b, i] = th_new[b, i]
            acc_theta[b, i] = thdd
            sum_p += q[b, i] * v
        red[0, tid] = sum_p
        cuda.syncthreads()
        _block_sum(red, 0, tid, nt)
        if tid == 0:
            phi[b] = shared[2]
            pinned = math.isinf(c.total_inertia[b])
            p_phi[b] = momentum(p_phi[b], force_phi[b], shared[1], dt, pinned)
            phi_dot[b] = disk_velocity(c, b, p_phi[b], red[0, 0])
            force_phi[b] = shared[1]
            acc_phi[b] = phdd
        cuda.syncthreads()
        if (s + 1) % record_every == 0:
            _record(b, (s + 1) // record_every, theta, theta_dot, c.omega, r, red, tid, nt, status, r_group, group_start)  # fmt: skip  # noqa: E501


@cuda.jit(device=True)
def _record(b, k, theta, theta_dot, omega, r, red, tid, nt, status, r_group, group_start):
    """r from the analytic phases, reduced over the block; thread 0 stores it, and
    each group's r when there are several. A run that has diverged records nothing,
    as in every other backend (the test is the same for all threads of the block, so
    none waits alone at a barrier)."""
    if status[b] & STATUS_DIVERGED:
        return
    value = _order(b, 0, theta.shape[1], theta, theta_dot, omega, red, tid, nt)
    if tid == 0:
        r[b, k] = value
    if group_start.shape[0] > 2:  # several groups
        for g in range(group_start.shape[0] - 1):
            lo = group_start[g]
            hi = group_start[g + 1]
            value = _order(b, lo, hi, theta, theta_dot, omega, red, tid, nt)
            if tid == 0:
                r_group[b, k, g] = value


@cuda.jit(device=True)
def _order(b, lo, hi, theta, theta_dot, omega, red, tid, nt):
    """r of metronomes lo..hi-1 of run ``b``, reduced over the block (valid in thread 0)."""
    re = 0.0
    im = 0.0
    for i in range(lo + tid, hi, nt):
        x = theta[b, i]
        y = -theta_dot[b, i] / omega[b, i]
        rho = math.sqrt(x * x + y * y)
        if rho > 0.0:
            re += x / rho
            im += y / rho
    red[0, tid] = re
    red[1, tid] = im
    cuda.syncthreads()
    _block_sum(red, 0, tid, nt)
    _block_sum(red, 1, tid, nt)
    out = math.sqrt(red[0, 0] ** 2 + red[1, 0] ** 2) / (hi - lo)
    cuda.syncthreads()  # every thread has read red before the next reduction reuses it
    return out


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, threads=None
):
    """Advance ``state`` on the GPU by ``n_steps`` steps; same contract as the CPU kernels.

    ``threads`` per block defaults to `threads_for` N. Trajectories are not recorded on
    the GPU in this version."""
    if state.traj_theta.shape[0]:
        raise NotImplementedError("trajectories are not recorded by the GPU backend yet")
    require("verlet/gpu", sys)
    b, n = state.theta.shape
    st = State(*(cuda.to_device(a) for a in state.kernel_state()))
    constants = Constants(*(cuda.to_device(a) for a in constants_of(sys)))
    kept = state.kernel_recording()
    grouped = state.group_start.size > 2
    # Trajectory fields, and r_group of one group: placeholders the kernel never reads.
    rec = Recording(
        *(cuda.to_device(a) for a in kept[:4]),
        *(cuda.device_array((1,) * np.ndim(a)) for a in kept[4:8]),
        cuda.to_device(kept.r_group) if grouped else cuda.device_array((1, 1, 1)),
        cuda.to_device(kept.group_start),
    )
    scratch = tuple(cuda.device_array((b, n)) for _ in range(3))
    settings = settings_of(
        dt=dt, step0=step0, n_steps=n_steps, record_every=record_every,
        overturn_angle=overturn_angle,
    )  # fmt: skip
    advance[b, threads or threads_for(n)](st, constants, settings, rec, scratch)
    back = st + rec[:4] + ((rec.r_group,) if grouped else ())
    hosts = state.kernel_state() + kept[:4] + ((kept.r_group,) if grouped else ())
    for device, host in zip(back, hosts, strict=True):
        device.copy_to_host(host)

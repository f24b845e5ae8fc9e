"""Fixed-step kernel for NVIDIA GPUs (numba.cuda): the same scheme and records.

One thread block per run; its threads stride over the metronomes. Each step is the
two passes of the CPU kernels, with the sums of eqs. (eqm1)–(eqm2) reduced in shared
memory; thread 0 then computes φ̈ and the disk's update. A crossing's phase is added
to the shared records with atomic adds. Everything is float64.

Status: verified in numba's CUDA simulator against the NumPy reference (see
tests/integrators/test_kernel_cuda.py); not yet run or timed on a GPU. Known limits of
this first version: one run per block (for small N most threads idle), and the state
travels between host and device once per chunk of steps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import cuda, float64

from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._state import RECORD_FIELDS, STATE_FIELDS, SYSTEM_FIELDS, StepState

#: Threads per block, a power of two; a block holds one run.
MAX_THREADS = 256
TWO_PI = 2.0 * math.pi


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
def _add_crossing_phase(cross_re, cross_im, cross_count, b, t_prev, t_next, grid_dt, n_rec):
    period = t_next - t_prev
    g0 = int(math.ceil(t_prev / grid_dt))
    g1 = min(int(math.ceil(t_next / grid_dt)), n_rec)
    for g in range(g0, g1):
        ph = TWO_PI * (g * grid_dt - t_prev) / period
        cuda.atomic.add(cross_re, (b, g), math.cos(ph))
        cuda.atomic.add(cross_im, (b, g), math.sin(ph))
        cuda.atomic.add(cross_count, (b, g), 1)


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
def advance(
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status,
    mh, mgh, inertia, c_theta, drive, omega, radius, c_phi, total_inertia,
    dt, step0, n_steps, record_every, overturn_angle,
    r, cross_re, cross_im, cross_count, th_new, rest, q,
):  # fmt: skip
    b = cuda.blockIdx.x
    tid = cuda.threadIdx.x
    nt = cuda.blockDim.x
    n = theta.shape[1]
    n_rec = r.shape[1]
    red = cuda.shared.array((4, MAX_THREADS), float64)
    shared = cuda.shared.array(2, float64)
    dt2 = dt * dt
    grid_dt = record_every * dt
    rad = radius[b]
    if step0 == 0:
        _record(b, 0, theta, theta_dot, omega, r, red, tid, nt, status)
    for s in range(step0, step0 + n_steps):
        cuda.syncthreads()
        if status[b] & STATUS_DIVERGED:
            break
        t_old = s * dt
        phd_pred = phi_dot[b] + acc_phi[b] * dt
        sum_num = 0.0
        sum_den = 0.0
        sum_kick = 0.0
        over = 0.0
        for i in range(tid, n, nt):
            th = theta[b, i]
            a = acc_theta[b, i]
            tn = th + theta_dot[b, i] * dt + 0.5 * a * dt2
            vp = theta_dot[b, i] + a * dt
            kick = 0.0
            if th < 0.0 and tn > 0.0:
                kick = drive[b, i] / dt
                t_cross = t_old + dt * th / (th - tn)
                if last_up[b, i] >= 0.0:
                    _add_crossing_phase(cross_re, cross_im, cross_count, b, last_up[b, i], t_cross, grid_dt, n_rec)  # fmt: skip  # noqa: E501
                last_up[b, i] = t_cross
            elif th > 0.0 and tn < 0.0:
                kick = -drive[b, i] / dt
            if abs(tn) > overturn_angle:
                over = 1.0
            sn = math.sin(tn)
            cs = math.cos(tn)
            inv_i = 1.0 / inertia[b, i]
            res = (kick - mgh[b, i] * sn - c_theta[b, i] * vp) * inv_i
            qi = mh[b, i] * cs
            sum_num += mh[b, i] * vp * vp * sn - qi * res
            sum_den += qi * qi * inv_i
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
            force = -c_phi[b] * phd_pred - red[2, 0]
            phdd = (rad * red[0, 0] + force) / (total_inertia[b] - rad * rad * red[1, 0])
            shared[0] = phdd
            shared[1] = force
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
            thdd = rest[b, i] - rad * q[b, i] / inertia[b, i] * phdd
            v = theta_dot[b, i] + 0.5 * (acc_theta[b, i] + thdd) * dt
            theta_dot[b, i] = v
            theta[b, i] = th_new[b, i]
            acc_theta[b, i] = thdd
            sum_p += q[b, i] * v
        red[0, tid] = sum_p
        cuda.syncthreads()
        _block_sum(red, 0, tid, nt)
        if tid == 0:
            phi[b] += phi_dot[b] * dt + 0.5 * acc_phi[b] * dt2
            if math.isinf(total_inertia[b]):
                phi_dot[b] = 0.0
            else:
                p_phi[b] += 0.5 * (force_phi[b] + shared[1]) * dt
                phi_dot[b] = (p_phi[b] - rad * red[0, 0]) / total_inertia[b]
            force_phi[b] = shared[1]
            acc_phi[b] = phdd
        cuda.syncthreads()
        if (s + 1) % record_every == 0:
            _record(b, (s + 1) // record_every, theta, theta_dot, omega, r, red, tid, nt, status)


@cuda.jit(device=True)
def _record(b, k, theta, theta_dot, omega, r, red, tid, nt, status):
    """r from the analytic phases, reduced over the block; thread 0 stores it."""
    n = theta.shape[1]
    re = 0.0
    im = 0.0
    for i in range(tid, n, nt):
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
    if tid == 0:
        r[b, k] = math.sqrt(red[0, 0] ** 2 + red[1, 0] ** 2) / n
    cuda.syncthreads()


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, threads=None
):
    """Advance ``state`` on the GPU by ``n_steps`` steps; same contract as the CPU kernels.

    ``threads`` per block defaults to `threads_for` N. Trajectories are not recorded on
    the GPU in this version."""
    if state.traj_theta.shape[0]:
        raise NotImplementedError("trajectories are not recorded by the GPU backend yet")
    b, n = state.theta.shape
    dev = {name: cuda.to_device(getattr(state, name)) for name in STATE_FIELDS + RECORD_FIELDS}
    consts = [cuda.to_device(np.ascontiguousarray(getattr(sys, name))) for name in SYSTEM_FIELDS]
    scratch = [cuda.device_array((b, n)) for _ in range(3)]
    advance[b, threads or threads_for(n)](
        *(dev[name] for name in STATE_FIELDS), *consts,
        float(dt), int(step0), int(n_steps), int(record_every), float(overturn_angle),
        *(dev[name] for name in RECORD_FIELDS), *scratch,
    )  # fmt: skip
    for name in STATE_FIELDS + RECORD_FIELDS:
        dev[name].copy_to_host(getattr(state, name))

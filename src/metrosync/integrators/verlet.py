"""The paper's fixed-step "velocity Verlet-type" integrator, compiled with numba.

The scheme, per step of length dt (state x = (φ, θ), velocities v, accelerations a):

1. positions   x' = x + v dt + a dt²/2
2. kick        𝕄_i = +M/dt if θ_i < 0 < θ_i', −M/dt if θ_i > 0 > θ_i', else 0
               (the paper's discrete escapement, §4)
3. forces      a' = f(x', v*, 𝕄), eqs. (eqm1)–(eqm2), evaluated with the *predicted*
               velocities v* = v + a dt: that is how the velocity-dependent terms
               (friction, the θ̇² sin θ term, c_φ φ̇) enter the explicit scheme
4. velocities  θ̇' = θ̇ + (a + a') dt/2
5. disk        p_φ' = p_φ + (F + F') dt/2 with F = −c_φ φ̇* − Σ𝕄 the external torque on
               the disk, and φ̇' recovered from p_φ' = (J + R²Σm) φ̇' + R Σ m h cos θ' θ̇'.
               Without friction and drive p_φ is then conserved to rounding.

Because a' carries the kick, the impulse M/I enters the velocities in two halves, one
in this step and one in the next: the total momentum transfer is M, as in the paper.
Without kicks the scheme is second order; kicks quantise the impulse to the step, so
ensemble statistics converge to the ``exact`` integrator at first order in dt.

The same step also records, for each run, the analytic-phase order parameter and the
running sums of the crossing-interpolated phase (MODEL-NOTES "Observables").
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._state import STATUS_DIVERGED, STATUS_OVERTURNED, StepState

TWO_PI = 2.0 * math.pi


@nb.njit(cache=True, inline="always")
def _add_crossing_phase(cross_re, cross_im, cross_count, b, t_prev, t_next, grid_dt, n_rec):
    """Add e^{iΦ} for grid times in [t_prev, t_next), Φ rising linearly 0 → 2π."""
    period = t_next - t_prev
    g0 = int(math.ceil(t_prev / grid_dt))
    g1 = min(int(math.ceil(t_next / grid_dt)), n_rec)
    for g in range(g0, g1):
        ph = TWO_PI * (g * grid_dt - t_prev) / period
        cross_re[b, g] += math.cos(ph)
        cross_im[b, g] += math.sin(ph)
        cross_count[b, g] += 1


@nb.njit(parallel=True, cache=True)
def advance(
    theta, theta_dot, phi, phi_dot, acc_theta, acc_phi, p_phi, force_phi, last_up, status,
    mh, mgh, inertia, c_theta, drive, omega, radius, c_phi, total_inertia,
    dt, step0, n_steps, record_every, overturn_angle,
    r, cross_re, cross_im, cross_count,
    traj_theta, traj_theta_dot, traj_phi, traj_phi_dot,
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
                    if last_up[b, i] >= 0.0:
                        _add_crossing_phase(cross_re, cross_im, cross_count, b,
                                            last_up[b, i], t_cross, grid_dt, n_rec)  # fmt: skip
                    last_up[b, i] = t_cross
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


@nb.njit(cache=True, inline="always")
def _record(b, k, theta, theta_dot, phi, phi_dot, omega, r, save,
            traj_theta, traj_theta_dot, traj_phi, traj_phi_dot):  # fmt: skip
    """Store r from the analytic phase Φ = atan2(−θ̇/ω, θ) and, if asked, the state."""
    n = theta.shape[1]
    re = 0.0
    im = 0.0
    for i in range(n):
        x = theta[b, i]
        y = -theta_dot[b, i] / omega[b, i]
        rho = math.sqrt(x * x + y * y)
        if rho > 0.0:
            re += x / rho
            im += y / rho
    r[b, k] = math.sqrt(re * re + im * im) / n
    if save:
        for i in range(n):
            traj_theta[b, k, i] = theta[b, i]
            traj_theta_dot[b, k, i] = theta_dot[b, i]
        traj_phi[b, k] = phi[b]
        traj_phi_dot[b, k] = phi_dot[b]


def advance_state(state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle):
    """Typed front of `advance` for one chunk of steps."""
    advance(
        state.theta, state.theta_dot, state.phi, state.phi_dot, state.acc_theta, state.acc_phi,
        state.p_phi, state.force_phi, state.last_up, state.status,
        sys.mh, sys.mgh, sys.inertia, sys.c_theta, sys.drive, sys.omega,
        sys.radius, sys.c_phi, sys.total_inertia,
        float(dt), int(step0), int(n_steps), int(record_every), float(overturn_angle),
        state.r, state.cross_re, state.cross_im, state.cross_count,
        state.traj_theta, state.traj_theta_dot, state.traj_phi, state.traj_phi_dot,
    )  # fmt: skip

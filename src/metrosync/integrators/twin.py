"""The NumPy twin of the fixed-step schemes: one step function, every scheme.

Plain NumPy, vectorised over runs and metronomes, the same steps and records as the
compiled loops (`layout_runs`, `layout_metronomes`). It is the oracle they are tested
against, so that a kernel's indexing, memory layout or parallel writes cannot go wrong
unnoticed, and the baseline the benchmarks compare them with. Its smooth forces come
from `equations`, the one vectorised statement of eqs. (eqm1)–(eqm2).

A scheme is told apart only where the compiled loops take its hooks (`layouts`): how
the escapement's firing becomes a torque over the step (``verlet``, ±M/dt) or an
impulse at its located instant (``located``; each impulse's pieces from the compiled
scalar `_located_parts.kick` and `_physics.disk_acceleration`, called once per
impulse; the physics of an impulse is checked against ``exact`` instead,
tests/integrators/test_located.py). `VERLET` and `LOCATED` are the two.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..capabilities import require
from ..equations import (
    SystemArrays,
    accelerations,
    disk_torque,
    dry_friction,
    effective_inertia,
    escapement,
    holding_torque,
)
from ..status import STATUS_DIVERGED, STATUS_OVERTURNED
from ._abi import constants_of
from ._located_parts import kick
from ._physics import disk_acceleration
from ._state import StepState


@dataclass(frozen=True)
class TwinScheme:
    """A fixed-step scheme as the twin runs it: ``impulsive`` schemes apply the
    escapement as an impulse at its located instant, the others as a torque ±M/dt
    over the step."""

    name: str
    impulsive: bool

    def begin(self, sys: SystemArrays, fires: np.ndarray, dt: float):
        """The escapement's torque over the step and its impulses (N m s), (B, N):
        the twin of the compiled hook ``begin``."""
        if self.impulsive:
            return np.zeros_like(fires), fires * sys.drive
        return fires * (sys.drive * (1.0 / dt)), np.zeros_like(fires)

    def advance_state(
        self,
        state: StepState,
        sys: SystemArrays,
        *,
        dt: float,
        step0: int,
        n_steps: int,
        record_every: int,
        overturn_angle: float,
    ) -> None:
        """Advance every run by ``n_steps`` steps from step ``step0``, in place."""
        require(f"{self.name}/numpy", sys)
        flat = sys.one_coordinate()
        n_rec = state.r.shape[1]
        step: _Step | _CoordinatesStep
        if flat is None:  # a platform of several coordinates
            step = _CoordinatesStep(sys, self, dt, record_every, overturn_angle, n_rec)
        else:  # one coordinate: the scheme as the kernels run it, on the same arrays
            step = _Step(flat, self, dt, record_every, overturn_angle, n_rec, constants_of(sys))
            state = state.one_coordinate()
        if step0 == 0:
            _record(state, 0, sys.omega, (state.status & STATUS_DIVERGED) == 0)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for s in range(step0, step0 + n_steps):
                if not step(state, s):
                    break


@dataclass
class _StepSettings:
    """What a step of either kind is told: the model, the scheme and the step's
    settings."""

    sys: SystemArrays
    scheme: TwinScheme
    dt: float
    record_every: int
    overturn_angle: float
    n_rec: int
    #: the records' spacing, s
    grid_dt: float = field(init=False)

    def __post_init__(self) -> None:
        self.grid_dt = self.record_every * self.dt

    def __call__(self, state: StepState, s: int) -> bool:
        """Step ``s`` of every run still alive; False when none is."""
        alive = (state.status & STATUS_DIVERGED) == 0
        if not alive.any():
            return False
        self._advance(state, s, alive, _predicted(self, state, s, alive))
        return True

    def _advance(self, state: StepState, s: int, alive: np.ndarray, first: tuple) -> None:
        """The rest of the step after its first pass ``first`` (`_predicted`)."""
        raise NotImplementedError

    def _book_crossings(self, state, th, th_new, ok, t_old) -> None:
        """The phase's upward zero crossings in the step, at their linear instants."""
        up = (th < 0) & (th_new > 0) & ok[:, None]
        for b, i in zip(*np.nonzero(up), strict=True):
            t_cross = t_old + self.dt * th[b, i] / (th[b, i] - th_new[b, i])
            if state.last_up[b, i] >= 0:
                grp = np.searchsorted(state.group_start, i, side="right") - 1
                _add_crossing_phase(
                    state, b, grp, state.last_up[b, i], t_cross, self.grid_dt, self.n_rec
                )
            state.last_up[b, i] = t_cross


@dataclass
class _Step(_StepSettings):
    """One step of ``scheme`` for every run, a platform of one coordinate with its
    constants per run (`SystemArrays.one_coordinate`, the state's `StepState.one_coordinate`);
    what does not change between steps is computed once."""

    constants: tuple

    def __post_init__(self) -> None:
        sys = self.sys
        self.rigid = np.isinf(sys.total_inertia)
        self.dry = (sys.dry_friction > 0) & ~self.rigid
        super().__post_init__()

    def _advance(self, state: StepState, s: int, alive: np.ndarray, first: tuple) -> None:
        sys, dt = self.sys, self.dt
        half = 0.5 * dt
        t_old, t_new, th, thd, acc, th_new, vel_pred, phd_pred, phi_new, torque, kicks = first

        forces = (sys, th_new, vel_pred, phd_pred, torque, t_new)
        others = disk_torque(sys, phd_pred, torque, t_new)
        friction, held = self._dry_friction(state.phi_dot, forces)
        phdd, thdd = accelerations(*forces, friction=friction)
        diverged = ~np.isfinite(phdd) & alive
        state.status[diverged] |= STATUS_DIVERGED
        ok = alive & ~diverged
        force = others + friction
        self._book_crossings(state, th, th_new, ok, t_old)
        q_new = sys.mh * np.cos(th_new)
        through_disk = sys.lever[:, None] * (1.0 / sys.inertia)
        own, own_change, after, jump, shift, change, momentum_jump = self._impulses(
            state, kicks, th, th_new, ok, q_new
        )

        # Finish the step. Every pendulum's jump through the disk, −R q Δφ̇/I (eq. (eqm2)
        # for an impulse), with q at the step's end; all 0 for a step without impulses.
        thdd = thdd + own_change - through_disk * q_new * change[:, None]
        new_theta_dot = (
            thd
            + own
            + (after - half) * own_change
            + 0.5 * (acc + thdd) * dt
            - through_disk * q_new * jump[:, None]
        )
        new_theta = th_new + after * own - through_disk * q_new * shift[:, None]
        phdd = phdd + change
        new_p = state.p_phi + 0.5 * (state.force_phi + force) * dt + momentum_jump
        stopping = (
            self.dry & ~held & (friction * _disk_velocity(sys, new_p, th_new, new_theta_dot) >= 0)
        )
        if stopping.any():  # rare: the disk's velocity reached 0 within the step
            end, stops = _friction_at_stop(sys, friction, new_p, th_new, new_theta_dot, dt)
            end = np.where(stopping, end, friction)
            stops &= stopping
            mean_phdd, mean_thdd = accelerations(*forces, friction=end)
            new_theta_dot = thd + 0.5 * (acc + mean_thdd) * dt
            new_p = state.p_phi + 0.5 * (state.force_phi + others + end) * dt
            at_rest, _ = self._dry_friction(np.zeros_like(state.phi_dot), forces)
            friction = np.where(stops, at_rest, end)
            phdd, thdd = accelerations(*forces, friction=friction)
            force = others + friction
            held |= stops
        coupling = sys.lever * np.sum(q_new * new_theta_dot, axis=1)
        new_p = np.where(held, coupling, new_p)  # a disk at rest: p_φ = R Σ m h cos θ θ̇
        state.rest_steps[held & ok] += 1
        with np.errstate(invalid="ignore"):
            new_phi_dot = np.where(self.rigid, 0.0, (new_p - coupling) / sys.total_inertia)

        ok2 = ok[:, None]
        state.phi[ok] = (phi_new + shift)[ok]
        state.theta[...] = np.where(ok2, new_theta, th)
        state.theta_dot[...] = np.where(ok2, new_theta_dot, thd)
        state.acc_theta[...] = np.where(ok2, thdd, acc)
        state.p_phi[ok] = np.where(self.rigid, state.p_phi, new_p)[ok]
        state.phi_dot[ok] = new_phi_dot[ok]
        state.force_phi[ok] = force[ok]
        state.acc_phi[ok] = phdd[ok]
        if (s + 1) % self.record_every == 0:
            _record(state, (s + 1) // self.record_every, sys.omega, ok)

    def _dry_friction(self, phi_dot, forces):
        """The disk's dry friction as a step starts resolving the disk, (B,), and where it
        holds the disk at rest (the twin of `_physics.disk_friction`); 0 where it is off."""
        sys, dry = self.sys, self.dry
        if not dry.any():
            return np.zeros_like(phi_dot), np.zeros(phi_dot.shape, dtype=bool)
        holding = holding_torque(*forces)
        friction = np.where(dry, dry_friction(sys, phi_dot, holding), 0.0)
        return friction, dry & (phi_dot == 0) & (np.abs(holding) <= sys.dry_friction)

    def _impulses(self, state, kicks, th, th_new, ok, q_new):
        """Each impulse at its instant (`_located_parts.kick` gives its pieces, summed
        as the compiled loops sum them) and the disk's jumps that follow from the sums:
        the pendulums' own jumps and their forces' change, the time left after each
        impulse (N, B), the disk's velocity jump, the distance it travels and the change
        of φ̈ (B,), and the disk's momentum jump (B,). Zeros without impulses."""
        sys, dt, c = self.sys, self.dt, self.constants
        runs = th.shape[0]
        own, own_change, after = (np.zeros_like(th) for _ in range(3))
        jump, shift, change = (np.zeros(runs) for _ in range(3))
        kicked = (kicks != 0.0) & ok[:, None]
        if not kicked.any():
            return own, own_change, after, jump, shift, change, np.zeros(runs)
        half = 0.5 * dt
        frac = np.where(kicked, (th - sys.escapement_offset) / (th - th_new), 0.0)
        after = np.where(kicked, dt - frac * dt, 0.0)
        sums = np.zeros((runs, 5))
        for b, i in zip(*np.nonzero(kicked), strict=True):
            dv, dnum, dforce, jrest, jnum = kick(c, (b, i), b, kicks[b, i], state.theta_dot[b, i])
            own[b, i] = dv
            own_change[b, i] = jrest
            a = after[b, i]
            sums[b] += [dnum + (a - half) * jnum, dforce, a * dnum, a * dforce, jnum]
        den = np.sum(q_new * q_new * (1.0 / sys.inertia), axis=1)
        for b in np.nonzero(kicked.any(axis=1))[0]:
            jump[b] = disk_acceleration(c, b, sums[b, 0], den[b], sums[b, 1])
            shift[b] = disk_acceleration(c, b, sums[b, 2], den[b], sums[b, 3])
            change[b] = disk_acceleration(c, b, sums[b, 4], den[b], 0.0)
        return own, own_change, after, jump, shift, change, np.where(self.rigid, 0.0, sums[:, 1])


@dataclass
class _CoordinatesStep(_StepSettings):
    """One step of ``scheme`` for a platform of P coordinates (`equations`): the same
    scheme as `_Step` (positions by Taylor, the platform's momentum by the trapezoid
    of its forces, φ̇ from it), for the escapement as a torque over the step; no dry
    friction (a law of one coordinate)."""

    def __post_init__(self) -> None:
        if self.scheme.impulsive:  # refused by name before (`capabilities.require`)
            raise ValueError(f"{self.scheme.name!r} has a platform of one coordinate only")
        self.rigid = np.any(np.isinf(self.sys.total_inertia), axis=(1, 2))
        super().__post_init__()

    def _advance(self, state: StepState, s: int, alive: np.ndarray, first: tuple) -> None:
        sys, dt = self.sys, self.dt
        t_old, t_new, th, thd, acc, th_new, vel_pred, phd_pred, phi_new, torque, _ = first
        phdd, thdd = accelerations(sys, th_new, vel_pred, phd_pred, torque, t_new)
        force = disk_torque(sys, phd_pred, torque, t_new)
        diverged = ~np.all(np.isfinite(phdd), axis=1) & alive
        state.status[diverged] |= STATUS_DIVERGED
        ok = alive & ~diverged
        self._book_crossings(state, th, th_new, ok, t_old)
        new_theta_dot = thd + 0.5 * (acc + thdd) * dt
        new_p = state.p_phi + 0.5 * (state.force_phi + force) * dt
        q = sys.mh * np.cos(th_new) * new_theta_dot
        coupling = np.einsum("bnp,bn->bp", sys.lever, q)
        inertia = np.where(self.rigid[:, None, None], np.eye(sys.coordinates), sys.total_inertia)
        inertia = np.where(np.isfinite(inertia), inertia, 1.0)
        new_phi_dot = np.linalg.solve(inertia, (new_p - coupling)[..., None])[..., 0]
        new_phi_dot[self.rigid] = 0.0

        ok2 = ok[:, None]
        state.phi[...] = np.where(ok2, phi_new, state.phi)
        state.theta[...] = np.where(ok2, th_new, th)
        state.theta_dot[...] = np.where(ok2, new_theta_dot, thd)
        state.acc_theta[...] = np.where(ok2, thdd, acc)
        state.p_phi[...] = np.where(ok2 & ~self.rigid[:, None], new_p, state.p_phi)
        state.phi_dot[...] = np.where(ok2, new_phi_dot, state.phi_dot)
        state.force_phi[...] = np.where(ok2, force, state.force_phi)
        state.acc_phi[...] = np.where(ok2, phdd, state.acc_phi)
        if (s + 1) % self.record_every == 0:
            _record(state, (s + 1) // self.record_every, sys.omega, ok)


#: The twins of the two fixed-step schemes.
VERLET = TwinScheme("verlet", impulsive=False)
LOCATED = TwinScheme("located", impulsive=True)


def _predicted(step, state: StepState, s: int, alive: np.ndarray) -> tuple:
    """The first pass of step ``s``, shared by both steps: (t_old, t_new, θ, θ̇, θ̈, θ
    new, θ̇ and φ̇ predicted, φ new, the escapement's torque and kicks); marks the
    escapements that fired and the runs that overturned."""
    sys, dt = step.sys, step.dt
    t_old, t_new = s * dt, (s + 1) * dt
    th, thd, acc = state.theta, state.theta_dot, state.acc_theta
    th_new = th + thd * dt + 0.5 * acc * (dt * dt)
    vel_pred = thd + acc * dt
    phd_pred = state.phi_dot + state.acc_phi * dt
    phi_new = state.phi + state.phi_dot * dt + 0.5 * state.acc_phi * (dt * dt)
    fires = np.where(alive[:, None], escapement(sys, th, th_new), 0.0)
    torque, kicks = step.scheme.begin(sys, fires, dt)
    state.last_kick[fires != 0.0] = t_new
    overturned = np.any(np.abs(th_new) > step.overturn_angle, axis=1) & alive
    state.status[overturned] |= STATUS_OVERTURNED
    return t_old, t_new, th, thd, acc, th_new, vel_pred, phd_pred, phi_new, torque, kicks


def _disk_velocity(sys, p_phi, theta, theta_dot):
    coupling = sys.lever * np.sum(sys.mh * np.cos(theta) * theta_dot, axis=1)
    with np.errstate(invalid="ignore"):
        return (p_phi - coupling) / sys.total_inertia


def _friction_at_stop(sys, friction, p_phi, theta, theta_dot, dt):
    """The twin of `_physics.disk_friction_stop`: the friction's end value that brings the
    disk to rest, where it is within ±T (then True), else the reversed friction."""
    stop = (
        friction
        - 2.0 * effective_inertia(sys, theta) * _disk_velocity(sys, p_phi, theta, theta_dot) / dt
    )
    stops = np.abs(stop) <= sys.dry_friction
    return np.where(stops, stop, -friction), stops


def _add_crossing_phase(state, b, grp, t_prev, t_next, grid_dt, n_rec):
    g = np.arange(int(np.ceil(t_prev / grid_dt)), min(int(np.ceil(t_next / grid_dt)), n_rec))
    phase = 2 * np.pi * (g * grid_dt - t_prev) / (t_next - t_prev)
    state.cross_re[b, g, grp] += np.cos(phase)
    state.cross_im[b, g, grp] += np.sin(phase)
    state.cross_count[b, g, grp] += 1


def _record(state: StepState, k: int, omega: np.ndarray, which: np.ndarray) -> None:
    x = state.theta
    y = -state.theta_dot / omega
    rho = np.hypot(x, y)
    safe = np.where(rho > 0, rho, 1.0)
    unit = np.where(rho > 0, (x + 1j * y) / safe, 0.0)
    r = np.abs(unit.sum(axis=1)) / x.shape[1]
    state.r[which, k] = r[which]
    if state.group_start.size > 2:  # several groups
        bounds = state.group_start
        for g, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
            state.r_group[which, k, g] = (np.abs(unit[:, lo:hi].sum(axis=1)) / (hi - lo))[which]
    if state.traj_theta.shape[0]:
        state.traj_theta[which, k] = x[which]
        state.traj_theta_dot[which, k] = state.theta_dot[which]
        state.traj_phi[which, k] = state.phi[which]
        state.traj_phi_dot[which, k] = state.phi_dot[which]

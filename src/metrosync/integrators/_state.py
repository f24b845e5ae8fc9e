"""Mutable integration state and recording buffers of a fixed-step ensemble run.

Both fixed-step backends (the compiled kernel and its NumPy twin) advance the same
`StepState` in place, chunk after chunk, so that a driver can show progress and
memory stays independent of the duration: only records every ``record_every`` steps
are kept. Layouts are run-major, (B, ...), for locality inside a run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..equations import SystemArrays, accelerations, disk_torque, dry_friction, holding_torque
from ..observables.mechanics import platform_momentum
from ..status import STATUS_DIVERGED, STATUS_OK
from ._abi import Recording, State

#: Which of `StepState`'s two tuples holds each field.
_PART_OF = {
    **dict.fromkeys(Recording._fields, "recording"),
    **dict.fromkeys(State._fields, "state"),
}


@dataclass
class StepState:
    """State (B runs × N metronomes) and record buffers, advanced in place: the
    kernels' `State` and `Recording` tuples, whose fields read as attributes
    (``step_state.theta`` is ``step_state.state.theta``).

    theta, theta_dot, acc_theta : (B, N)
    phi, phi_dot, acc_phi : (B, P), the platform's P coordinates (P = 1: the disk, the
        board).
    p_phi : (B, P) the platform's momentum M φ̇ + Σ_i ℓ_i m_i h_i cos θ_i θ̇_i (for the
        disk (J + R²Σm) φ̇ + R Σ m h cos θ θ̇), carried as state so that it changes only
        by the external torque impulse.
    force_phi : (B, P) torque on the disk at the last evaluation, −c_φ φ̇ − Σ𝕄 + τ(t)
        (`equations.disk_torque`) plus the dry friction (`equations.dry_friction`).
    last_up : (B, N) time of the last upward zero crossing, −1 before the first.
    status : (B,) int8 bit flags.
    last_kick : (B, N) end time of the last step in which the metronome's escapement
        fired (its impulse), −1 before the first: `observables.death` reads it.
    rest_steps : (B,) int64 count of steps that ended with the disk held at rest by its
        dry friction (0 without dry friction).
    r : (B, n_rec) analytic-phase order parameter at each record.
    cross_re, cross_im, cross_count : (B, n_rec, G) running sums of e^{iΦ} over each
        group's metronomes whose crossing-interpolated phase Φ is known at each record.
    traj_* : trajectories (B, n_rec, N) and, of the platform, (B, n_rec, P), or
        (0, 0, 0) placeholders.
    r_group : (B, n_rec, G) each group's analytic-phase r, or a (0, 0, 0) placeholder
        for a single group (its r is ``r``).
    group_start : (G + 1,) group g is metronomes group_start[g] .. group_start[g+1]-1.
    """

    state: State
    recording: Recording

    def __getattr__(self, name: str):
        # Called only for names the dataclass itself lacks; vars() rather than
        # attributes, so that an instance without fields yet (copy, pickle) does not recurse.
        # The NumPy twin reads fields this way some forty times a step: one dict lookup.
        part = vars(self).get(_PART_OF.get(name, ""))
        if part is None:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        return getattr(part, name)

    @classmethod
    def start(
        cls,
        sys: SystemArrays,
        theta0: np.ndarray,
        theta_dot0: np.ndarray,
        phi0: np.ndarray,
        phi_dot0: np.ndarray,
        *,
        n_records: int,
        trajectories: bool,
        group_start: np.ndarray | None = None,
    ) -> StepState:
        """The state at t = 0 and empty records; ``group_start`` bounds the groups
        (default: all N metronomes one group). ``phi0`` and ``phi_dot0`` are (B, P), or
        (B,) for every coordinate alike."""
        b, n = theta0.shape
        p = sys.coordinates
        bounds = np.array([0, n] if group_start is None else group_start, dtype=np.int64)
        if bounds[0] != 0 or bounds[-1] != n or np.any(np.diff(bounds) < 1):
            raise ValueError(f"group_start {bounds} does not split {n} metronomes into groups")
        n_groups = bounds.size - 1
        theta = np.array(theta0, dtype=float, order="C")
        theta_dot = np.array(theta_dot0, dtype=float, order="C")
        phi_dot = _coordinates(phi_dot0, b, p)
        rigid = np.any(np.isinf(sys.total_inertia), axis=(1, 2))
        phi_dot[rigid] = 0.0
        no_kick = np.zeros_like(theta)
        # A run may diverge from its very start; it is flagged, not raised.
        with np.errstate(over="ignore", invalid="ignore"):
            acc_phi, acc_theta = accelerations(sys, theta, theta_dot, phi_dot, no_kick)
            p_phi = platform_momentum(sys, theta, theta_dot, phi_dot)
            holding = holding_torque(sys, theta, theta_dot, phi_dot, no_kick)
            friction = np.where(rigid[:, None], 0.0, dry_friction(sys, phi_dot, holding))
        finite = np.all(np.isfinite(acc_phi), axis=1) & np.all(np.isfinite(acc_theta), axis=1)
        traj_shape = (b, n_records, n) if trajectories else (0, 0, 0)
        platform_shape = (b, n_records, p) if trajectories else (0, 0, p)
        state = State(
            theta=theta,
            theta_dot=theta_dot,
            phi=_coordinates(phi0, b, p),
            phi_dot=phi_dot,
            acc_theta=np.ascontiguousarray(acc_theta),
            acc_phi=np.ascontiguousarray(acc_phi),
            p_phi=p_phi,
            force_phi=disk_torque(sys, phi_dot, no_kick, 0.0) + friction,
            last_up=np.full((b, n), -1.0),
            status=np.where(finite, STATUS_OK, STATUS_DIVERGED).astype(np.int8),
            last_kick=np.full((b, n), -1.0),
            rest_steps=np.zeros(b, dtype=np.int64),
        )
        recording = Recording(
            r=np.full((b, n_records), np.nan),
            cross_re=np.zeros((b, n_records, n_groups)),
            cross_im=np.zeros((b, n_records, n_groups)),
            cross_count=np.zeros((b, n_records, n_groups), dtype=np.int32),
            traj_theta=np.full(traj_shape, np.nan),
            traj_theta_dot=np.full(traj_shape, np.nan),
            traj_phi=np.full(platform_shape, np.nan),
            traj_phi_dot=np.full(platform_shape, np.nan),
            r_group=np.full((b, n_records, n_groups) if n_groups > 1 else (0, 0, 0), np.nan),
            group_start=bounds,
        )
        return cls(state, recording)

    @property
    def coordinates(self) -> int:
        """P, the number of the platform's coordinates."""
        return self.state.phi.shape[1]

    def kernel_state(self) -> State:
        """The state arrays as the kernels take them: the same arrays, not copies, the
        platform's seen as its one coordinate, (B,) views of the (B, 1) arrays.
        `ValueError` for a platform of more than one coordinate (refused by name before,
        `capabilities.require`)."""
        self._one_coordinate()
        s = self.state
        return s._replace(**{name: getattr(s, name)[:, 0] for name in PLATFORM_STATE})

    def kernel_recording(self) -> Recording:
        """The record buffers as the kernels take them (the same arrays; the platform's
        trajectories (B, n_rec) views)."""
        self._one_coordinate()
        r = self.recording
        return r._replace(traj_phi=r.traj_phi[:, :, 0], traj_phi_dot=r.traj_phi_dot[:, :, 0])

    def one_coordinate(self) -> StepState:
        """This state as the kernels see it (`kernel_state`, `kernel_recording`), for a
        scheme written for one coordinate: the same arrays."""
        return StepState(self.kernel_state(), self.kernel_recording())

    def _one_coordinate(self) -> None:
        if self.coordinates != 1:  # refused by name before (`capabilities.require`)
            raise ValueError(
                f"the kernels' state is for a platform of one coordinate, not {self.coordinates}"
            )

    def crossing_order(self) -> np.ndarray:
        """r from crossing-interpolated phases, (B, n_rec); NaN where some metronome
        has no phase (before its first or after its last upward crossing)."""
        n = self.theta.shape[1]
        with np.errstate(invalid="ignore"):
            r = np.hypot(self.cross_re.sum(axis=2), self.cross_im.sum(axis=2)) / n
        return np.where(self.cross_count.sum(axis=2) == n, r, np.nan)

    def group_crossing_order(self) -> np.ndarray:
        """Each group's `crossing_order`, (B, n_rec, G)."""
        size = np.diff(self.group_start)
        with np.errstate(invalid="ignore"):
            r = np.hypot(self.cross_re, self.cross_im) / size
        return np.where(self.cross_count == size, r, np.nan)

    def group_order(self) -> np.ndarray:
        """Each group's analytic-phase r, (B, n_rec, G)."""
        return self.r_group if self.group_start.size > 2 else self.r[:, :, None]


@dataclass
class Records:
    """What an integrator hands back, per run: arrays (B, n_rec[, N]) and (B,); the
    groups' r and r_crossing are (B, n_rec, G)."""

    r: np.ndarray
    r_crossing: np.ndarray
    status: np.ndarray
    theta: np.ndarray | None = None
    theta_dot: np.ndarray | None = None
    #: (B, n_rec) for a platform of one coordinate, (B, n_rec, P) for more.
    phi: np.ndarray | None = None
    phi_dot: np.ndarray | None = None
    #: per run, N lists of upward-crossing times (integrators that keep them all).
    crossings: list | None = None
    r_group: np.ndarray | None = None
    r_crossing_group: np.ndarray | None = None
    #: (B, N) time of each metronome's last escapement impulse, −1 if none.
    last_kick: np.ndarray | None = None
    #: (B,) time the disk was held at rest by dry friction in the final window, s (set
    #: by the driver, which knows the window).
    rest_time: np.ndarray | None = None


#: The platform's fields of `State`, (B, P).
PLATFORM_STATE = ("phi", "phi_dot", "acc_phi", "p_phi", "force_phi")


def _coordinates(value, runs: int, p: int) -> np.ndarray:
    """A (B, P) float array (a copy) of ``value``, (B, P) or (B,) for every coordinate."""
    value = np.asarray(value, dtype=float)
    if value.ndim == 1:
        value = value[:, None]
    return np.array(np.broadcast_to(value, (runs, p)), dtype=float)


def platform_records(value: np.ndarray | None) -> np.ndarray | None:
    """The platform's trajectory as records keep it: (B, n_rec) for one coordinate
    (as it always was), (B, n_rec, P) for more."""
    if value is None or value.shape[-1] > 1:
        return value
    return value[..., 0]


def records_of(state: StepState) -> Records:
    traj = state.traj_theta.shape[0] > 0
    r_crossing = state.crossing_order()
    grouped = state.group_start.size > 2
    return Records(
        r=state.r,
        r_crossing=r_crossing,
        status=state.status,
        theta=state.traj_theta if traj else None,
        theta_dot=state.traj_theta_dot if traj else None,
        phi=platform_records(state.traj_phi) if traj else None,
        phi_dot=platform_records(state.traj_phi_dot) if traj else None,
        # One group: views of the global records, no copies.
        r_group=state.group_order(),
        r_crossing_group=state.group_crossing_order() if grouped else r_crossing[:, :, None],
        last_kick=state.last_kick,
    )

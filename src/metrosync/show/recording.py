"""One recorded run, ready to be shown: extraction, checks and interpolation.

Every view (animation, sound, page, plots) reads a run through `RecordedRun`, so
all of them show the same numbers: the trajectories that `simulate` recorded, never
a second simulation. Between records, θ and φ are interpolated with cubic Hermite
polynomials that use the recorded velocities θ̇ and φ̇, which keeps a pendulum's
swing smooth even when records are several steps apart.

Geometry (a display convention; the equations do not depend on it): metronome i sits
on the rim at angle α_i = 2π i / N from the x axis, and the disk turns by φ. On the
board (``platform == "board"``, the dataset's attribute) the metronomes stand in a row
along it and φ is the board's position, m.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import MetrosyncError, ParameterError


class NoTrajectoriesError(MetrosyncError, ValueError):
    """The dataset has no recorded trajectories (θ, θ̇, φ, φ̇) to show."""


@dataclass(frozen=True)
class RecordedRun:
    """The trajectories of one run of a simulated dataset.

    time : (T,) record times, s.
    theta, theta_dot : (T, N) pendulum angles (rad) and velocities (rad/s).
    phi, phi_dot : (T,) disk angle (rad) and velocity (rad/s), or on the board its
        position (m) and velocity (m/s).
    r : (T,) analytic-phase order parameter.
    r_crossing : (T,) crossing-phase order parameter (NaN where undefined).
    omega : (N,) natural angular frequencies, rad/s (ω = π·BPM/60).
    radius : disk radius, m (the dataset's; the default disk's on the board).
    step : integration time step dt, s.
    equilibrium_window : length of the final window that r_eq averages, s.
    r_eq : equilibrium r of this run (crossing phases), NaN if undefined.
    run : index of the run in the dataset.
    attrs : the dataset's attributes.
    escapement_offset : (N,) angle δ_i at which each metronome's escapement acts, rad;
        None for 0, the vertical (see `tick_angles`).
    platform : ``"disk"`` or ``"board"`` (the dataset's ``platform`` attribute; a
        dataset from before the board has none and is the disk's).
    """

    time: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    phi: np.ndarray
    phi_dot: np.ndarray
    r: np.ndarray
    r_crossing: np.ndarray
    omega: np.ndarray
    radius: float
    step: float
    equilibrium_window: float
    r_eq: float
    run: int
    attrs: dict
    escapement_offset: np.ndarray | None = None
    platform: str = "disk"

    @classmethod
    def from_dataset(cls, ds, run: int = 0) -> RecordedRun:
        """Pick run ``run`` of a dataset from `metrosync.simulate` with trajectories.

        Raises `NoTrajectoriesError` when θ was not recorded and `ParameterError` for
        a run index out of range or a run that diverged. Warns (`UserWarning`) for an
        overturned run, which is still shown.
        """
        if "theta" not in ds or "phi" not in ds:
            raise NoTrajectoriesError(
                "the dataset holds no trajectories (theta, phi); simulate with "
                "`trajectories=True` (CLI: `--save-every K`)."
            )
        run = check_run(run, ds.sizes["run"])
        status = int(ds.status.values[run]) if "status" in ds else 0
        if status & 2:
            raise ParameterError(
                f"run {run} diverged (status {status}); its trajectory stops early. "
                f"Choose another `run` or a smaller time step."
            )
        if status & 1:
            warnings.warn(
                f"run {run} overturned: some pendulum swung past the horizontal.",
                UserWarning,
                stacklevel=2,
            )
        sel = ds.isel(run=run)
        step = float(ds.attrs.get("dt", np.nan))
        window = float(ds.attrs.get("equilibrium_window", np.nan))
        r_eq = float(sel.r_eq.values) if "r_eq" in sel else math.nan
        return cls(
            time=np.asarray(ds.time.values, dtype=float),
            theta=np.asarray(sel.theta.values, dtype=float),
            theta_dot=np.asarray(sel.theta_dot.values, dtype=float),
            phi=np.asarray(sel.phi.values, dtype=float),
            phi_dot=np.asarray(sel.phi_dot.values, dtype=float),
            r=np.asarray(sel.r.values, dtype=float),
            r_crossing=np.asarray(sel.r_crossing.values, dtype=float)
            if "r_crossing" in sel
            else np.full(ds.sizes["time"], np.nan),
            omega=np.pi * np.asarray(sel.frequency_bpm.values, dtype=float) / 60.0,
            radius=float(ds.attrs.get("radius", 0.27)),
            step=step,
            equilibrium_window=window,
            r_eq=r_eq,
            run=run,
            attrs=dict(ds.attrs),
            escapement_offset=_escapement_offset(ds, sel),
            platform=str(ds.attrs.get("platform", "disk")),
        )

    @property
    def tick_angles(self) -> np.ndarray:
        """(N,) the angle where each metronome ticks, rad: where its escapement acts."""
        if self.escapement_offset is None:
            return np.zeros(self.n)
        return np.broadcast_to(np.asarray(self.escapement_offset, dtype=float), (self.n,))

    @property
    def n(self) -> int:
        """Number of metronomes N."""
        return self.theta.shape[1]

    @property
    def record_interval(self) -> float:
        """Time between records, s (NaN with a single record)."""
        return float(self.time[1] - self.time[0]) if self.time.size > 1 else math.nan

    @property
    def every_step(self) -> bool:
        """True when every integration step was recorded."""
        return math.isclose(self.record_interval, self.step, rel_tol=1e-9)

    @property
    def rim_angles(self) -> np.ndarray:
        """(N,) angle α_i of each metronome on the disk at φ = 0, rad."""
        return 2 * np.pi * np.arange(self.n) / self.n

    def stereo_position(self, i: int, times) -> np.ndarray:
        """Where metronome ``i`` sits from left (−1) to right (1) at ``times``, for a
        listener in front: on the disk its x, cos(α_i + φ), seen from above; on the
        board its place in the row (the board's millimetres of motion are not heard)."""
        times = np.asarray(times, dtype=float)
        if self.platform == "board":
            place = 2.0 * i / (self.n - 1) - 1.0 if self.n > 1 else 0.0
            return np.full(times.shape, place)
        return np.cos(self.rim_angles[i] + self.phi_at(times))

    def window(self, start: float | None = None, end: float | None = None) -> tuple[float, float]:
        """Check and complete a time window [start, end] inside the recording, s."""
        return check_window(start, end, float(self.time[0]), float(self.time[-1]))

    def theta_at(self, times) -> np.ndarray:
        """(K, N) pendulum angles at ``times`` (K,), Hermite-interpolated."""
        return hermite(self.time, self.theta, self.theta_dot, times)

    def theta_dot_at(self, times) -> np.ndarray:
        """(K, N) pendulum velocities at ``times``, linearly interpolated."""
        times = np.asarray(times, dtype=float)
        return np.stack(
            [np.interp(times, self.time, self.theta_dot[:, i]) for i in range(self.n)], axis=-1
        )

    def phi_at(self, times) -> np.ndarray:
        """(K,) disk angle at ``times``, Hermite-interpolated."""
        return hermite(self.time, self.phi, self.phi_dot, times)

    def phase_at(self, times) -> np.ndarray:
        """(K, N) analytic phase atan2(−θ̇/ω, θ) at ``times``, rad in (−π, π]."""
        return np.arctan2(-self.theta_dot_at(times) / self.omega, self.theta_at(times))

    @cached_property
    def phi_trend(self) -> tuple[float, float]:
        """(a, b) of the straight line a + b t fitted to φ(t) over the recording: the
        board's mean motion. Without damping the board keeps the momentum its start
        gave it and drifts at a steady speed; drawn about this line it stays in view.
        Fitted once: an animation asks for it every frame."""
        if self.time.size < 2:
            return float(self.phi[0]), 0.0
        slope, intercept = np.polyfit(self.time - self.time[0], self.phi, 1)
        return float(intercept - slope * self.time[0]), float(slope)

    def board_offset_at(self, times) -> np.ndarray:
        """(K,) φ less its mean motion (`phi_trend`) at ``times``: where to draw the board."""
        a, b = self.phi_trend
        times = np.asarray(times, dtype=float)
        return self.phi_at(times) - (a + b * times)

    def r_at(self, times) -> np.ndarray:
        """(K,) recorded r at ``times`` (linear interpolation)."""
        return np.interp(np.asarray(times, dtype=float), self.time, self.r)


def check_run(run, runs: int) -> int:
    """``run`` as an index of one of ``runs`` runs; `ParameterError` otherwise.

    The one check of a run index, also made before simulating, from the runs asked for.
    """
    if isinstance(run, bool) or not isinstance(run, int | np.integer) or not 0 <= run < runs:
        raise ParameterError(f"`run` must be an integer in [0, {runs - 1}], got {run!r}.")
    return int(run)


def check_window(
    start: float | None, end: float | None, t0: float, t1: float
) -> tuple[float, float]:
    """Check and complete a time window [start, end] inside a recording of [t0, t1], s.

    The one check of a window, also made before simulating, on [0, duration].
    """
    start = t0 if start is None else float(start)
    end = t1 if end is None else float(end)
    if not (math.isfinite(start) and t0 <= start < t1):
        raise ParameterError(f"`start` must be a time in [{t0:g}, {t1:g}) s, got {start!r}.")
    if not (math.isfinite(end) and start < end <= t1):
        raise ParameterError(f"`end` must be a time in ({start:g}, {t1:g}] s, got {end!r}.")
    return start, end


def hermite(time, y, y_dot, times) -> np.ndarray:
    """Cubic Hermite interpolation of samples with known derivatives.

    Parameters
    ----------
    time : (T,) increasing sample times.
    y, y_dot : (T, ...) values and their time derivatives.
    times : (K,) times inside [time[0], time[-1]].

    Returns
    -------
    (K, ...) interpolated values; exact at the samples.
    """
    time = np.asarray(time, dtype=float)
    times = np.asarray(times, dtype=float)
    y = np.asarray(y, dtype=float)
    y_dot = np.asarray(y_dot, dtype=float)
    k = np.clip(np.searchsorted(time, times, side="right") - 1, 0, time.size - 2)
    h = time[k + 1] - time[k]
    s = (times - time[k]) / h
    extra = (slice(None),) + (None,) * (y.ndim - 1)
    s, h = s[extra], h[extra]
    s2, s3 = s * s, s * s * s
    return (
        (2 * s3 - 3 * s2 + 1) * y[k]
        + (s3 - 2 * s2 + s) * h * y_dot[k]
        + (-2 * s3 + 3 * s2) * y[k + 1]
        + (s3 - s2) * h * y_dot[k + 1]
    )


def _escapement_offset(ds, sel) -> np.ndarray | None:
    """Each metronome's escapement angle: the per-metronome variable `simulate` writes
    when some metronome is out of beat, else the model's one value, else None."""
    if "escapement_offset" in sel:
        return np.asarray(sel.escapement_offset.values, dtype=float)
    value = float(ds.attrs.get("escapement_offset", 0.0))
    return None if value == 0.0 else np.full(ds.sizes["metronome"], value)

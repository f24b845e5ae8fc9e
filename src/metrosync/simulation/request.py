"""The first stage of `metrosync.simulate`: a request, the options checked.

`SimulationRequest` holds every option of one `simulate` call and checks itself when
made: the model (preset and changes), the integrator and backend, the duration, step
and recording stride, and the memory and time the run will take (`metrosync.budget`:
refused when it cannot fit, a warning when it will take minutes), all before the
ensemble's first array is allocated. What needs the ensemble (the step against its
fastest period, `metrosync.ensemble.check_time_step`) is checked where the ensemble
exists, in the run (`metrosync.simulation.run`), and so is the averaging window
(`SimulationRequest.window`), after the ensemble's own checks as it always was.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .._words import plural
from ..budget import simulation_budget
from ..ensemble import MIN_STEPS_PER_PERIOD, Ensemble, build_ensemble
from ..errors import ParameterError
from ..groups import Group
from ..integrators import BACKENDS, Integrator, get_integrator
from ..model import Metronome, ModelParameters, get_preset
from ..model.quantity import quantity

#: Time between records of r(t) when `record_every` is not given, s.
RECORD_SECONDS = 0.1
#: Most records of r(t) per run when `record_every` is not given: a longer run records
#: at a larger stride, so that memory does not grow with the duration.
MAX_RECORDS = 100_000
#: Most steps of one run: step times are exact in float64 below 2**53.
MAX_STEPS = 2.0**53

#: How far the budget's warning is from the caller of `metrosync.simulate` (``check`` <-
#: ``_check_budget`` <- ``__post_init__`` <- ``__init__`` <- ``simulate`` <- caller):
#: the warning names the caller's line.
_CALLER_LEVEL = 6


@dataclass(frozen=True, eq=False)
class SimulationRequest:
    """Every option of one `metrosync.simulate` call (see it for their meaning; the
    units are declared on the fields), checked when the request is made, and what
    follows from them alone.

    Resolved on construction: ``params`` (the preset with its ``changes``),
    ``scheme`` (the integrator), ``n_steps``, ``stride`` (the record stride used, in
    steps), ``stride_reason`` (why, stored in the dataset's ``attrs``) and
    ``n_records``.
    """

    n: int | None = 7
    bpm: float | None = quantity(192.0, unit="BPM")
    sigma_bpm: float = quantity(0.0, unit="BPM")
    groups: Sequence[Group | tuple] | None = None
    runs: int = 1
    duration: float = quantity(600.0, unit="s")
    dt: float = quantity(0.01, unit="s")
    seed: int | None = 0
    preset: str | ModelParameters = "default"
    changes: Mapping[str, float] | None = None
    integrator: str = "verlet"
    backend: str = "numba"
    frequencies_bpm: Sequence[float] | np.ndarray | None = None
    metronomes: Sequence[Metronome] | None = None
    amplitude: float | None = quantity(None, unit="rad")
    theta0: Sequence[float] | np.ndarray | None = None
    theta_dot0: Sequence[float] | np.ndarray | None = None
    record_every: int | None = None
    trajectories: bool = False
    equilibrium_window: float | None = quantity(None, unit="s")
    overturn_angle: float = quantity(math.pi / 2, unit="rad")
    progress: bool | None = None

    params: ModelParameters = field(init=False)
    scheme: Integrator = field(init=False)
    n_steps: int = field(init=False)
    stride: int = field(init=False)
    stride_reason: str = field(init=False)
    n_records: int = field(init=False)

    def __post_init__(self) -> None:
        self._resolve_model_and_scheme()
        n_steps = self._check_time()
        stride, reason = record_stride(self.record_every, n_steps, self.dt)
        self._set(n_steps=n_steps, stride=stride, stride_reason=reason)
        self._set(n_records=n_steps // stride + 1)
        self._check_budget()

    def _resolve_model_and_scheme(self) -> None:
        """The model (preset and changes), the integrator and the backend: the one
        place where all three are known together, before anything is sized."""
        params = get_preset(self.preset, warn=not self.changes)
        if self.changes:
            params = get_preset(params.with_changes(**self.changes))
        self._set(params=params, scheme=get_integrator(self.integrator))
        if self.backend not in BACKENDS:
            raise ParameterError(
                f"unknown `backend` {self.backend!r}; choose one of {sorted(BACKENDS)}."
            )
        # What runs where is one table (`metrosync.capabilities`): refuse before any work.
        options = {
            "trajectories": self.trajectories,
            "groups": self.groups,
            "escapement_stopped": True,
        }
        self.scheme.require(self.backend, params, options)

    def _set(self, **resolved) -> None:
        for name, value in resolved.items():
            object.__setattr__(self, name, value)

    def _check_time(self) -> int:
        """The step count of a ``duration`` and ``dt`` that a run can take."""
        duration, dt, overturn_angle = self.duration, self.dt, self.overturn_angle
        if not (math.isfinite(duration) and duration > 0):
            raise ParameterError(f"`duration` must be a finite time > 0 s, got {duration!r}.")
        if not (math.isfinite(overturn_angle) and overturn_angle > 0):
            raise ParameterError(f"`overturn_angle` must be > 0 rad, got {overturn_angle!r}.")
        # Size before work: everything below that grows with the inputs is estimated and
        # checked before the ensemble's first array is allocated.
        if not (math.isfinite(dt) and dt > 0):
            raise ParameterError(
                f"`dt` = {dt!r} s does not resolve any period: it needs 0 < dt <= "
                f"period/{MIN_STEPS_PER_PERIOD} ({120 / 192 / MIN_STEPS_PER_PERIOD:g} s at "
                f"192 BPM)."
            )
        if not duration / dt < MAX_STEPS:
            raise ParameterError(
                f"`duration` / `dt` = {duration:g} s / {dt:g} s = {duration / dt:.3g} steps, "
                f"more than the {MAX_STEPS:.3g} a run can count; shorten `duration` or "
                f"enlarge `dt`."
            )
        n_steps = int(round(duration / dt))
        if n_steps < 1:
            raise ParameterError(
                f"`duration` = {duration!r} s is shorter than one time step (`dt` = {dt!r} s); "
                f"lengthen `duration`."
            )
        return n_steps

    def _check_budget(self) -> None:
        """Refuse a request that cannot fit in memory; warn about a long one."""
        size = self.size()
        if size is None:
            return  # malformed: building the ensemble says what is wrong
        n, runs, groups = size
        # Several groups keep their records per group: count them as that many records.
        simulation_budget(
            n=n,
            runs=runs,
            steps=self.n_steps,
            records=self.n_records * groups,
            trajectories=self.trajectories,
            integrator=self.integrator,
            backend=self.backend,
            dt=self.dt,
        ).check(stacklevel=_CALLER_LEVEL)

    def size(self) -> tuple[int, int, int] | None:
        """(N, runs, groups) of the request, read without building anything; None when
        the inputs are malformed (`build_ensemble` then says what is wrong)."""
        n, runs, groups = self.n, self.runs, self.groups
        try:
            if groups is not None:
                n = sum(operator.index(g.n if isinstance(g, Group) else g[0]) for g in groups)
            elif self.metronomes is not None:
                n = len(self.metronomes)
            elif self.frequencies_bpm is not None:
                n = np.shape(self.frequencies_bpm)[-1]
            elif self.theta0 is not None and n is None:
                n = np.shape(self.theta0)[-1]
            n, runs = operator.index(n), operator.index(runs)
        except (TypeError, IndexError):
            return None
        count = len(groups) if groups is not None else 1
        return (n, runs, count) if n >= 1 and runs >= 1 else None

    def build_ensemble(self) -> Ensemble:
        """The ensemble this request asks for (`metrosync.ensemble.build_ensemble`)."""
        return build_ensemble(
            self.n,
            self.bpm,
            params=self.params,
            sigma_bpm=self.sigma_bpm,
            runs=self.runs,
            seed=self.seed,
            frequencies_bpm=self.frequencies_bpm,
            metronomes=self.metronomes,
            amplitude=self.amplitude,
            theta0=self.theta0,
            theta_dot0=self.theta_dot0,
            groups=self.groups,
        )

    def window(self) -> float:
        """The final window averaged for r_eq, s: ``equilibrium_window``, or a quarter
        of ``duration``."""
        duration, given = self.duration, self.equilibrium_window
        window = duration / 4 if given is None else float(given)
        if not (0 < window <= duration):
            raise ParameterError(f"`equilibrium_window` must be in (0, duration], got {given!r}.")
        return window

    @property
    def simulated_time(self) -> float:
        """The time simulated, s: a whole number of steps."""
        return self.n_steps * self.dt

    @property
    def record_interval(self) -> float:
        """Time between records, s."""
        return self.stride * self.dt


def record_stride(record_every, n_steps: int, dt: float) -> tuple[int, str]:
    """The record stride (steps) of a run of ``n_steps`` steps of ``dt`` s, and why it
    is what it is (stored in ``attrs``): ``record_every`` when given, else 0.1 s or
    the stride that keeps `MAX_RECORDS` records."""
    reason = "given"
    defaulted = record_every is None
    if record_every is None:
        record_every = max(1, int(round(RECORD_SECONDS / dt)))
        reason = f"default {RECORD_SECONDS:g} s"
        capped = math.ceil(n_steps / (MAX_RECORDS - 1))
        if capped > record_every:
            record_every = capped
            reason = (
                f"raised from {RECORD_SECONDS:g} s to keep at most {MAX_RECORDS} records per run"
            )
    if (
        isinstance(record_every, bool)
        or not isinstance(record_every, int | np.integer)
        or record_every < 1
    ):
        raise ParameterError(f"`record_every` must be an integer >= 1 step, got {record_every!r}.")
    if record_every > n_steps:
        if defaulted:  # the user gave no stride: the run is what is too short
            raise ParameterError(
                f"`duration` = {n_steps * dt:g} s is shorter than the default recording "
                f"interval ({record_every * dt:g} s, {plural(record_every, 'step')} of {dt!r} s); "
                f"lengthen `duration`, or give `record_every` <= {plural(n_steps, 'step')}."
            )
        raise ParameterError(
            f"`record_every` = {plural(record_every, 'step')} exceeds the "
            f"{plural(n_steps, 'step')} of the run; "
            f"lower it or lengthen `duration`."
        )
    return int(record_every), reason

"""Run a declared study on the sweep machinery and assemble its data: the engine.

Contract: `run_study(study, mode, out)` has a study expand itself into *points*, one
public `metrosync.simulate` call each, with the exact keyword arguments a user would
pass (`points_of`: the study's ``points``), and runs them with the sweep machinery
(`metrosync.sweeps`): the points are keyed by `metrosync.sweeps.points` (the fully
resolved model parameters, the package version and the simulation's sources, never a
preset's name), computed by `metrosync.sweeps.executors.execute` in process or on
Dask, and each written atomically to the one point store of the output folder,
``out/points/<key>.nc`` (`metrosync.sweeps.PointStore` rooted at ``out``). An
interrupted run (``--full`` takes a quarter of an hour or more) resumes where it
stopped; a point whose parameters or simulation code changed is recomputed, never
reused. The study then assembles its points into one `xarray.Dataset`, written to
``out/<study>.nc``.

The engine knows no kind of study: a study is anything with the few members of
`Study` (its points, a label for each, and how it runs and assembles them), declared in
`metrosync.paper.studies`, `metrosync.paper.sigma_map` and `metrosync.paper.claims_map`;
`metrosync.paper.catalogue` lists the paper's. Most run the usual way, `run_points`.

Each stored point holds what it cost (compute seconds and oscillator-steps), so a
study's throughput, and from it the estimate of a ``--full`` run, comes from every
point, reused or not (`StudyResult.throughput`).

A study without points (the estimation study: its `simulate` calls are made inside
`metrosync.calibration` and take seconds) is recomputed on every run; its compute time
is its wall time.

Seeds are a fixed function of the study and point names, so results never depend on
the order or the number of points computed in one go, nor on the executor.

How a study integrates is its own declared choice, a `Stepping` (integrator and time
step) in its ``stepping`` field, which the points carry into `simulate`; there is no
step shared by all studies. Each was chosen from measured accuracy against the
paper's scheme and step, `PAPER_STEPPING`: the cheapest whose statistics stay within
the study's statistical error (`benchmarks/reproduce_accuracy.py`, docs/reproducing.md).
"""

from __future__ import annotations

import math
import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
import xarray as xr

from .._files import write_netcdf
from .._version import __version__
from ..errors import MetrosyncError, ParameterError
from ..sweeps import PointStore
from ..sweeps.executors import execute
from ..sweeps.points import PointSpec, make_point


@dataclass(frozen=True)
class Stepping:
    """The integrator (a name of `metrosync.integrators.REGISTRY`, fixed-step) and the
    time step ``dt`` (s) of a study's `simulate` calls."""

    integrator: str
    dt: float

    def __post_init__(self) -> None:
        from ..integrators import REGISTRY

        scheme = REGISTRY.get(self.integrator)
        if scheme is None or not scheme.fixed_step:
            fixed = [name for name, s in REGISTRY.items() if s.fixed_step]
            raise ParameterError(
                f"unknown fixed-step `integrator` {self.integrator!r}; choose one of {fixed}."
            )
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ParameterError(f"`dt` must be a finite time > 0 s, got {self.dt!r}.")

    def kwargs(self) -> dict[str, float | str]:
        """The `simulate` keyword arguments of this choice."""
        return {"dt": float(self.dt), "integrator": self.integrator}

    def describe(self) -> str:
        """E.g. ``located, dt = 0.02 s`` (for figures and reports)."""
        return f"{self.integrator}, dt = {self.dt:g} s"


#: The paper's scheme and step: the reference against which each study's choice is
#: measured.
PAPER_STEPPING = Stepping("verlet", 0.01)

#: ``compute(name, specs, label)``: the points of ``specs`` computed or reused
#: (`compute_points` with the run's output folder, executor and log).
Compute = Callable[[str, list[PointSpec], Callable[[PointSpec], str]], "Computed"]


class Study(Protocol):
    """What the engine asks of a study (every kind in `metrosync.paper` has these).

    name, figure, title : its file name, the paper's figure and a one-line title.
    points(mode) : its `simulate` calls in ``mode`` ("quick" or "full"); [] for none.
    point_label(spec) : a short human name of one of its points (for reports).
    run(mode, out, compute) : (dataset, specs, computed): its points computed or reused
        with ``compute`` and assembled (most do `run_points`); ``computed`` is None for
        a study without points, which computes in process.
    """

    name: str
    figure: str
    title: str

    def points(self, mode: str) -> list[PointSpec]: ...

    def point_label(self, spec: PointSpec) -> str: ...

    def run(
        self, mode: str, out: Path, compute: Compute
    ) -> tuple[xr.Dataset, list[PointSpec], Computed | None]: ...


class StudyIncomplete(MetrosyncError):
    """A point of a study failed or was lost with its worker; the others are kept."""


@dataclass(frozen=True)
class StudyResult:
    """A study's assembled data and what it cost.

    wall_s : wall time of this invocation.   computed_work : oscillator-steps computed
    now.   total_work : oscillator-steps of all its points.   cached_points, points :
    points reused from the store, and in all.   compute_s : compute seconds stored with
    its points, reused or not.   cached : labels of the reused points.
    """

    study: Study
    mode: str
    dataset: xr.Dataset
    path: Path
    wall_s: float
    computed_work: float
    total_work: float
    cached_points: int
    points: int
    compute_s: float = math.nan
    cached: tuple[str, ...] = ()

    @property
    def throughput(self) -> float:
        """Oscillator-steps per compute second over every point (NaN without points)."""
        if self.total_work > 0 and self.compute_s > 0:
            return self.total_work / self.compute_s
        return math.nan


def points_of(study: Study, mode: str) -> list[PointSpec]:
    """Expand ``study`` into its `simulate` calls for ``mode`` ("quick" or "full")."""
    return study.points(mode)


def point_label(study: Study, spec: PointSpec) -> str:
    """A short human name of one point of ``study`` (for reports)."""
    return study.point_label(spec)


def run_study(
    study: Study,
    mode: str,
    out: Path,
    *,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
) -> StudyResult:
    """Simulate (or resume) every point of ``study``, assemble and write ``out/<name>.nc``.

    ``scheduler`` and ``n_workers`` choose the executor, as for `metrosync.sweep`.
    Raises `StudyIncomplete` when a point fails or is lost with a Dask worker (the
    points that finished stay in the store; running again computes only the rest).
    """
    out = Path(out)
    started = time.perf_counter()

    def compute(name, specs, label):
        return compute_points(
            name, specs, out, label=label, progress=progress, log=log,
            scheduler=scheduler, n_workers=n_workers, started=started,
        )  # fmt: skip

    dataset, specs, computed = study.run(mode, out, compute)
    if computed is None:
        wall = time.perf_counter() - started
        return _finish(study, mode, out, dataset, started, 0.0, 0.0, [], 0, wall)
    return _summarise(study, mode, out, dataset, started, specs, computed, computed.loaded)


def run_points(study, mode: str, out: Path, compute: Compute):
    """The usual `Study.run`: compute or reuse every point of ``study`` in ``mode``, then
    join them with its ``assemble(mode, specs, parts)``."""
    specs = study.points(mode)
    computed = compute(study.name, specs, study.point_label)
    parts = [computed.loaded[spec.key] for spec in specs]
    return study.assemble(mode, specs, parts), specs, computed


@dataclass
class Computed:
    """Points computed or reused by `compute_points`.

    loaded : key -> stored point.   now : keys computed in this call.   work :
    oscillator-steps computed in this call.   labels : key -> short name of the point.
    """

    loaded: dict[str, xr.Dataset]
    now: set[str]
    work: float
    labels: dict[str, str]

    def merge(self, other: Computed) -> Computed:
        return Computed(
            {**self.loaded, **other.loaded}, self.now | other.now, self.work + other.work,
            {**self.labels, **other.labels},
        )  # fmt: skip


def compute_points(
    name: str,
    specs: list[PointSpec],
    out: Path,
    *,
    label: Callable[[PointSpec], str],
    progress: bool = False,
    log: Callable[[str], None] | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    started: float | None = None,
) -> Computed:
    """Compute the points of ``specs`` not yet in the store of ``out`` and load them all.

    A key listed twice (two readings that share a simulation) is computed once. Raises
    `StudyIncomplete` when a point fails or is lost with a Dask worker.
    """
    started = time.perf_counter() if started is None else started
    store = PointStore(out)
    unique = list({spec.key: spec for spec in specs}.values())
    loaded = {spec.key: ds for spec in unique if (ds := _stored(store, spec)) is not None}
    todo = [spec for spec in unique if spec.key not in loaded]
    finished = len(unique) - len(todo)

    def tell(_spec: PointSpec) -> None:
        nonlocal finished
        finished += 1
        if log is not None and len(unique) > 1:
            elapsed = time.perf_counter() - started
            log(f"  {name}: {finished}/{len(unique)} points ({elapsed:.0f} s)")

    def keep(spec: PointSpec, ds: xr.Dataset) -> None:
        loaded[spec.key] = ds  # as stored: reading the file back would cost as much again

    execution = execute(
        todo, store, scheduler=scheduler, n_workers=n_workers, progress=progress,
        desc=name, on_done=tell, on_result=keep,
    )  # fmt: skip
    if execution.failed:
        key, message = next(iter(execution.failed.items()))
        spec = next(s for s in unique if s.key == key)
        raise StudyIncomplete(
            f"study {name!r}: the simulation of point {label(spec)!r} failed: {message}"
        )
    if execution.lost:
        raise StudyIncomplete(
            f"study {name!r}: {len(execution.lost)} of {len(unique)} points were lost "
            f"with their Dask workers ({next(iter(execution.lost.values()))}); the others are "
            f"kept in {store.points}: run the same command again to compute the rest."
        )
    return Computed(
        loaded, {spec.key for spec in todo}, float(execution.work),
        {spec.key: label(spec) for spec in unique},
    )  # fmt: skip


def _summarise(study, mode, out, dataset, started, specs, computed: Computed, loaded):
    """Stamp and write a study's dataset with what its points cost (reused or not)."""
    unique = list({spec.key: spec for spec in specs}.values())
    cached = [computed.labels[s.key] for s in unique if s.key not in computed.now]
    compute = sum(float(loaded[s.key].attrs.get("compute_seconds", np.nan)) for s in unique)
    total = float(sum(spec.work for spec in unique))
    return _finish(
        study, mode, out, dataset, started, total, computed.work, cached, len(unique), compute,
    )  # fmt: skip


def _stored(store: PointStore, spec: PointSpec) -> xr.Dataset | None:
    """The stored result of ``spec``, or None when there is no usable one."""
    if not store.has(spec.key):
        return None
    try:
        ds = store.read(spec.key)
    except (OSError, ValueError):
        return None  # unreadable leftovers are recomputed, never trusted
    return None if ds.attrs.get("error") else ds  # a failed point is tried again


def _finish(study, mode, out, dataset, started, total, computed, cached, points, compute):
    """Stamp a study's dataset with what it cost, write ``out/<name>.nc``, wrap it."""
    wall = time.perf_counter() - started
    dataset.attrs.update(
        study=study.name,
        figure=study.figure,
        title=study.title,
        mode=mode,
        wall_time_s=wall,
        compute_time_s=compute,
        work_osc_steps=total,
        computed_osc_steps=computed,
        cached_points=len(cached),
        metrosync_version=__version__,
    )
    path = Path(out) / f"{study.name}.nc"
    write_netcdf(dataset, path)
    return StudyResult(
        study, mode, dataset, path, wall, computed, total, len(cached), points, compute,
        tuple(cached),
    )  # fmt: skip


def point_seed(study: str, key: str) -> int:
    """A seed fixed by the study and point names (stable across runs and platforms)."""
    return zlib.crc32(f"{study}/{key}".encode())


def ensemble_points(
    study: str, cells, stats, preset: str, changes, stepping: Stepping
) -> list[PointSpec]:
    """The points of an ensemble study: one per cell ``(key, n, bpm, sigma, coords)``, with
    the statistics ``stats`` (runs, duration), the model ``changes`` and the ``stepping``
    of the study."""
    return [
        ensemble_point(study, i, key, n, bpm, sigma, stats, preset, coords, dict(changes), stepping)
        for i, (key, n, bpm, sigma, coords) in enumerate(cells)
    ]


def ensemble_point(study, i, key, n, bpm, sigma, stats, preset, coords, changes, stepping):
    """One ensemble point; its seed depends on the study's and the cell's names only, so
    every reading of the claims map draws the same frequencies and starts."""
    kwargs = {
        "n": int(n),
        "bpm": float(bpm),
        "sigma_bpm": float(sigma),
        "runs": int(stats.runs),
        "duration": float(stats.duration),
        **stepping.kwargs(),
        "preset": preset,
        "seed": point_seed(study, key),
    }
    if changes:
        kwargs["changes"] = changes
    return make_point(kwargs, keep="run_mean_r", index=(i,), coords=coords)

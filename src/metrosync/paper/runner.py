"""Run a declared study on the sweep machinery and assemble its data.

Contract: `run_study(study, mode, out)` expands a study (`metrosync.paper.studies`)
into *points*, one public `metrosync.simulate` call each, with the exact keyword
arguments a user would pass (`points_of`), and runs them with the sweep machinery
(`metrosync.sweeps`): the points are keyed by `metrosync.sweeps.points` (the fully
resolved model parameters, the package version and the simulation's sources, never a
preset's name), computed by `metrosync.sweeps.executors.execute` in process or on
Dask, and each written atomically to the one point store of the output folder,
``out/points/<key>.nc`` (`metrosync.sweeps.PointStore` rooted at ``out``). An
interrupted run (``--full`` takes a quarter of an hour or more) resumes where it
stopped; a point whose parameters or simulation code changed is recomputed, never
reused. The points are then assembled into one `xarray.Dataset` per study, written to
``out/<study>.nc``.

Each stored point holds what it cost (compute seconds and oscillator-steps), so a
study's throughput, and from it the estimate of a ``--full`` run, comes from every
point, reused or not (`StudyResult.throughput`).

The estimation study (`EstimationStudy`) has no points: its `simulate` calls are made
inside `metrosync.calibration` and take seconds, so it is recomputed on every run.

Seeds are a fixed function of the study and point names, so results never depend on
the order or the number of points computed in one go, nor on the executor.
"""

from __future__ import annotations

import math
import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from .._files import write_netcdf
from .._version import __version__
from ..errors import MetrosyncError
from ..sweeps import PointStore
from ..sweeps.executors import execute
from ..sweeps.points import PointSpec, make_point
from .assemble import assemble
from .estimation import run_estimation
from .studies import EstimationStudy, Study, SweepStudy, TimeSeriesStudy, ZStudy

#: Runs per `simulate` call of the z-study: bounds the memory of full trajectories.
Z_BATCH = 12
DT = 0.01


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
    if isinstance(study, TimeSeriesStudy | SweepStudy):
        if isinstance(study, TimeSeriesStudy):
            stats = study.statistics(mode)
            cells = [(f"case{i:02d}", c.n, c.bpm, c.sigma_bpm, {"case": i})
                     for i, c in enumerate(study.cases)]  # fmt: skip
        else:
            grid = study.grid(mode)
            stats = grid.stats
            cells = [(f"n{n:04d}_bpm{bpm:07.2f}", n, bpm, study.sigma_bpm, {"n": n, "bpm": bpm})
                     for n in grid.ns for bpm in grid.bpms]  # fmt: skip
        return [
            _ensemble_point(study.name, i, key, n, bpm, sigma, stats, study.preset, coords)
            for i, (key, n, bpm, sigma, coords) in enumerate(cells)
        ]
    if isinstance(study, ZStudy):
        grid = study.grid(mode)
        theta2 = np.asarray(grid.theta2, dtype=float)
        out = []
        for r, regime in enumerate(study.regimes):
            for start in range(0, theta2.size, Z_BATCH):
                chunk = theta2[start : start + Z_BATCH]
                theta0 = np.column_stack([np.full(chunk.size, study.theta1), chunk])
                kwargs = {
                    "n": 2,
                    "bpm": study.bpm,
                    "runs": int(chunk.size),
                    "duration": grid.duration,
                    "dt": study.dt,
                    "preset": regime.preset,
                    "changes": dict(regime.changes) or None,
                    "theta0": theta0.tolist(),
                    "theta_dot0": np.zeros_like(theta0).tolist(),
                    "trajectories": True,
                    "record_every": grid.record_every,
                    "seed": 0,
                }
                where = {"regime": r, "start": start}
                out.append(make_point(kwargs, keep="z", index=(len(out),), coords=where))
        return out
    if isinstance(study, EstimationStudy):
        return []
    raise TypeError(f"unknown study type {type(study).__name__}")


def point_label(study: Study, spec: PointSpec) -> str:
    """A short human name of one point of ``study`` (for reports)."""
    c = spec.coords
    if isinstance(study, TimeSeriesStudy):
        return study.cases[c["case"]].label
    if isinstance(study, SweepStudy):
        return f"N = {c['n']}, ω₀ = {c['bpm']:g} BPM"
    if isinstance(study, ZStudy):
        runs = spec.kwargs["runs"]
        return f"regime {c['regime']}, θ₂(0) #{c['start']}–{c['start'] + runs - 1}"
    return spec.key[:12]


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
    if isinstance(study, EstimationStudy):
        dataset = run_estimation(study, mode, out / "points" / study.name)
        wall = time.perf_counter() - started
        return _finish(study, mode, out, dataset, started, 0.0, 0.0, [], 0, wall)
    specs = points_of(study, mode)
    store = PointStore(out)
    loaded = {spec.key: ds for spec in specs if (ds := _stored(store, spec)) is not None}
    todo = [spec for spec in specs if spec.key not in loaded]
    done_before = len(specs) - len(todo)

    finished = done_before

    def tell(_spec: PointSpec) -> None:
        nonlocal finished
        finished += 1
        if log is not None and len(specs) > 1:
            elapsed = time.perf_counter() - started
            log(f"  {study.name}: {finished}/{len(specs)} points ({elapsed:.0f} s)")

    execution = execute(
        todo, store, scheduler=scheduler, n_workers=n_workers, progress=progress,
        desc=study.name, on_done=tell,
    )  # fmt: skip
    if execution.failed:
        key, message = next(iter(execution.failed.items()))
        spec = next(s for s in specs if s.key == key)
        raise StudyIncomplete(
            f"study {study.name!r}: the simulation of point {point_label(study, spec)!r} "
            f"failed: {message}"
        )
    if execution.lost:
        raise StudyIncomplete(
            f"study {study.name!r}: {len(execution.lost)} of {len(specs)} points were lost "
            f"with their Dask workers ({next(iter(execution.lost.values()))}); the others are "
            f"kept in {store.points}: run the same command again to compute the rest."
        )
    loaded.update({spec.key: store.read(spec.key) for spec in todo})
    reduced = [loaded[spec.key] for spec in specs]
    computed_now = {spec.key for spec in todo}
    cached = [point_label(study, s) for s in specs if s.key not in computed_now]
    compute = sum(float(ds.attrs.get("compute_seconds", np.nan)) for ds in reduced)
    total = float(sum(spec.work for spec in specs))
    dataset = assemble(study, mode, [spec.coords for spec in specs], reduced)
    return _finish(
        study, mode, out, dataset, started, total, float(execution.work), cached, len(specs),
        compute,
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


def _ensemble_point(study, i, key, n, bpm, sigma, stats, preset, coords) -> PointSpec:
    kwargs = {
        "n": int(n),
        "bpm": float(bpm),
        "sigma_bpm": float(sigma),
        "runs": int(stats.runs),
        "duration": float(stats.duration),
        "dt": DT,
        "preset": preset,
        "seed": point_seed(study, key),
    }
    return make_point(kwargs, keep="run_mean_r", index=(i,), coords=coords)

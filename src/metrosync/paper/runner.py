"""Run a declared study through the public `metrosync.simulate` and assemble its data.

Contract: `run_study(study, mode, out)` expands a study (`metrosync.paper.studies`)
into *points*, one `simulate` call each, with the exact keyword arguments a user would
pass. Each point's reduced result is written atomically to
``out/points/<study>/<key>.nc`` together with a hash of its arguments, so an
interrupted run (``--full`` takes hours) resumes where it stopped: a point whose file
exists with the same hash is loaded, not recomputed. The points are then assembled
into one `xarray.Dataset` per study, written to ``out/<study>.nc``.

The estimation study (`EstimationStudy`) has no points: its `simulate` calls are made
inside `metrosync.calibration` and take seconds, so it is recomputed on every run.

Seeds are a fixed function of the study and point names, so results never depend on
the order or the number of points computed in one go.
"""

from __future__ import annotations

import hashlib
import json
import time
import warnings
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from .._files import write_netcdf
from .._version import __version__
from ..progress import progress_bar
from ..simulate import simulate
from .assemble import assemble, reduce_ensemble, reduce_z
from .estimation import run_estimation
from .studies import EstimationStudy, Study, SweepStudy, TimeSeriesStudy, ZStudy

#: Runs per `simulate` call of the z-study: bounds the memory of full trajectories.
Z_BATCH = 12
DT = 0.01


@dataclass(frozen=True)
class Point:
    """One `simulate` call: ``kwargs`` are passed verbatim; ``work`` = runs·N·steps."""

    key: str
    kwargs: dict
    coords: dict

    @property
    def work(self) -> float:
        k = self.kwargs
        runs = k.get("runs", 1)
        return float(runs * k["n"] * round(k["duration"] / k.get("dt", DT)))

    @property
    def digest(self) -> str:
        text = json.dumps(self.kwargs, sort_keys=True, default=_jsonable)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class StudyResult:
    """A study's assembled data and what it cost in this invocation."""

    study: Study
    mode: str
    dataset: xr.Dataset
    path: Path
    wall_s: float
    computed_work: float
    total_work: float
    cached_points: int
    points: int


def points_of(study: Study, mode: str) -> list[Point]:
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
            _ensemble_point(study.name, key, n, bpm, sigma, stats, study.preset, coords)
            for key, n, bpm, sigma, coords in cells
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
                out.append(
                    Point(f"regime{r}_from{start:03d}", kwargs, {"regime": r, "start": start})
                )
        return out
    if isinstance(study, EstimationStudy):
        return []
    raise TypeError(f"unknown study type {type(study).__name__}")


def run_study(
    study: Study,
    mode: str,
    out: Path,
    *,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
) -> StudyResult:
    """Simulate (or resume) every point of ``study``, assemble and write ``out/<name>.nc``."""
    out = Path(out)
    started = time.perf_counter()
    if isinstance(study, EstimationStudy):
        dataset = run_estimation(study, mode, out / "points" / study.name)
        return _finish(study, mode, out, dataset, started, 0.0, 0.0, 0, 0)
    points = points_of(study, mode)
    cache = out / "points" / study.name
    total = sum(p.work for p in points)
    reduced, computed, cached = [], 0.0, 0
    with progress_bar(total=total, unit="osc-step", enabled=progress, desc=study.name) as bar:
        for i, point in enumerate(points):
            path = cache / f"{point.key}.nc"
            ds = _load_cached(path, point.digest)
            if ds is None:
                ds = _compute(study, point)
                write_netcdf(ds, path)
                computed += point.work
            else:
                cached += 1
            reduced.append(ds)
            bar.update(point.work)
            if log is not None and len(points) > 1:
                elapsed = time.perf_counter() - started
                log(f"  {study.name}: {i + 1}/{len(points)} points ({elapsed:.0f} s)")
    dataset = assemble(study, mode, [p.coords for p in points], reduced)
    return _finish(study, mode, out, dataset, started, total, computed, cached, len(points))


def _finish(study, mode, out, dataset, started, total, computed, cached, points) -> StudyResult:
    """Stamp a study's dataset with what it cost, write ``out/<name>.nc``, wrap it."""
    wall = time.perf_counter() - started
    dataset.attrs.update(
        study=study.name,
        figure=study.figure,
        title=study.title,
        mode=mode,
        wall_time_s=wall,
        work_osc_steps=total,
        computed_osc_steps=computed,
        cached_points=cached,
        metrosync_version=__version__,
    )
    path = Path(out) / f"{study.name}.nc"
    write_netcdf(dataset, path)
    return StudyResult(study, mode, dataset, path, wall, computed, total, cached, points)


def point_seed(study: str, key: str) -> int:
    """A seed fixed by the study and point names (stable across runs and platforms)."""
    return zlib.crc32(f"{study}/{key}".encode())


def _ensemble_point(study, key, n, bpm, sigma, stats, preset, coords) -> Point:
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
    return Point(key, kwargs, coords)


def _load_cached(path: Path, digest: str) -> xr.Dataset | None:
    if not path.exists():
        return None
    try:
        ds = xr.load_dataset(path, engine="h5netcdf")
    except (OSError, ValueError):
        return None  # unreadable leftovers are recomputed, never trusted
    return ds if ds.attrs.get("point_digest") == digest else None


def _simulate(point: Point) -> tuple[xr.Dataset, list[str]]:
    """Call `simulate` with the point's arguments; collect (not lose) its warnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = simulate(**point.kwargs, progress=False)
    return ds, sorted({str(w.message) for w in caught})


def _compute(study: Study, point: Point) -> xr.Dataset:
    ds, messages = _simulate(point)
    reduced = reduce_z(ds) if isinstance(study, ZStudy) else reduce_ensemble(ds)
    reduced.attrs.update(_scalar_attrs(ds.attrs))
    reduced.attrs.update(point_digest=point.digest, warnings=" | ".join(messages) or "none")
    return reduced


def _scalar_attrs(attrs: dict) -> dict:
    return {k: v for k, v in attrs.items() if isinstance(v, str | int | float | np.number | list)}


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot hash {type(value).__name__}")

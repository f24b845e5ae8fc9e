"""Run a declared study through the public `metrosync.simulate` and assemble its data.

Contract: `run_study(study, mode, out)` expands a study (`metrosync.reproduce.studies`)
into *points*, one `simulate` call each, with the exact keyword arguments a user would
pass. Each point's reduced result is written atomically to
``out/points/<study>/<key>.nc`` together with a hash of its arguments, so an
interrupted run (``--full`` takes hours) resumes where it stopped: a point whose file
exists with the same hash is loaded, not recomputed. The points are then assembled
into one `xarray.Dataset` per study, written to ``out/<study>.nc``.

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

from .. import __version__
from ..observables import ensemble_statistics, z_order
from ..progress import progress_bar
from ..simulate import simulate
from .studies import Study, SweepStudy, TimeSeriesStudy, ZStudy

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
    if isinstance(study, TimeSeriesStudy):
        stats = study.statistics(mode)
        return [
            _ensemble_point(
                study.name,
                f"case{i:02d}",
                c.n,
                c.bpm,
                c.sigma_bpm,
                stats.runs,
                stats.duration,
                study.preset,
                {"case": i},
            )
            for i, c in enumerate(study.cases)
        ]
    if isinstance(study, SweepStudy):
        grid = study.grid(mode)
        return [
            _ensemble_point(
                study.name,
                f"n{n:04d}_bpm{bpm:07.2f}",
                n,
                bpm,
                study.sigma_bpm,
                grid.stats.runs,
                grid.stats.duration,
                study.preset,
                {"n": n, "bpm": bpm},
            )
            for n in grid.ns
            for bpm in grid.bpms
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
                write_atomic(ds, path)
                computed += point.work
            else:
                cached += 1
            reduced.append(ds)
            bar.update(point.work)
            if log is not None and len(points) > 1:
                elapsed = time.perf_counter() - started
                log(f"  {study.name}: {i + 1}/{len(points)} points ({elapsed:.0f} s)")
    dataset = _assemble(study, mode, points, reduced)
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
    path = out / f"{study.name}.nc"
    write_atomic(dataset, path)
    return StudyResult(study, mode, dataset, path, wall, computed, total, cached, len(points))


def write_atomic(ds: xr.Dataset, path: Path) -> None:
    """Write NetCDF through a temporary file, so ``path`` is never half-written."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".partial")
    ds.to_netcdf(tmp, engine="h5netcdf")
    tmp.replace(path)


def point_seed(study: str, key: str) -> int:
    """A seed fixed by the study and point names (stable across runs and platforms)."""
    return zlib.crc32(f"{study}/{key}".encode())


def _ensemble_point(study, key, n, bpm, sigma, runs, duration, preset, coords) -> Point:
    kwargs = {
        "n": int(n),
        "bpm": float(bpm),
        "sigma_bpm": float(sigma),
        "runs": int(runs),
        "duration": float(duration),
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
    reduced = _reduce_z(ds, study) if isinstance(study, ZStudy) else _reduce_ensemble(ds)
    reduced.attrs.update(_scalar_attrs(ds.attrs))
    reduced.attrs.update(point_digest=point.digest, warnings=" | ".join(messages) or "none")
    return reduced


def _reduce_ensemble(ds: xr.Dataset) -> xr.Dataset:
    """Keep what the figures and the report need: run-mean r(t) and per-run r_eq."""
    r_cross = ds.r_crossing.values
    finite = np.isfinite(r_cross)
    count = finite.sum(axis=1)
    # Near the ends only some runs have a crossing phase; averaging over whichever runs
    # happen to have one would draw spikes, so the mean is drawn only where every run
    # that ever has a phase (all but overturned or diverged ones) contributes.
    active = finite.any(axis=0)
    enough = finite[:, active].all(axis=1) & active.any()
    with np.errstate(invalid="ignore", divide="ignore"):
        r_mean = np.where(enough, np.where(finite, r_cross, 0.0).sum(axis=1) / count, np.nan)
    freq = ds.frequency_bpm.values
    spread = freq.std(axis=1, ddof=1) if freq.shape[1] > 1 else np.zeros(freq.shape[0])
    return xr.Dataset(
        {
            "r_mean": ("time", r_mean, {"long_name": "run-mean r, crossing-interpolated phase"}),
            "r_analytic_mean": (
                "time",
                ds.r.mean("run").values,
                {"long_name": "run-mean r, analytic phase"},
            ),
            "r_eq": ds.r_eq,
            "r_eq_analytic": ds.r_eq_analytic,
            "status": ds.status,
            "sigma_realized": (
                "run",
                spread,
                {"units": "BPM", "long_name": "std of the drawn natural frequencies"},
            ),
        },
        coords={"time": ds.time, "run": ds.run},
    )


def _reduce_z(ds: xr.Dataset, study: ZStudy) -> xr.Dataset:
    """z per run over the whole run (the paper's average) and over its last quarter."""
    t = ds.time.values
    theta = ds.theta.values
    late = t >= t[-1] * 0.75
    z_all, z_late, amp = [], [], []
    for b in range(theta.shape[1]):
        z_all.append(z_order(t, theta[:, b, 0], theta[:, b, 1]))
        z_late.append(z_order(t, theta[:, b, 0], theta[:, b, 1], start=t[-1] * 0.75))
        amp.append(float(np.abs(theta[late, b, :]).max()))
    theta2 = ds.theta.values[0, :, 1]
    return xr.Dataset(
        {
            "z": ("run", np.array(z_all), {"long_name": "z over the whole run"}),
            "z_late": ("run", np.array(z_late), {"long_name": "z over the last quarter"}),
            "amplitude_late": (
                "run",
                np.array(amp),
                {"units": "rad", "long_name": "max |θ| over the last quarter"},
            ),
            "status": ds.status,
            "theta2_0": ("run", theta2, {"units": "rad"}),
        },
        coords={"run": ds.run},
    )


def _assemble(study: Study, mode: str, points: list[Point], parts: list[xr.Dataset]) -> xr.Dataset:
    first = parts[0]
    if isinstance(study, TimeSeriesStudy):
        ds = xr.concat([p.drop_attrs(deep=False) for p in parts], dim="case")
        ds = ds.assign_coords(
            case=[c.label for c in study.cases],
            n=("case", [c.n for c in study.cases]),
            bpm=("case", [c.bpm for c in study.cases], {"units": "BPM"}),
            sigma_bpm=("case", [c.sigma_bpm for c in study.cases], {"units": "BPM"}),
        )
        ds["r_eq_mean"], ds["sigma_r"] = _statistics(ds.r_eq)
    elif isinstance(study, SweepStudy):
        grid = study.grid(mode)
        stacked = xr.concat([p.drop_attrs(deep=False) for p in parts], dim="point")
        shape = (len(grid.ns), len(grid.bpms))
        ds = xr.Dataset(
            coords={"n": list(grid.ns), "bpm": ("bpm", list(grid.bpms), {"units": "BPM"})}
        )
        for name in ("r_eq", "r_eq_analytic", "status", "sigma_realized"):
            values = stacked[name].values.reshape(shape + (-1,))
            ds[name] = (("n", "bpm", "run"), values, stacked[name].attrs)
        ds["r_mean"] = (("n", "bpm", "time"), stacked.r_mean.values.reshape(shape + (-1,)))
        ds = ds.assign_coords(time=stacked.time, run=stacked.run)
        ds["r_eq_mean"], ds["sigma_r"] = _statistics(ds.r_eq)
    else:
        ds = _assemble_z(study, points, parts)
    # Attributes that vary between points live in coordinates and variables instead.
    varying = {
        "point_digest",
        "n",
        "bpm",
        "sigma_bpm",
        "r_eq_mean",
        "r_eq_std",
        "seed",
        "disk_inertia",
        "runs",
        "warnings",
    }
    if isinstance(study, ZStudy):
        varying |= {"preset", "c_theta", "c_phi", "drive", "theta0", "theta_dot0"}
    common = {k: v for k, v in first.attrs.items() if k not in varying}
    ds.attrs = {**common, **ds.attrs}
    if isinstance(study, TimeSeriesStudy):
        ds.attrs["legend_title"] = study.legend_title
    elif isinstance(study, SweepStudy):
        ds.attrs["sigma_bpm_study"] = study.sigma_bpm
    ds.attrs["warnings"] = " | ".join(sorted({p.attrs["warnings"] for p in parts}))
    return ds


def _assemble_z(study: ZStudy, points: list[Point], parts: list[xr.Dataset]) -> xr.Dataset:
    by_regime: dict[int, list[xr.Dataset]] = {}
    for point, part in zip(points, parts, strict=True):
        by_regime.setdefault(point.coords["regime"], []).append(part)
    rows = []
    for r in range(len(study.regimes)):
        joined = xr.concat([p.drop_attrs(deep=False) for p in by_regime[r]], dim="run")
        rows.append(joined.assign_coords(run=np.arange(joined.sizes["run"])))
    ds = xr.concat(rows, dim="regime").rename(run="theta2")
    ds = ds.assign_coords(
        theta2=("theta2", ds.theta2_0.values[0], {"units": "rad", "long_name": "θ₂(0)"}),
        regime=[g.label for g in study.regimes],
        **{
            name: (
                "regime",
                [_regime_value(study, g, parts, points, name) for g in study.regimes],
                {"units": unit},
            )
            for name, unit in (("drive", "N m s"), ("c_theta", "kg m2/s"), ("c_phi", "kg m2/s"))
        },
        preset=("regime", [g.preset for g in study.regimes]),
        from_paper=("regime", [g.from_paper for g in study.regimes]),
    ).drop_vars("theta2_0")
    ds.attrs = {"bpm": study.bpm, "theta1_0": study.theta1, "theta_dot0": 0.0}
    return ds


def _regime_value(study, regime, parts, points, name) -> float:
    for point, part in zip(points, parts, strict=True):
        if study.regimes[point.coords["regime"]] is regime:
            return float(part.attrs[name])
    return float("nan")


def _statistics(r_eq: xr.DataArray) -> tuple[xr.DataArray, xr.DataArray]:
    """Mean and σ_r (sample std) of r_eq across runs; ``run`` must be the last dim."""
    values = r_eq.transpose(..., "run").values
    pairs = np.array([ensemble_statistics(row) for row in values.reshape(-1, values.shape[-1])])
    dims = [d for d in r_eq.dims if d != "run"]
    coords = {d: r_eq[d] for d in dims}
    shape = values.shape[:-1]
    mean = xr.DataArray(
        pairs[:, 0].reshape(shape),
        dims=dims,
        coords=coords,
        attrs={"long_name": "equilibrium r, mean over runs"},
    )
    std = xr.DataArray(
        pairs[:, 1].reshape(shape),
        dims=dims,
        coords=coords,
        attrs={"long_name": "σ_r, sample std of equilibrium r over runs"},
    )
    return mean, std


def _scalar_attrs(attrs: dict) -> dict:
    return {k: v for k, v in attrs.items() if isinstance(v, str | int | float | np.number | list)}


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot hash {type(value).__name__}")

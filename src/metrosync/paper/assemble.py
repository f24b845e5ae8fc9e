"""Assemble a study's dataset from its stored points.

Contract: each point of a study is stored reduced (`metrosync.sweeps.keep`: run-mean
r(t), per-run equilibrium r and status; or z per run); each kind of study
(`metrosync.paper.studies`) joins its points with its own function here into one
dataset on its own coordinates (``case``: `assemble_time_series`; ``n`` × ``bpm``:
`assemble_sweep`; ``regime`` × ``theta2``: `assemble_z`) with the run statistics (mean
r_eq and σ_r) and the attributes shared by every point.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..observables import ensemble_statistics

#: Attributes that vary between points: they live in coordinates and variables instead.
VARYING = frozenset(
    {
        "key",
        "error",
        "compute_seconds",
        "osc_steps",
        "host",
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
)
#: What varies, besides, between the points of a z-study (its regimes).
VARYING_Z = frozenset({"preset", "c_theta", "c_phi", "drive", "theta0", "theta_dot0"})


def assemble_time_series(study, parts: list[xr.Dataset]) -> xr.Dataset:
    """A `TimeSeriesStudy`'s dataset: its cases' points along ``case``."""
    ds = xr.concat([p.drop_attrs(deep=False) for p in parts], dim="case")
    ds = ds.assign_coords(
        case=[c.label for c in study.cases],
        n=("case", [c.n for c in study.cases]),
        bpm=("case", [c.bpm for c in study.cases], {"units": "BPM"}),
        sigma_bpm=("case", [c.sigma_bpm for c in study.cases], {"units": "BPM"}),
    )
    ds["r_eq_mean"], ds["sigma_r"] = _statistics(ds.r_eq)
    return _shared_attrs(ds, parts, VARYING, legend_title=study.legend_title)


def assemble_sweep(study, mode: str, parts: list[xr.Dataset]) -> xr.Dataset:
    """A `SweepStudy`'s dataset: its points on the ``n`` × ``bpm`` grid of ``mode``."""
    grid = study.grid(mode)
    stacked = xr.concat([p.drop_attrs(deep=False) for p in parts], dim="point")
    shape = (len(grid.ns), len(grid.bpms))
    ds = xr.Dataset(coords={"n": list(grid.ns), "bpm": ("bpm", list(grid.bpms), {"units": "BPM"})})
    for name in ("r_eq", "r_eq_analytic", "status", "sigma_realized"):
        values = stacked[name].values.reshape(shape + (-1,))
        ds[name] = (("n", "bpm", "run"), values, stacked[name].attrs)
    ds["r_mean"] = (("n", "bpm", "time"), stacked.r_mean.values.reshape(shape + (-1,)))
    ds = ds.assign_coords(time=stacked.time, run=stacked.run)
    ds["r_eq_mean"], ds["sigma_r"] = _statistics(ds.r_eq)
    return _shared_attrs(ds, parts, VARYING, sigma_bpm_study=study.sigma_bpm)


def assemble_z(study, coords: list[dict], parts: list[xr.Dataset]) -> xr.Dataset:
    """A `ZStudy`'s dataset: ``regime`` × ``theta2`` from its batches of runs."""
    return _shared_attrs(_z_grid(study, coords, parts), parts, VARYING | VARYING_Z)


def _shared_attrs(ds: xr.Dataset, parts: list[xr.Dataset], varying, **own) -> xr.Dataset:
    """``ds`` with the attributes every point shares, then its own (``own``), then the
    points' warnings."""
    common = {k: v for k, v in parts[0].attrs.items() if k not in varying}
    ds.attrs = {**common, **ds.attrs}
    ds.attrs.update(own)
    ds.attrs["warnings"] = " | ".join(sorted({p.attrs["warnings"] for p in parts}))
    return ds


def _z_grid(study, coords: list[dict], parts: list[xr.Dataset]) -> xr.Dataset:
    by_regime: dict[int, list[xr.Dataset]] = {}
    for where, part in zip(coords, parts, strict=True):
        by_regime.setdefault(where["regime"], []).append(part)
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
                [_regime_value(study, g, parts, coords, name) for g in study.regimes],
                {"units": unit},
            )
            for name, unit in (("drive", "N m s"), ("c_theta", "kg m2/s"), ("c_phi", "kg m2/s"))
        },
        preset=("regime", [g.preset for g in study.regimes]),
        from_paper=("regime", [g.from_paper for g in study.regimes]),
    ).drop_vars("theta2_0")
    ds.attrs = {"bpm": study.bpm, "theta1_0": study.theta1, "theta_dot0": 0.0}
    return ds


def _regime_value(study, regime, parts, coords, name) -> float:
    for where, part in zip(coords, parts, strict=True):
        if study.regimes[where["regime"]] is regime:
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

"""What a point keeps of its `simulate` result: the reductions written to the store.

Contract: `kept_dataset(spec, result)` turns the `metrosync.simulate` dataset of one
point into the small dataset stored for it, by the point's ``keep``:

``r_eq``        per-run equilibrium r (both phases) and status (a sweep point)
``r_eq+r``      the same plus r(t) of every run (``sweep --keep-r``)
``run_mean_r``  per-run r_eq and status, the run-mean r(t) and the realized
                spread of the drawn frequencies (the paper's ensemble studies)
``z``           the z order parameter of two metronomes per run (the paper's §6)

``kept_dataset(spec, None, error)`` is the record of a failed point: the error
message, and NaN r_eq with the `STATUS_FAILED` bit for each run. Every dataset
carries the point's ``key`` and ``seed`` and an ``error`` ("" when it succeeded) in
``attrs``. The store adds what the point cost (`metrosync.sweeps.store`).

This module's source is part of every point's key (`metrosync.sweeps.points`):
changing a reduction changes what a point holds, so stored points are recomputed.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..observables import z_order
from ..status import STATUS_FAILED
from .points import PointSpec


def kept_dataset(spec: PointSpec, result: xr.Dataset | None, error: str = "") -> xr.Dataset:
    """What is stored of one point (see the module docstring)."""
    attrs = {"key": spec.key, "seed": spec.kwargs.get("seed", 0), "error": error}
    if result is None:
        return _failed(spec, attrs)
    if spec.keep == "run_mean_r":
        ds = reduce_ensemble(result)
    elif spec.keep == "z":
        ds = reduce_z(result)
    else:
        ds = _sweep_point(spec, result)
    # The simulation's own settings and model parameters (scalars) describe the point.
    ds.attrs = {**_scalar_attrs(result.attrs), **ds.attrs, **attrs}
    return ds


def _failed(spec: PointSpec, attrs: dict) -> xr.Dataset:
    runs = spec.kwargs.get("runs", 1)
    nan = np.full(runs, np.nan)
    data = {
        "r_eq": ("run", nan),
        "r_eq_analytic": ("run", nan.copy()),
        "status": ("run", np.full(runs, STATUS_FAILED, dtype=np.int8)),
    }
    return xr.Dataset(data, attrs={**attrs, "r_eq_mean": np.nan, "r_eq_std": np.nan})


def _sweep_point(spec: PointSpec, result: xr.Dataset) -> xr.Dataset:
    data = {
        "r_eq": ("run", result.r_eq.values),
        "r_eq_analytic": ("run", result.r_eq_analytic.values),
        "status": ("run", result.status.values.astype(np.int8)),
    }
    coords = {}
    if "r_eq_group" in result:  # groups (`metrosync.groups`): each group's r_eq
        data["r_eq_group"] = (("run", "group"), result.r_eq_group.values)
    if spec.keep_r:
        data["r"] = (("time", "run"), result.r.values)
        data["r_crossing"] = (("time", "run"), result.r_crossing.values)
        coords["time"] = result.time.values
    attrs = {"r_eq_mean": result.attrs["r_eq_mean"], "r_eq_std": result.attrs["r_eq_std"]}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def reduce_ensemble(ds: xr.Dataset) -> xr.Dataset:
    """Keep what the paper's figures and report need: run-mean r(t) and per-run r_eq."""
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


def reduce_z(ds: xr.Dataset) -> xr.Dataset:
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


def _scalar_attrs(attrs: dict) -> dict:
    return {k: v for k, v in attrs.items() if isinstance(v, str | int | float | np.number | list)}

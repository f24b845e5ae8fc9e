"""The point store: one file per finished grid point, and the merged sweep.

Contract: a store is a directory. ``points/<key>.nc`` holds one finished point, named
by its content key (`metrosync.sweeps.points`), written to a temporary file and moved
into place (`metrosync._files.atomic_path`), so a file at that name is always
complete; a crash loses at most the points in flight. A point is finished when its
file exists; a run started again skips those points, and a point whose inputs or
code changed has another key, so a stale file is never read for it. Each file also
records what the point cost, ``compute_seconds`` and ``osc_steps`` (oscillator-steps)
with the ``host`` that computed it, so the cost of a run can be estimated from
reused points too. ``log.jsonl`` gets one line per point computed (key, seconds,
host), appended after the file is in place.

`merge` gathers the points of a grid into one `xarray.Dataset` with one dimension per
swept parameter (plus ``run``, and ``time`` when r(t) is kept). Apart from the cost
attributes, which the merge leaves out, point files hold only deterministic content,
so the merge does not depend on which executor ran them.
"""

from __future__ import annotations

import json
import socket
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._files import write_netcdf
from ..observables.order import ensemble_statistics
from ..status import STATUS_ABSENT, STATUS_FAILED
from ..status import SWEEP_FLAG_MEANINGS as FLAG_MEANINGS
from .grid import UNITS, Grid

#: What each parameter is, for the coordinates of a merged sweep.
LONG_NAMES = {
    "amplitude": "start amplitude at random phases",
    "n": "metronomes on the disk",
    "bpm": "nominal beat frequency",
    "sigma_bpm": "spread (std) of the natural frequencies",
    "runs": "independent runs",
    "duration": "simulated time",
    "dt": "time step",
    "seed": "sweep seed",
    "drive": "escapement impulse M",
    "c_theta": "pendulum friction",
    "c_phi": "disk friction",
    "inertia": "disk inertia J",
    "j0": "disk inertia without metronomes",
    "j_per_metronome": "disk inertia added per metronome",
    "w1": "fixed weight",
    "w2": "sliding weight",
    "l1": "distance of the fixed weight below the pivot",
    "radius": "disk radius",
    "g": "gravitational acceleration",
    "group_offset_bpm": "BPM added to every group after the first",
    "tuning": "how a nominal BPM becomes a slider position",
}


class PointStore:
    """A directory of finished points (see the module docstring)."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.points = self.root / "points"
        self.log_path = self.root / "log.jsonl"

    def path(self, key: str) -> Path:
        """File of the point with content hash ``key``."""
        return self.points / f"{key}.nc"

    def has(self, key: str) -> bool:
        """True when the point ``key`` is finished (its file exists)."""
        return self.path(key).is_file()

    def failed(self, key: str) -> bool:
        """True when the stored point records a failed simulation."""
        with xr.open_dataset(self.path(key), engine="h5netcdf") as ds:
            return bool(ds.attrs.get("error", ""))

    def write(
        self,
        ds: xr.Dataset,
        *,
        seconds: float = float("nan"),
        host: str = "",
        work: int | None = None,
    ) -> xr.Dataset:
        """Write one point atomically with what it cost, then log it; returns the
        point as written (with its cost attributes).

        ``seconds`` : compute time of the point.   ``host`` : the machine that ran it.
        ``work`` : oscillator-steps simulated (0 for a failed point; default 0).
        """
        key = ds.attrs["key"]
        host = host or socket.gethostname()
        ds = ds.assign_attrs(compute_seconds=float(seconds), osc_steps=int(work or 0), host=host)
        write_netcdf(ds, self.path(key))
        line = json.dumps({"key": key, "seconds": round(seconds, 4), "host": host})
        with open(self.log_path, "a") as log:
            log.write(line + "\n")
        return ds

    def read(self, key: str) -> xr.Dataset:
        """Load the point ``key``; `OSError` if its file holds another key."""
        with xr.open_dataset(self.path(key), engine="h5netcdf") as ds:
            loaded = ds.load()
        if loaded.attrs.get("key") != key:
            raise OSError(f"point file {self.path(key)} holds key {loaded.attrs.get('key')!r}")
        return loaded

    def cost(self, key: str) -> tuple[float, int]:
        """(compute seconds, oscillator-steps) stored with the point ``key``."""
        with xr.open_dataset(self.path(key), engine="h5netcdf") as ds:
            attrs = ds.attrs
            return float(attrs.get("compute_seconds", np.nan)), int(attrs.get("osc_steps", 0))

    def kept(self, keys) -> int:
        """How many of ``keys`` are finished (for "k of n points kept" messages)."""
        return sum(self.has(key) for key in keys)

    def logged_keys(self) -> list[str]:
        """Keys of every computation logged, in order (a key twice = computed twice)."""
        if not self.log_path.exists():
            return []
        lines = self.log_path.read_text().splitlines()
        return [json.loads(line)["key"] for line in lines if line.strip()]


def merge(grid: Grid, store: PointStore, batches=None) -> xr.Dataset:
    """One dataset for the whole grid; a point not in the store is marked ``missing``.

    ``batches`` : with ``grid.target_error``, each point's batches by grid index
    (`metrosync.sweeps.adaptive`); a point's runs are those of its stored batches.

    Variables (``*axes`` = one dimension per swept parameter, in grid order):
    r_eq, r_eq_analytic (*axes, run); status (*axes, run) int8 bit flags, -1 for no
    such run; r_eq_mean, r_eq_std, n_flagged, seed, error (*axes); with groups
    r_eq_group (*axes, run, group) and its mean over runs r_eq_group_mean (*axes,
    group); with ``keep_r`` r, r_crossing (*axes, time, run); with ``target_error``
    n_runs and r_eq_error, the standard error of r_eq_mean (*axes).
    """
    specs = list(grid.points())
    batches = batches or {spec.index: [spec] for spec in specs}
    loaded = {spec.index: _read_batches(store, batches[spec.index]) for spec in specs}
    shape = grid.shape
    n_run = max(
        max((ds.sizes["run"] for ds in loaded.values() if ds is not None), default=0),
        max(spec.kwargs["runs"] for spec in specs),
    )
    r_eq = np.full((*shape, n_run), np.nan)
    r_eq_analytic = np.full((*shape, n_run), np.nan)
    status = np.full((*shape, n_run), STATUS_ABSENT, dtype=np.int8)
    mean = np.full(shape, np.nan)
    std = np.full(shape, np.nan)
    seed = np.zeros(shape, dtype=np.int64)
    error = np.full(shape, "", dtype=object)
    times = [ds.time.values for ds in loaded.values() if ds is not None and "time" in ds.coords]
    time = max(times, key=len) if times else None
    if time is not None:
        r_t = np.full((*shape, len(time), n_run), np.nan)
        r_cross = np.full((*shape, len(time), n_run), np.nan)
    n_groups = len(grid.groups) if grid.groups else 0
    r_eq_group = np.full((*shape, n_run, n_groups), np.nan)
    for spec in specs:
        i = spec.index
        seed[i] = spec.kwargs["seed"]
        ds = loaded[i]
        if ds is None:
            error[i] = "missing"
            continue
        runs = ds.sizes["run"]
        r_eq[i][:runs] = ds.r_eq.values
        r_eq_analytic[i][:runs] = ds.r_eq_analytic.values
        status[i][:runs] = ds.status.values
        mean[i], std[i] = ds.attrs["r_eq_mean"], ds.attrs["r_eq_std"]
        error[i] = ds.attrs.get("error", "")
        if "r_eq_group" in ds:
            r_eq_group[i][:runs] = ds.r_eq_group.values
        if time is not None and "r" in ds:
            steps = ds.sizes["time"]
            r_t[i][:steps, :runs] = ds.r.values
            r_cross[i][:steps, :runs] = ds.r_crossing.values
    dims = tuple(grid.axes)
    flags = {
        "long_name": "run status bit flags (0 ok, -1 no such run)",
        "flag_masks": np.array(list(FLAG_MEANINGS), dtype=np.int8),
        "flag_meanings": " ".join(FLAG_MEANINGS.values()),
    }
    # A failed point has no runs to flag: its runs carry STATUS_FAILED, counted apart.
    flagged = ((status > 0) & ((status & STATUS_FAILED) == 0)).sum(axis=-1).astype(np.int64)
    data: dict[str, Any] = {
        "r_eq": ((*dims, "run"), r_eq, {"long_name": "equilibrium r per run (crossing phases)"}),
        "r_eq_analytic": (
            (*dims, "run"),
            r_eq_analytic,
            {"long_name": "equilibrium r per run (analytic phase)"},
        ),
        "status": ((*dims, "run"), status, flags),
        "r_eq_mean": (dims, mean, {"long_name": "equilibrium r, mean over runs"}),
        "r_eq_std": (dims, std, {"long_name": "sigma_r: std of equilibrium r over runs"}),
        "n_flagged": (
            dims,
            flagged,
            {"long_name": "runs flagged overturned, diverged or stopped (not failed points)"},
        ),
        "seed": (dims, seed, {"long_name": "seed passed to simulate for this point"}),
        "error": (dims, error.astype(str), {"long_name": "why the point has no result ('' = ok)"}),
    }
    coords: dict[str, Any] = {
        name: (name, np.asarray(values), _describe(name)) for name, values in grid.axes.items()
    }
    coords["run"] = ("run", np.arange(n_run), {"long_name": "run of the ensemble at each point"})
    if time is not None:
        data["r"] = ((*dims, "time", "run"), r_t, {"long_name": "Kuramoto r (analytic phase)"})
        data["r_crossing"] = (
            (*dims, "time", "run"),
            r_cross,
            {"long_name": "Kuramoto r (crossing phases)"},
        )
        coords["time"] = ("time", time, {"units": "s", "long_name": "simulated time"})
    if grid.target_error is not None:
        runs_done = (status != STATUS_ABSENT).sum(axis=-1).astype(np.int64)
        finite = np.isfinite(r_eq).sum(axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            standard_error = np.where(finite > 1, std / np.sqrt(finite), np.nan)
        data["n_runs"] = (dims, runs_done, {"long_name": "runs simulated at this point"})
        data["r_eq_error"] = (
            dims,
            standard_error,
            {"long_name": "standard error of r_eq_mean (r_eq_std / sqrt(finite runs))"},
        )
    if n_groups:
        data["r_eq_group"] = (
            (*dims, "run", "group"),
            r_eq_group,
            {"long_name": "equilibrium r of each group per run (crossing phases)"},
        )
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a point without finite runs
            group_mean = np.nanmean(r_eq_group, axis=-2)
        data["r_eq_group_mean"] = (
            (*dims, "group"),
            group_mean,
            {"long_name": "equilibrium r of each group, mean over runs"},
        )
    return xr.Dataset(data, coords=coords, attrs=grid.describe())


def _read_batches(store: PointStore, batches) -> xr.Dataset | None:
    """A point's stored batches as one dataset along ``run`` (None without its first);
    its r_eq_mean and r_eq_std are those of all its runs."""
    stored = [store.read(b.key) for b in batches if store.has(b.key)]
    if not stored or not store.has(batches[0].key):
        return None
    if len(stored) == 1:
        return stored[0]
    ds = xr.concat(
        stored,
        dim="run",
        data_vars="minimal",
        coords="minimal",
        compat="override",
        join="override",
        combine_attrs="override",
    )
    mean, spread = ensemble_statistics(ds.r_eq.values)
    return ds.assign_attrs(r_eq_mean=mean, r_eq_std=spread)


def _describe(name: str) -> dict[str, str]:
    """Attributes of the coordinate of swept parameter ``name``."""
    attrs = {"long_name": LONG_NAMES.get(name, name)}
    if name in UNITS:
        attrs["units"] = UNITS[name]
    return attrs


def write_dataset(ds: xr.Dataset, path: str | Path) -> Path:
    """Write the merged sweep to NetCDF atomically (a crash never leaves half a file)."""
    return write_netcdf(ds, path)

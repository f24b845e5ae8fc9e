"""`sweep`: run a parameter grid, resumably, on any executor, into one dataset.

Contract: ``sweep(grid, store)`` computes every point of ``grid`` that the store does
not already hold, writes each as soon as it is done, and returns the merged dataset
(see `metrosync.sweeps.store.merge`) with a report of what was computed, reused,
failed or lost. Calling it again with the same grid and store finishes an
interrupted sweep and gives the same dataset as an uninterrupted one.
"""

from __future__ import annotations

import itertools
import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._words import plural
from ..budget import Budget, simulation_budget
from ..errors import Interrupted, OverturnWarning, ParameterError
from ..simulation.request import record_stride
from . import adaptive
from .executors import Execution, check_scheduler, execute
from .grid import MODEL_PARAMETERS, Grid
from .store import PointStore, merge, write_dataset


@dataclass(frozen=True)
class SweepResult:
    """The merged dataset and what this call did.

    dataset : the merged sweep.   store : the store directory.
    reused : points found in the store.   execution : points computed now, failed
    (stored with their error) and lost (not stored; a rerun computes them).
    """

    dataset: xr.Dataset
    grid: Grid
    store: Path
    reused: int
    execution: Execution
    out: Path | None = None
    rounds: int = 1

    @property
    def complete(self) -> bool:
        """True when every point is in the store (failed points count as stored)."""
        return not bool((self.dataset.error == "missing").any())

    def failures(self) -> list[tuple[dict[str, Any], str]]:
        """(coords, message) of every point without a result, failed or missing."""
        ds = self.dataset
        out = []
        for index in itertools.product(*(range(n) for n in self.grid.shape)):
            message = str(ds.error.values[index])
            if message:
                coords = {
                    name: vals[i]
                    for (name, vals), i in zip(self.grid.axes.items(), index, strict=True)
                }
                out.append((coords, message))
        return out

    def _precision_line(self) -> str:
        """How many runs the points took to reach `target_error`, and which did not."""
        target, cap = self.grid.target_error, self.grid.max_runs
        assert target is not None  # only called with a target
        # Read from the merged file: the points that have a result, and their runs.
        ds = self.dataset
        done = ds.error.values == ""
        finite = np.isfinite(ds.r_eq.values).sum(axis=-1)[done]
        error = ds.r_eq_error.values[done]
        runs = finite.tolist()
        short = error[~(error <= target)]
        line = (
            f"  runs until the standard error of mean r_eq is <= {target:g}: "
            + (_span(runs) + " a point" if runs else "no point finished")
            + f", in {plural(self.rounds, 'round')}"
        )
        if short.size:
            known = short[np.isfinite(short)]
            line += (
                f"; {plural(short.size, 'point')} stopped short (at `max_runs` = {cap}, or "
                f"with fewer than 2 finite runs)"
                + (f": standard error up to {known.max():.3g}" if known.size else "")
            )
        return line

    def summary(self) -> str:
        """Human-readable report: points computed and reused, throughput, failures."""
        ex = self.execution
        ds = self.dataset
        error = ds.error.values
        failed = int(((error != "") & (error != "missing")).sum())
        missing = int((error == "missing").sum())
        simulated = int((ds.status.values[error == ""] >= 0).sum())
        flagged = int(ds.n_flagged.sum())
        # With `target_error` a point is computed in batches of `runs`.
        unit = " batches" if self.grid.target_error is not None else ""
        lines = [
            f"metrosync sweep: {plural(self.grid.size, 'point')} over {', '.join(self.grid.axes)}; "
            f"{len(ex.computed)}{unit} computed, {self.reused} reused from {self.store}",
            f"  {ex.seconds:.2f} s wall, {ex.work:.3g} oscillator-steps, "
            f"{ex.throughput:.3g} oscillator-steps/s",
            f"  runs flagged (overturned/diverged/stopped): {flagged} of "
            f"{plural(simulated, 'run')} simulated"
            + ("; their r is not meaningful (status bits: metrosync.status)" if flagged else ""),
        ]
        if self.grid.target_error is not None:
            lines.append(self._precision_line())
        failures = self.failures()
        if failures:
            lines.append(
                f"  {plural(len(failures), 'point')} without a result: {failed} failed (the "
                f"simulation raised; its runs are not counted above), {missing} missing (not "
                f"computed yet):"
            )
            for coords, message in failures[:20]:
                where = ", ".join(f"{k}={v}" for k, v in coords.items())
                lines.append(f"    {where}: {message}")
            if len(failures) > 20:
                lines.append(f"    ... and {len(failures) - 20} more")
        if ex.lost:
            lines.append("  points lost with their worker are computed when the sweep runs again")
        if self.out is not None:
            lines.append(f"  wrote {self.out}")
        return "\n".join(lines)


def sweep(
    grid: Grid | Mapping[str, Any],
    store: str | Path,
    *,
    out: str | Path | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool | None = None,
    retry_failed: bool = False,
    fixed: Mapping[str, Any] | None = None,
    **grid_options: Any,
) -> SweepResult:
    """Run every point of a parameter grid and merge the results.

    Parameters
    ----------
    grid : a `Grid`, or its swept axes (name -> values)
        For example ``{"bpm": "150:220:2.5", "n": [7, 16]}``, completed by ``fixed``
        and ``grid_options`` (``seed``, ``preset``, ``keep_r``, ... see `Grid`).
    store : directory of finished points; reused across calls and across grids.
    out : also write the merged dataset to this NetCDF file (atomically).
    scheduler : None (in process), ``"local"`` (Dask LocalCluster on loopback) or
        ``"tcp://HOST:PORT"`` (an existing Dask cluster).
    n_workers : worker processes for ``"local"`` (default: one per core).
    progress : show a progress bar with ETA; default when stderr is a terminal.
    retry_failed : compute again the points stored as failed.

    Returns
    -------
    SweepResult, whose ``dataset`` has one dimension per swept parameter.
    """
    import sys

    check_scheduler(scheduler, n_workers)
    if not isinstance(grid, Grid):
        grid = Grid(axes=grid, fixed=fixed or {}, **grid_options)
    elif fixed or grid_options:
        raise TypeError("give `fixed` and grid options only with a mapping of axes, not a Grid.")
    _warn_overturn(grid)
    points = PointStore(store)
    plan = adaptive.start(grid)
    show = sys.stderr.isatty() if progress is None else progress
    execution, reused, rounds = Execution(), 0, 0
    specs = [batch for batches in plan.values() for batch in batches]
    try:
        # One round without `target_error`; with it, until no point needs another batch.
        while specs:
            todo = [
                spec
                for spec in specs
                if not points.has(spec.key) or (retry_failed and points.failed(spec.key))
            ]
            sweep_budget(specs, todo, scheduler=scheduler, n_workers=n_workers).check()
            done = execute(todo, points, scheduler=scheduler, n_workers=n_workers, progress=show)
            execution = execution.then(done)
            reused += len(specs) - len(todo)
            rounds += 1
            specs = adaptive.extend(grid, points, plan)
        dataset = merge(grid, points, plan)
        out_path = write_dataset(dataset, out) if out is not None else None
    except KeyboardInterrupt:
        planned = [batch.key for batches in plan.values() for batch in batches]
        raise Interrupted(
            f"{points.kept(planned)} of {plan_size(plan)} kept in {points.root}; run "
            f"the same command again to resume"
        ) from None
    return SweepResult(dataset, grid, points.root, reused, execution, out_path, rounds=rounds)


def _span(values) -> str:
    low, high = min(values), max(values)
    return f"{low}" if low == high else f"{low}-{high}"


def plan_size(plan) -> str:
    """The planned work in words: points, and batches when a point has several."""
    total = sum(len(batches) for batches in plan.values())
    if total == len(plan):
        return plural(total, "point")
    return f"{plural(total, 'batch')} of {plural(len(plan), 'point')}"


#: Memory of one point's dataset object while the sweep is merged, besides its arrays.
POINT_OVERHEAD = 50_000


def sweep_budget(specs, todo, *, scheduler=None, n_workers=None) -> Budget:
    """Memory and time of a sweep of ``specs`` that computes ``todo``, before it starts.

    Memory: the largest point's simulation (on each local worker; none for a remote
    cluster) or the merge, whichever is larger: every point's arrays loaded, the
    merged arrays, and r(t) of every run with ``keep_r``. Time: the points to compute,
    one after another, on this machine.
    """
    sims, merge = [], 0.0
    to_compute = {spec.key for spec in todo}
    for spec in specs:
        k = spec.kwargs
        steps = round(k["duration"] / k["dt"])
        try:
            every, _ = record_stride(k["record_every"], steps, k["dt"])
        except ParameterError:
            every = steps or 1  # the point fails, quickly
        records = steps // every + 1
        merge += 2 * (17.0 * k["runs"] + (16.0 * records * k["runs"] if spec.keep_r else 0.0))
        merge += POINT_OVERHEAD
        groups = k.get("groups") or ()  # records are kept per group, N is their total
        n = sum(g[0] for g in groups) if groups else k["n"]
        if spec.key in to_compute:
            sims.append(
                simulation_budget(
                    n=n,
                    runs=k["runs"],
                    steps=steps,
                    records=records * max(1, len(groups)),
                    trajectories=False,
                    integrator=k["integrator"],
                    backend=k["backend"],
                    dt=k["dt"],
                )  # fmt: skip
            )
    workers = {None: 1, "local": n_workers or os.cpu_count() or 1}.get(scheduler, 0)
    largest = max((b.nbytes for b in sims), default=0.0) * workers
    arrays = {"merged result": merge}
    if largest > merge:
        arrays = {"the largest point" + (f" on {workers} workers" if workers > 1 else ""): largest}
    seconds = sum(b.seconds for b in sims)
    work = sum(spec.work for spec in todo)
    fixes = "sweep fewer points, use fewer `runs` or a shorter `duration`"
    if any(spec.keep_r for spec in specs):
        fixes += ", or drop `keep_r` (--keep-r)"
    return Budget("the sweep", arrays, seconds, f"{len(todo)} points, {work:.2g} oscillator-steps",
                  fixes)  # fmt: skip


def _warn_overturn(grid: Grid) -> None:
    starts = grid.axes.get("amplitude", (grid.fixed.get("amplitude"),))
    high = [a for a in starts if a is not None and a > math.pi / 2]
    if high:
        warnings.warn(
            f"`amplitude` = {high[0]:g} rad starts the pendulums past pi/2: they overturn at "
            f"once; such runs are flagged in `status` and their r is not meaningful.",
            OverturnWarning,
            stacklevel=3,
        )
        return
    swept = [name for name in grid.axes if name in MODEL_PARAMETERS]
    for values in itertools.product(*(grid.axes[name] for name in swept)):
        params = grid.model_parameters(dict(zip(swept, values, strict=True)))
        if params.overturns:
            where = dict(zip(swept, values, strict=True))
            warnings.warn(
                f"with {params.name!r} parameters {where} the energy-balance "
                f"amplitude is {params.balance_amplitude:.2f} rad > pi/2: pendulums overturn; such "
                f"runs are flagged in `status`.",
                OverturnWarning,
                stacklevel=3,
            )
            return

"""Runs until the error is small enough: how many batches each point of a sweep needs.

Contract: with ``Grid.target_error`` set, a sweep point is not ``runs`` runs but a
list of batches of ``runs`` runs each (`Grid.batch`: the same point with new frequency
draws). `extend` reads the batches of every point that the store holds and adds the
batches that bring the standard error of the point's mean r_eq, s/√n over its finite
runs, down to the target: n ≥ (s/target)², with s the spread found so far, never past
``max_runs``. The sweep computes what was added and asks again, until nothing is.

Why: near the onset of synchronization r_eq spreads widely over frequency draws
(quenched disorder), far from it hardly at all, so a fixed number of runs large enough
at the onset wastes most of the work elsewhere. Each decision depends only on stored
results, so an interrupted sweep takes the same decisions when it runs again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .grid import Grid
from .points import PointSpec
from .store import PointStore

#: A point's batches, in order (batch 0 first), by grid index.
Plan = dict[tuple[int, ...], list[PointSpec]]


@dataclass(frozen=True)
class Precision:
    """Where a point stands: finite runs, the standard error of its mean r_eq, and the
    runs it needs for the target (NaN with fewer than 2 finite runs)."""

    runs: int
    error: float
    needed: float


def precision(r_eq: np.ndarray, target: float) -> Precision:
    """The `Precision` of per-run values ``r_eq`` (NaN runs are not counted)."""
    finite = np.asarray(r_eq, dtype=float)
    finite = finite[np.isfinite(finite)]
    if finite.size < 2:
        return Precision(int(finite.size), math.nan, math.nan)
    spread = float(np.std(finite, ddof=1))
    return Precision(int(finite.size), spread / math.sqrt(finite.size), (spread / target) ** 2)


def start(grid: Grid) -> Plan:
    """Every point's first batch."""
    return {spec.index: [spec] for spec in grid.points()}


def extend(grid: Grid, store: PointStore, plan: Plan) -> list[PointSpec]:
    """Add to ``plan`` the batches its points still need, and return them.

    A point gets none while one of its batches is not stored (lost or interrupted: the
    next round computes it first), when a batch failed, when it has fewer than two
    finite runs (no spread to go by), or once it holds ``max_runs``.
    """
    if grid.target_error is None or grid.max_runs is None:
        return []
    batch_runs = grid.fixed["runs"]
    most = grid.max_runs // batch_runs
    added = []
    for batches in plan.values():
        r_eq = stored_r_eq(store, batches) if len(batches) < most else None
        if r_eq is None:
            continue
        now = precision(r_eq, grid.target_error)
        if not now.error > grid.target_error:  # NaN (too few finite runs) stops too
            continue
        missing = now.needed - now.runs
        wanted = min(most, len(batches) + max(1, math.ceil(missing / batch_runs)))
        new = [grid.batch(batches[0], k) for k in range(len(batches), wanted)]
        batches.extend(new)
        added.extend(new)
    return added


def stored_r_eq(store: PointStore, batches: list[PointSpec]) -> np.ndarray | None:
    """The per-run r_eq of all of a point's batches, or None unless each is stored and
    succeeded."""
    if not all(store.has(b.key) for b in batches):
        return None
    stored = [store.read(b.key) for b in batches]
    if any(ds.attrs.get("error", "") for ds in stored):
        return None
    return np.concatenate([ds.r_eq.values for ds in stored])

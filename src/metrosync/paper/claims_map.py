"""The claims map: claims 1–5 under every reading, then the best readings again.

Contract: `ClaimsMapStudy` declares the map (`CLAIMS_MAP`): every reading of
`metrosync.paper.readings` at the ``screen`` level, and, in ``--full``, the ``best``
readings again at the paper's statistics. `run_claims_map(study, mode, compute)` (its
``run``) expands every reading into the points of its five studies at the mode's
``screen`` statistics, has ``compute(name, specs, label)`` simulate or reuse them
(`metrosync.paper.runner.compute_points`: the one point store, so an interrupted map
resumes), and judges each claim with the reproduction's own verdict
functions (`metrosync.paper.claims`). Readings are ranked by their score (1 per claim
reproduced, ½ per claim partly reproduced); with a ``best`` level (``--full``), the
``top`` readings are simulated again at the paper's statistics and judged again.

Each claim runs with the integrator and step of the study that checks it (the
``stepping`` of `metrosync.paper.studies`' Figs. 8, 10, 11 and z-study, carried into
every reading by `reading_studies`), so today's reading at the ``best`` level reuses
the reproduction's own points.

Two guards keep a verdict honest where the model leaves its domain: a claim whose
runs mostly overturn (a pendulum past the horizontal) is *not reproduced*, whatever
r says; and claim 4's sweep is not simulated for a reading whose energy-balance
swing already exceeds π/2 (every run overturns; claims 1–3 measure it).

Returns ``(dataset, specs, computed)``; the dataset holds, over ``reading`` × ``claim``
× ``level`` (``screen``, ``best``): ``verdict``, ``numbers`` (text), ``failed`` (the parts
of the claim found missing, joined by `` | ``) and ``score``, plus
the reading's axes as coordinates, its ``total`` score per level and ``rank``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from ..status import STATUS_OVERTURNED
from ..sweeps.points import PointSpec
from .claims import CHECKS, OMEGA_C_PAPER, Verdict
from .readings import (
    BEST,
    READINGS,
    SCORES,
    SCREEN,
    ClaimStatistics,
    Reading,
    axes_changed,
    reading_studies,
)
from .runner import Compute
from .studies import _check_mode

LEVELS = ("screen", "best")
CLAIMS = (1, 2, 3, 4, 5)
#: Fraction of overturned runs above which a claim's r is not meaningful.
OVERTURNED_LIMIT = 0.5


@dataclass(frozen=True)
class ClaimsMapGrid:
    """One mode of the claims map: the readings at ``screen``, and the ``top`` best
    again at ``best`` (None: no second pass). ``one_axis`` keeps only today's reading
    and those that change one axis from it (7 of the 25)."""

    screen: ClaimStatistics
    best: ClaimStatistics | None = None
    top: int = 2
    one_axis: bool = False


@dataclass(frozen=True)
class ClaimsMapStudy:
    """Claims 1–5 under every reading of the paper's parameters."""

    name: str
    figure: str
    title: str
    readings: tuple[Reading, ...]
    quick: ClaimsMapGrid
    full: ClaimsMapGrid

    def grid(self, mode: str) -> ClaimsMapGrid:
        return getattr(self, _check_mode(mode))

    def readings_of(self, mode: str) -> tuple[Reading, ...]:
        """The readings run in ``mode`` (see `ClaimsMapGrid.one_axis`)."""
        if not self.grid(mode).one_axis:
            return self.readings
        return tuple(r for r in self.readings if axes_changed(r) <= 1)

    def points(self, mode: str) -> list[PointSpec]:
        """The screen's points of ``mode`` (the best readings' are known after it)."""
        return planned_specs(self, mode)

    def point_label(self, spec: PointSpec) -> str:
        return spec.key[:12]

    def run(self, mode: str, out: Path, compute: Compute):
        return run_claims_map(self, mode, compute)


def _plan(readings, level: ClaimStatistics):
    """(reading, claim, study, specs) for every claim of every reading at ``level``."""
    out = []
    for reading in readings:
        for claim, study in reading_studies(reading, level).items():
            if (claim == 4 and reading.overturns) or (claim < 5 and not reading.tunable):
                out.append((reading, claim, study, []))
            else:
                out.append((reading, claim, study, study.points("quick")))
    return out


def planned_specs(study: ClaimsMapStudy, mode: str):
    """The screen's points of ``mode`` (the best readings' are known after the screen)."""
    screen = study.grid(mode).screen
    return [s for *_, specs in _plan(study.readings_of(mode), screen) for s in specs]


def best_work(study: ClaimsMapStudy, mode: str) -> float:
    """Oscillator-steps of the second pass: ``top`` readings at the ``best`` level
    (an upper bound: today's reading reuses the reproduction's points)."""
    grid = study.grid(mode)
    if grid.best is None:
        return 0.0
    per = [sum(s.work for *_, specs in _plan([r], grid.best) for s in specs)
           for r in study.readings_of(mode) if not r.overturns]  # fmt: skip
    return float(grid.top * (max(per) if per else 0.0))


def _judge(reading, claim, study, specs, loaded) -> Verdict:
    if not specs:
        why = (
            "claims 1–3 of the small-amplitude reading measure how many runs do"
            if reading.tunable
            else "and there is no steady swing for the steady-swing tuning to tune to"
        )
        return Verdict(
            claim,
            "not reproduced",
            "not simulated: the energy-balance swing 2M/(π c_θ) exceeds π/2 under this "
            f"reading, so every ensemble overturns ({why}).",
            study.name,
        )
    parts = [loaded[spec.key] for spec in specs]
    ds = study.assemble("quick", specs, parts)
    ds.attrs["study"] = study.name
    verdict = CHECKS[study.name](ds)
    if claim == 5:
        return verdict
    status = ds.status.values
    status = status[status >= 0]
    turned = float(np.mean((status & STATUS_OVERTURNED) != 0)) if status.size else 0.0
    if turned > OVERTURNED_LIMIT:
        return Verdict(
            claim,
            "not reproduced",
            f"{turned:.0%} of the runs overturn (|θ| > π/2): r no longer describes a "
            f"metronome's tick. As measured: {verdict.numbers}",
            study.name,
            {**verdict.values, "overturned": turned},
        )
    return Verdict(claim, verdict.verdict, verdict.numbers, study.name,
                   {**verdict.values, "overturned": turned})  # fmt: skip


def failed_checks(verdict: Verdict) -> list[str]:
    """The parts of a claim that its verdict finds missing, in words."""
    v, values = verdict.verdict, verdict.values
    if v == "reproduced":
        return []
    if values.get("overturned", 0.0) > OVERTURNED_LIMIT or verdict.numbers.startswith(
        "not simulated"
    ):
        return ["runs that stay below the horizontal (they overturn)"]
    if verdict.claim == 1:
        return ["every run of every N synchronizing completely"]
    if verdict.claim == 2:
        return ["a significant rise of r with ω₀ at N = 7"]
    if verdict.claim == 3:
        return ["a significant fall of r with N from 2 to 7"]
    if verdict.claim == 4:
        return [name for name, ok in values.get("checks", {}).items() if not ok]
    if verdict.claim == 5:
        parts = {
            "no locking without friction and drive": values.get("free_intermediate", 0) >= 0.5,
            "both in- and anti-phase locking with the small drive": values.get("small_both"),
            "only in-phase locking with the large drive": values.get("large_only_in_phase"),
        }
        return [name for name, ok in parts.items() if not ok]
    return [v]


def _position_gap(verdict: Verdict) -> float:
    """|σ_r peak − 185 BPM| at the largest N of a claim-4 verdict (inf when absent)."""
    feats = verdict.values.get("features")
    if not feats:
        return math.inf
    return abs(feats[max(feats)]["peak_bpm"] - OMEGA_C_PAPER)


def rank(readings, verdicts: dict) -> list[Reading]:
    """Readings by score (high first); ties by claim 4's distance to 185 BPM, then order."""

    def key(item):
        i, reading = item
        row = [verdicts[(reading, c)] for c in CLAIMS]
        score = sum(SCORES.get(v.verdict, 0.0) for v in row)
        return (-score, _position_gap(row[3]), i)

    return [r for _, r in sorted(enumerate(readings), key=key)]


def run_claims_map(study: ClaimsMapStudy, mode: str, compute: Callable):
    """Screen every reading, then re-run the best (see the module docstring)."""
    grid = study.grid(mode)
    readings = study.readings_of(mode)
    levels = {"screen": (readings, grid.screen)}
    verdicts: dict[str, dict] = {}
    every_spec, computed = [], None
    order = list(readings)
    for level in LEVELS:
        if level == "best":
            if grid.best is None:
                break
            levels["best"] = (order[: grid.top], grid.best)
        plan = _plan(*levels[level])
        specs = [s for *_, specs in plan for s in specs]
        labels = {s.key: f"{r.name}, claim {c}" for r, c, _, ss in plan for s in ss}
        now = compute(f"{study.name} ({level})", specs, lambda s, labels=labels: labels[s.key])
        computed = now if computed is None else computed.merge(now)
        every_spec += specs
        verdicts[level] = {(r, c): _judge(r, c, st, ss, now.loaded) for r, c, st, ss in plan}
        if level == "screen":
            order = rank(readings, verdicts["screen"])
    return _dataset(study, mode, verdicts, order), every_spec, computed


def _dataset(study: ClaimsMapStudy, mode: str, verdicts: dict, order) -> xr.Dataset:
    readings = list(study.readings_of(mode))
    shape = (len(readings), len(CLAIMS), len(LEVELS))
    verdict = np.full(shape, "", dtype=object)
    numbers = np.full(shape, "", dtype=object)
    failed = np.full(shape, "", dtype=object)
    score = np.full(shape, np.nan)
    for k, level in enumerate(LEVELS):
        for (reading, claim), v in verdicts.get(level, {}).items():
            i, j = readings.index(reading), CLAIMS.index(claim)
            verdict[i, j, k], numbers[i, j, k] = v.verdict, v.numbers
            failed[i, j, k] = " | ".join(failed_checks(v))
            score[i, j, k] = SCORES.get(v.verdict, 0.0)
    dims = ("reading", "claim", "level")
    ds = xr.Dataset(
        {
            "verdict": (dims, verdict.astype(str), {"long_name": "verdict ('' = not run)"}),
            "numbers": (dims, numbers.astype(str), {"long_name": "what was measured"}),
            "failed": (
                dims,
                failed.astype(str),
                {"long_name": "parts of the claim missing, ' | '"},
            ),
            "score": (dims, score, {"long_name": "1 reproduced, 0.5 partly, 0 otherwise"}),
        },
        coords={
            "reading": [r.name for r in readings],
            "claim": list(CLAIMS),
            "level": list(LEVELS),
            "sigma_reading": ("reading", [r.sigma for r in readings]),
            "tuning": ("reading", [r.tuning for r in readings]),
            "drive": ("reading", [r.drive for r in readings]),
            "inertia": ("reading", [r.inertia for r in readings]),
            "reaction": ("reading", [r.reaction for r in readings]),
            "description": ("reading", [r.describe() for r in readings]),
        },
    )
    ds["total"] = ds.score.sum("claim", min_count=1)
    ds["rank"] = ("reading", [order.index(r) + 1 for r in readings], {"long_name": "by screen"})
    grid = study.grid(mode)
    ds.attrs.update(top=grid.top if grid.best is not None else 0, runs_mode=mode)
    return ds


CLAIMS_MAP = ClaimsMapStudy(
    name="claims_map",
    figure="claims map",
    title="Which reading of the paper's parameters reproduces which claim",
    readings=READINGS,
    quick=ClaimsMapGrid(screen=SCREEN, one_axis=True),
    full=ClaimsMapGrid(screen=SCREEN, best=BEST, top=2),
)

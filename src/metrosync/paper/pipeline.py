"""`reproduce`: run the paper's studies, draw their figures, and write REPORT.md.

Contract: ``reproduce(out, mode=...)`` writes into ``out``

    <study>.nc, figures/<study>.png|pdf   for every study (`catalogue.STUDIES`)
    points/estimation/free_decay000.log   the estimation study's virtual light-gate log
    consistency.nc                        the parameter-consistency table
    fig9.nc, figures/fig9.png|pdf         only with ``experiment``
    points/<key>.nc, log.jsonl            the point store (`metrosync.sweeps.PointStore`)
    REPORT.md                             verdicts, numbers, interpretations, timings
    figures/large_n_sigma_*.png           only with ``large_n`` (the large-N study)

and returns a `Reproduction`. Re-running with the same ``out`` reuses the points whose
key (resolved parameters, package version, simulation sources) is unchanged and
recomputes the others. `plan` lists every point of a reproduction and `kept_points`
counts those already in the store (for a message after an interruption).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import xarray as xr

from .._files import write_netcdf
from .._version import __version__
from ..errors import Interrupted, ParameterError
from ..integrators._cache import compile_seconds
from ..sweeps import PointStore
from ..sweeps.executors import check_scheduler
from ..sweeps.points import PointSpec
from .catalogue import get_studies
from .claims import Verdict, all_verdicts
from .claims_map import ClaimsMapStudy, best_work
from .consistency import consistency_table
from .experiment import compare_experiment, find_experiment, lightgate_analyze
from .figures import PLOTTERS, plot_comparison
from .large_n import LargeN, amend_claim_4, read_large_n
from .report import write_report
from .runner import StudyResult, points_of, run_study
from .studies import (
    FIG8_TOP,
    MODES,
    EstimationStudy,
    Study,
    SweepStudy,
    TimeSeriesStudy,
    ZStudy,
)

NO_EXPERIMENT = (
    "no light-gate data was given. Run `metrosync reproduce --experiment DIR` with one "
    "folder of logs per ω₀ (DIR/160/*.txt or *.log, DIR/192/…) to compare with experiment."
)


@dataclass
class Reproduction:
    """Everything a reproduction produced (see the module docstring for the files)."""

    out: Path
    mode: str
    results: list[StudyResult]
    verdicts: list[Verdict]
    consistency: xr.Dataset
    figures: dict[str, list[Path]]
    report: Path | None = None
    comparison: xr.Dataset | None = None
    comparison_note: str = NO_EXPERIMENT
    full_work: dict[str, float] = field(default_factory=dict)
    wall_s: float = 0.0
    compile_s: float = 0.0
    version: str = __version__
    large_n: list[LargeN] = field(default_factory=list)

    @property
    def datasets(self) -> dict[str, xr.Dataset]:
        return {r.study.name: r.dataset for r in self.results}


def reproduce(
    out: Path | str = "results",
    *,
    mode: str = "quick",
    studies: Sequence[str | Study] | None = None,
    experiment: Path | str | None = None,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    large_n: Sequence[Path | str] = (),
) -> Reproduction:
    """Reproduce the paper's simulation figures and check its claims.

    Parameters
    ----------
    out : output folder (created).
    mode : ``"quick"`` (reduced statistics) or ``"full"`` (the paper's, 100 runs a
        point; the README gives the measured times of both).
    studies : study names or `Study` objects; default every study in `STUDIES`.
    experiment : folder of light-gate logs, one sub-folder per ω₀ named by its BPM;
        adds Fig. 9. Checked before anything runs.
    progress : show progress bars.   log : called with one line per finished step.
    scheduler, n_workers : where the points run, as for `metrosync.sweep`: None (in
        process), ``"local"`` (a Dask LocalCluster of ``n_workers``) or
        ``"tcp://HOST:PORT"``. Checked before anything runs.
    large_n : merged sweeps of the large-N study (`studies/large_n/*.toml`), the paper's
        σ first; adds its section and takes claim 4's check of where the transition
        sits from it (`paper.large_n`). Read before anything runs.

    Returns
    -------
    Reproduction
    """
    if mode not in MODES:
        raise ParameterError(f"unknown `mode` {mode!r}; choose one of {list(MODES)}.")
    started = time.perf_counter()
    out = Path(out)
    chosen = _resolve(studies)
    check_scheduler(scheduler, n_workers)
    if experiment is not None:
        find_experiment(Path(experiment))
        lightgate_analyze()
    say = log or (lambda line: None)
    if large_n:
        say("large-N study: " + ", ".join(str(p) for p in large_n))
    studies_large_n = [read_large_n(path) for path in large_n]
    try:
        rep = _reproduce(out, mode, chosen, experiment, progress, say, started, scheduler,
                         n_workers, studies_large_n)  # fmt: skip
    except KeyboardInterrupt:
        kept, total = kept_points(out, mode, chosen)
        raise Interrupted(
            f"{kept} of {total} points kept in {PointStore(out).points}; run the same command "
            f"again to resume"
        ) from None
    return rep


def _reproduce(
    out, mode, chosen, experiment, progress, say, started, scheduler, n_workers, large_n
):
    compiled = compile_seconds()
    say("parameter consistency table")
    consistency = consistency_table(_bpms(chosen, mode))
    write_netcdf(consistency, out / "consistency.nc")

    results, figures = [], {}
    for study in chosen:
        calls = (
            "calibration procedure"
            if isinstance(study, EstimationStudy)
            else f"{len(points_of(study, mode))} simulate calls"
        )
        say(f"{study.name}: {study.figure} ({calls})")
        result = run_study(
            study, mode, out, progress=progress, log=say if mode == "full" else None,
            scheduler=scheduler, n_workers=n_workers,
        )  # fmt: skip
        results.append(result)
        figures[study.name] = PLOTTERS[type(study).__name__](
            result.dataset, out / "figures" / study.name
        )
        say(f"  {study.name}: {result.wall_s:.1f} s -> {result.path}")

    rep = Reproduction(
        out=out,
        mode=mode,
        results=results,
        verdicts=[],
        consistency=consistency,
        figures=figures,
        full_work={s.name: _full_work(s) for s in chosen},
        large_n=large_n,
    )
    if experiment is not None:
        sim = rep.datasets.get(FIG8_TOP.name)
        if sim is None:
            sim = run_study(
                FIG8_TOP, mode, out, progress=progress, scheduler=scheduler, n_workers=n_workers
            ).dataset
        rep.comparison = compare_experiment(Path(experiment), sim)
        write_netcdf(rep.comparison, out / "fig9.nc")
        figures["fig9"] = plot_comparison(rep.comparison, out / "figures" / "fig9")
        rep.comparison_note = f"Simulated r from the `{FIG8_TOP.name}` study ({mode} mode)."
    rep.verdicts = all_verdicts(rep.datasets)
    if large_n:
        rep.verdicts = [amend_claim_4(v, large_n) if v.claim == 4 else v for v in rep.verdicts]
    rep.wall_s = time.perf_counter() - started
    rep.compile_s = compile_seconds() - compiled
    rep.report = write_report(out / "REPORT.md", rep)
    say(f"wrote {rep.report}")
    return rep


def plan(mode: str = "quick", studies: Sequence[str | Study] | None = None) -> list[PointSpec]:
    """Every point a reproduction in ``mode`` computes or reuses, in run order."""
    if mode not in MODES:
        raise ParameterError(f"unknown `mode` {mode!r}; choose one of {list(MODES)}.")
    return [spec for study in _resolve(studies) for spec in points_of(study, mode)]


def kept_points(
    out: Path | str, mode: str = "quick", studies: Sequence[str | Study] | None = None
) -> tuple[int, int]:
    """(points of the reproduction already in the store of ``out``, points in all)."""
    specs = plan(mode, studies)
    return PointStore(out).kept(spec.key for spec in specs), len(specs)


def _full_work(study: Study) -> float:
    """Oscillator-steps of ``study`` in ``--full`` (the claims map's second pass included)."""
    work = float(sum(p.work for p in points_of(study, "full")))
    if isinstance(study, ClaimsMapStudy):
        work += best_work(study, "full")
    return work


def _resolve(studies) -> tuple[Study, ...]:
    if studies is None:
        return get_studies()
    return tuple(get_studies([s])[0] if isinstance(s, str) else s for s in studies)


def _bpms(studies: Sequence[Study], mode: str) -> list[float]:
    bpms: set[float] = set()
    for s in studies:
        if isinstance(s, TimeSeriesStudy):
            bpms |= {c.bpm for c in s.cases}
        elif isinstance(s, SweepStudy):
            bpms |= set(s.grid(mode).bpms)
        elif isinstance(s, ZStudy | EstimationStudy):
            bpms.add(s.bpm)
    return sorted(bpms) or [192.0]

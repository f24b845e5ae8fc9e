"""The paper's simulation studies, declared as data.

Contract: every study is a frozen dataclass that says *what* to simulate (model
parameters, the grid of cases, the statistics of each mode); each kind of study knows
its points (calls of the public `metrosync.simulate`), a label for each and how its
points are assembled (`points`, `point_label`, `run`, `assemble`), which is all the
engine, `metrosync.paper.runner`, asks of it (`runner.Study`).
A study's ``quick`` and ``full`` fields hold the statistics of the two modes:
``full`` follows the paper (100 runs a point), ``quick`` is reduced so that each
verdict of the report still rests on a measurable effect.

Adding a study is a declarative change: append an instance to
`metrosync.paper.catalogue.STUDIES` (and, for a new kind of study, give it those
methods and a plotter in `figures`).

Units: BPM (ω = π·BPM/60), seconds, radians. The σ columns of the paper's Tables 1
and 2 are converted by `paper_sigma_to_bpm` (docs/model.md §6.4).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..sweeps.points import PointSpec, make_point
from .assemble import assemble_sweep, assemble_time_series, assemble_z
from .runner import PAPER_STEPPING, Compute, Stepping, Study, ensemble_points, run_points

#: Runs per `simulate` call of the z-study: bounds the memory of full trajectories.
Z_BATCH = 12

#: The logger's clock tick, s (paper §2): the unit in which Tables 1–2 read sensibly.
LOGGER_TICK = 64e-6

#: Paper Table 1: σ of the seven metronomes' natural frequencies at each nominal ω₀,
#: in the paper's printed unit "BPM·10⁻⁷".
TABLE1_SIGMA = {160: 8.4, 168: 7.9, 176: 7.8, 184: 9.8, 192: 8.5, 208: 8.7}
#: Paper Table 2: σ at ω₀ = 192 BPM for each number of metronomes N, "BPM·10⁻⁷".
TABLE2_SIGMA = {2: 5.1, 3: 8.1, 4: 7.5, 5: 7.1, 6: 6.7, 7: 8.5}
#: The σ the paper fixes for Fig. 10, "BPM·10⁻⁷" (the mean of Table 1, rounded).
FIG10_SIGMA = 8.0

MODES = ("quick", "full")

#: What each mode cost, measured with `python benchmarks/reproduce.py [--full]` on the
#: 2-core x86-64 development machine. `reproduce --help`, the README and REPORT.md all
#: quote these words (a test checks that they agree); REPORT.md adds its own timings.


def paper_sigma_to_bpm(value):
    """Convert a σ printed in the paper's Tables 1–2 to BPM (docs/model.md §6.4).

    The tables print σ ≈ 8 in units of "BPM·10⁻⁷", far too small to desynchronize
    anything if taken literally. We read ``value × 10⁻⁷`` as beats per 64 µs clock
    tick of the light-gate logger, so

        σ_BPM = value × 10⁻⁷ / 64×10⁻⁶ s × 60 s/min   (8 → 0.75 BPM, ≈ 0.4 %).

    Parameters
    ----------
    value : float or array, the number printed in the table (e.g. 8.5).

    Returns
    -------
    float or ndarray, σ in BPM.
    """
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise ParameterError(f"`value` must be finite and >= 0 (a table entry), got {value!r}.")
    out = arr * 1e-7 / LOGGER_TICK * 60.0
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class Statistics:
    """How much to simulate for each case of a study.

    runs : independent runs per case.   duration : simulated time per run, s.
    """

    runs: int
    duration: float

    def __post_init__(self) -> None:
        if isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 1:
            raise ParameterError(f"`runs` must be an integer >= 1, got {self.runs!r}.")
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise ParameterError(f"`duration` must be a finite time > 0 s, got {self.duration!r}.")


@dataclass(frozen=True)
class Case:
    """One ensemble of a time-series study: N metronomes at ``bpm`` with spread σ (BPM)."""

    n: int
    bpm: float
    sigma_bpm: float
    label: str


@dataclass(frozen=True)
class TimeSeriesStudy:
    """r(t) averaged over runs, one curve per case (paper Figs. 8 and 11)."""

    name: str
    figure: str
    title: str
    cases: tuple[Case, ...]
    quick: Statistics
    full: Statistics
    #: Integrator and step of every point, chosen from measured accuracy (see `STEPPING`).
    stepping: Stepping
    preset: str = "default"
    legend_title: str = ""
    #: Model parameters changed from the preset, by name (a reading of the claims map).
    changes: tuple[tuple[str, float | str], ...] = ()

    def statistics(self, mode: str) -> Statistics:
        return getattr(self, _check_mode(mode))

    def points(self, mode: str) -> list[PointSpec]:
        """One ensemble point per case."""
        cells = [
            (f"case{i:02d}", c.n, c.bpm, c.sigma_bpm, {"case": i}) for i, c in enumerate(self.cases)
        ]
        return ensemble_points(
            self.name, cells, self.statistics(mode), self.preset, self.changes, self.stepping
        )

    def point_label(self, spec: PointSpec) -> str:
        return self.cases[spec.coords["case"]].label

    def run(self, mode: str, out: Path, compute: Compute):
        return run_points(self, mode, out, compute)

    def assemble(self, mode: str, specs: list[PointSpec], parts: list[xr.Dataset]):
        return assemble_time_series(self, parts)


@dataclass(frozen=True)
class SweepGrid:
    """The (N, ω₀) grid and statistics of a sweep in one mode."""

    ns: tuple[int, ...]
    bpms: tuple[float, ...]
    stats: Statistics


@dataclass(frozen=True)
class SweepStudy:
    """Equilibrium r and σ_r against ω₀ for several N at fixed σ (paper Fig. 10)."""

    name: str
    figure: str
    title: str
    sigma_bpm: float
    quick: SweepGrid
    full: SweepGrid
    #: Integrator and step of every point, chosen from measured accuracy (see `STEPPING`).
    stepping: Stepping
    preset: str = "default"
    #: Model parameters changed from the preset, by name (a reading of the claims map).
    changes: tuple[tuple[str, float | str], ...] = ()

    def grid(self, mode: str) -> SweepGrid:
        return getattr(self, _check_mode(mode))

    def points(self, mode: str) -> list[PointSpec]:
        """One ensemble point per (N, ω₀) of the mode's grid."""
        grid = self.grid(mode)
        cells = [
            (f"n{n:04d}_bpm{bpm:07.2f}", n, bpm, self.sigma_bpm, {"n": n, "bpm": bpm})
            for n in grid.ns
            for bpm in grid.bpms
        ]
        return ensemble_points(
            self.name, cells, grid.stats, self.preset, self.changes, self.stepping
        )

    def point_label(self, spec: PointSpec) -> str:
        return f"N = {spec.coords['n']}, ω₀ = {spec.coords['bpm']:g} BPM"

    def run(self, mode: str, out: Path, compute: Compute):
        return run_points(self, mode, out, compute)

    def assemble(self, mode: str, specs: list[PointSpec], parts: list[xr.Dataset]):
        return assemble_sweep(self, mode, parts)


@dataclass(frozen=True)
class Regime:
    """A parameter regime of the two-metronome z-study: a preset plus named changes."""

    label: str
    preset: str = "default"
    changes: tuple[tuple[str, float], ...] = ()
    from_paper: bool = True


@dataclass(frozen=True)
class ZGrid:
    """θ₂(0) grid and run length of the z-study in one mode."""

    theta2: tuple[float, ...]
    duration: float
    record_every: int = 2


@dataclass(frozen=True)
class ZStudy:
    """z against θ₂(0) for two identical metronomes (paper §6), one curve per regime."""

    name: str
    figure: str
    title: str
    regimes: tuple[Regime, ...]
    quick: ZGrid
    full: ZGrid
    #: Integrator and step of every point (see `STEPPING`); ``record_every`` counts steps.
    stepping: Stepping
    bpm: float = 192.0
    theta1: float = 0.1

    @property
    def dt(self) -> float:
        """The time step, s (``stepping.dt``)."""
        return self.stepping.dt

    def grid(self, mode: str) -> ZGrid:
        return getattr(self, _check_mode(mode))

    def points(self, mode: str) -> list[PointSpec]:
        """Per regime, the θ₂(0) grid in batches of `Z_BATCH` runs, trajectories kept."""
        grid = self.grid(mode)
        theta2 = np.asarray(grid.theta2, dtype=float)
        out = []
        for r, regime in enumerate(self.regimes):
            for start in range(0, theta2.size, Z_BATCH):
                chunk = theta2[start : start + Z_BATCH]
                theta0 = np.column_stack([np.full(chunk.size, self.theta1), chunk])
                kwargs = {
                    "n": 2,
                    "bpm": self.bpm,
                    "runs": int(chunk.size),
                    "duration": grid.duration,
                    **self.stepping.kwargs(),
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

    def point_label(self, spec: PointSpec) -> str:
        c = spec.coords
        return f"regime {c['regime']}, θ₂(0) #{c['start']}–{c['start'] + spec.kwargs['runs'] - 1}"

    def run(self, mode: str, out: Path, compute: Compute):
        return run_points(self, mode, out, compute)

    def assemble(self, mode: str, specs: list[PointSpec], parts: list[xr.Dataset]):
        return assemble_z(self, [spec.coords for spec in specs], parts)


@dataclass(frozen=True)
class EstimationGrid:
    """Run lengths (s) and the c_φ scan (kg m²/s) of the §5 estimation study in one mode."""

    c_phi_scan: tuple[float, ...]
    decay_duration: float = 8.0
    steady_duration: float = 60.0
    disk_duration: float = 60.0


@dataclass(frozen=True)
class EstimationStudy:
    """The paper's §5 parameter estimation, run on simulated measurements of known truth.

    The "measurements" are simulated with the ``preset``'s parameters (the truth);
    the procedure then estimates c_θ from a free decay on a rigid support (drive off),
    M from the steady amplitude, and c_φ from the disk's amplitude under ``n``
    synchronized metronomes, as `metrosync.calibration` implements it. c_φ is also
    estimated at ``c_phi_control``, a value where the disk's amplitude depends on it.
    An estimate counts as recovered within ``tolerance`` (relative).
    """

    name: str
    figure: str
    title: str
    quick: EstimationGrid
    full: EstimationGrid
    preset: str = "default"
    bpm: float = 192.0
    n: int = 7
    decay_theta0: float = 0.8
    gate_offset: float = 0.05
    gate_width: float = 0.02
    steady_theta0: float = 0.3
    c_phi_control: float = 2.0
    c_phi_bracket: tuple[float, float] = (1e-6, 10.0)
    #: The paper quotes each value to one significant figure; 5 % is well inside that.
    tolerance: float = 0.05

    def grid(self, mode: str) -> EstimationGrid:
        return getattr(self, _check_mode(mode))

    def points(self, mode: str) -> list[PointSpec]:
        """None: its `simulate` calls are made inside `metrosync.calibration`."""
        return []

    def point_label(self, spec: PointSpec) -> str:
        return spec.key[:12]

    def run(self, mode: str, out: Path, compute: Compute):
        """The procedure, recomputed on every run (seconds); its light-gate log is written
        under ``out/points/<name>``."""
        from .estimation import run_estimation  # calibration and the light gate, on use

        return run_estimation(self, mode, Path(out) / "points" / self.name), [], None


def _check_mode(mode: str) -> str:
    if mode not in MODES:
        raise ParameterError(f"unknown `mode` {mode!r}; choose one of {list(MODES)}.")
    return mode


def _bpm_range(start: float, stop: float, step: float) -> tuple[float, ...]:
    return tuple(float(x) for x in np.arange(start, stop + step / 2, step))


#: Fig. 8 in both modes: the paper's 100 runs of the experiments' 10 minutes, cheap
#: enough to keep even in quick mode.
FIG8_STATISTICS = Statistics(runs=100, duration=600.0)
#: Fig. 8 (both panels): the paper's scheme and step. `located` at 0.04 s keeps each
#: case within 1.7 standard errors (benchmarks/reproduce_accuracy.py, 100 runs, the same
#: draws), but saves seconds and, through the claims map's 20-run screen, moves claim 3's
#: weak slope across 2 SE under some readings (6 readings tie at 3.5 of 5, then 4).
FIG8_STEPPING = PAPER_STEPPING

FIG8_TOP = TimeSeriesStudy(
    name="fig8_top",
    figure="Fig. 8 (top)",
    title="N = 7 metronomes at the experiment's frequencies (σ from Table 1)",
    cases=tuple(
        Case(7, float(bpm), paper_sigma_to_bpm(s), f"ω₀ = {bpm} BPM")
        for bpm, s in TABLE1_SIGMA.items()
    ),
    quick=FIG8_STATISTICS,
    full=FIG8_STATISTICS,
    stepping=FIG8_STEPPING,
    legend_title="N = 7",
)

FIG8_BOTTOM = TimeSeriesStudy(
    name="fig8_bottom",
    figure="Fig. 8 (bottom)",
    title="N = 2…7 metronomes at 192 BPM (σ from Table 2)",
    cases=tuple(Case(n, 192.0, paper_sigma_to_bpm(s), f"N = {n}") for n, s in TABLE2_SIGMA.items()),
    # The paper calls this decrease "not as evident" in simulation: it needs every run.
    quick=FIG8_STATISTICS,
    full=FIG8_STATISTICS,
    stepping=FIG8_STEPPING,
    legend_title="ω₀ = 192 BPM",
)

FIG10 = SweepStudy(
    name="fig10",
    figure="Fig. 10",
    title="Equilibrium r and σ_r against ω₀ (σ = 0.75 BPM)",
    sigma_bpm=paper_sigma_to_bpm(FIG10_SIGMA),
    quick=SweepGrid(
        ns=(7, 16, 64, 256),
        bpms=_bpm_range(150.0, 220.0, 5.0),
        stats=Statistics(runs=10, duration=300.0),
    ),
    full=SweepGrid(
        ns=(7, 16, 32, 64, 128, 256),
        bpms=_bpm_range(150.0, 220.0, 2.5),
        stats=Statistics(runs=100, duration=1000.0),
    ),
    # The paper's scheme and step: near the onset `located` reads r_eq 0.05–0.075 higher
    # at dt = 0.02 s (4–9 SE; it is the better converged, docs/reproducing.md) and loses
    # the onset at 0.04 s (−0.29 at N = 256, 172.5 BPM); benchmarks/reproduce_accuracy.py.
    stepping=PAPER_STEPPING,
)

FIG11 = TimeSeriesStudy(
    name="fig11",
    figure="Fig. 11",
    title="Identical metronomes (σ = 0) at 192 BPM",
    cases=tuple(Case(n, 192.0, 0.0, f"N = {n}") for n in (2, 4, 8, 16, 32, 64)),
    quick=Statistics(runs=10, duration=600.0),
    full=Statistics(runs=100, duration=1000.0),
    # The paper's scheme and step: with `located` (dt = 0.02 or 0.04 s) the runs at N = 2
    # and 4 that do not synchronize under `verlet` do (r_eq +0.057 at N = 4, 3.4 SE),
    # which would change claim 1's verdict; benchmarks/reproduce_accuracy.py.
    stepping=PAPER_STEPPING,
    legend_title="σ = 0, ω₀ = 192 BPM",
)

#: Changes that make the frictionless, undriven limit of §6.
FREE = (("c_theta", 0.0), ("c_phi", 0.0), ("drive", 0.0))

Z_STUDY = ZStudy(
    name="z",
    figure="z figure (§6)",
    title="Two identical metronomes: z against θ₂(0), θ₁(0) = 0.1 rad, θ̇(0) = 0",
    regimes=(
        Regime("no friction, no drive (c_θ = c_φ = M = 0)", changes=FREE),
        Regime("published frictions, M = 6×10⁻⁵ N m s", preset="default"),
        Regime("published, M = 6×10⁻⁴ N m s", preset="boda2013"),
        Regime(
            "published frictions, M = 1×10⁻⁴ N m s (large drive, no overturning; ours)",
            changes=(("drive", 1e-4),),
            from_paper=False,
        ),
    ),
    quick=ZGrid(theta2=tuple(np.round(np.linspace(-0.1, 0.1, 21), 6)), duration=1500.0),
    full=ZGrid(theta2=tuple(np.round(np.linspace(-0.1, 0.1, 81), 6)), duration=4000.0),
    # The paper's scheme and step: two metronomes cost seconds, and its basins (which
    # θ₂(0) lock in phase) are what a coarser step could move; not re-measured.
    stepping=PAPER_STEPPING,
)

ESTIMATION = EstimationStudy(
    name="estimation",
    figure="§5 (parameter estimation)",
    title="c_θ, M and c_φ from simulated measurements of known truth",
    # Every model run is a fraction of a second: the modes differ only in the scan's density.
    quick=EstimationGrid(c_phi_scan=tuple(np.geomspace(1e-6, 10.0, 15))),
    full=EstimationGrid(c_phi_scan=tuple(np.geomspace(1e-6, 10.0, 43))),
)


def reduced(study: Study, **statistics) -> Study:
    """Copy of ``study`` with its ``quick`` statistics or grid replaced (for tests).

    Keyword arguments are the fields of the mode's `Statistics`, `SweepGrid`, `ZGrid`
    or `EstimationGrid`.
    """
    return replace(study, quick=replace(study.quick, **statistics))


__all__ = [
    "ESTIMATION",
    "FIG8_BOTTOM",
    "FIG8_TOP",
    "FIG10",
    "FIG11",
    "TABLE1_SIGMA",
    "TABLE2_SIGMA",
    "Z_STUDY",
    "Case",
    "EstimationGrid",
    "EstimationStudy",
    "Regime",
    "Statistics",
    "Study",
    "SweepGrid",
    "SweepStudy",
    "TimeSeriesStudy",
    "ZGrid",
    "ZStudy",
    "paper_sigma_to_bpm",
    "reduced",
]

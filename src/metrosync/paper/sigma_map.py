"""The σ map: where the onset ω_c sits as the spread σ of natural frequencies varies.

Contract: a `SigmaMapStudy` runs the Fig. 10 sweep (equilibrium r against ω₀ for
several N) for every spread σ (BPM) and every tuning, on a BPM window around each
onset; its `points` are `metrosync.simulate` calls, its `assemble` joins the
stored points into one dataset

    r_eq, status        (tuning, sigma, n, bpm, run)  NaN / -1 outside the window
    in_window           (tuning, sigma, bpm)

and `analyse` adds, for each tuning and σ, the critical frequency of every N and its
N → ∞ extrapolation by both estimators of `metrosync.sweeps.critical` (the σ_r peak
and the steepest rise), the spread σ* at which ω_c(∞) reaches the paper's 185 BPM,
and the reduced theory's prediction (`metrosync.theory.reduced_theory`) beside it:

    omega_c_{peak,rise}(_err)          (tuning, sigma, n)
    omega_inf_{peak,rise}(_err)        (tuning, sigma)
    fit_note_{peak,rise}               (tuning, sigma)     why `critical` distrusts a fit
    theory_omega_c(_low, _high)        (tuning, sigma)     linear threshold, N → ∞
    sigma_at_target(_err)              (tuning, estimator) from ω_c(∞) by the peak and
                                                           the rise (trusted fits only),
                                                           the rise at the largest N,
                                                           and the theory

Windows are declared per tuning and σ (``centres``), focused where the onset lies:
the N → ∞ onset moves by about 45 BPM per BPM of σ, and a window of ±12.5 BPM holds
the σ_r peak and the steepest rise of every N swept (N ≥ 64 in ``--full``). Every
point of one (N, ω₀) draws the same standard-normal frequencies and starts, whatever
σ and the tuning, so differences along σ are not blurred by new draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..status import STATUS_ABSENT
from ..sweeps.critical import METHODS, critical_frequency
from ..sweeps.points import PointSpec, make_point
from .runner import PAPER_STEPPING, Compute, Stepping, point_seed, run_points
from .studies import Statistics, _check_mode

#: The paper's critical frequency, BPM.
TARGET_BPM = 185.0
#: Bootstrap replicas of each ω_c estimate.
N_BOOT = 400
#: The two readings of Tables 1–2 (docs/model.md §6.4): σ = 8e-7 per 64 µs logger tick
#: read as beats per tick, or as periods per tick.
READINGS_OF_TABLES = {"beats per tick": 0.75, "periods per tick": 1.5}


@dataclass(frozen=True)
class SigmaMapGrid:
    """Sizes, window and statistics of the σ map in one mode.

    ns : metronome numbers.   half_width, step : each window is centre ± half_width
    BPM on a grid of ``step`` BPM.   stats : runs and duration of every point.
    theory_simulate : also run the fitted phase model (20 000 oscillators) for the
    theory's r = 1/2 curve (seconds a σ; skipped in quick mode).
    """

    ns: tuple[int, ...]
    half_width: float
    step: float
    stats: Statistics
    theory_simulate: bool = False


@dataclass(frozen=True)
class SigmaMapStudy:
    """Fig. 10's onset for each spread σ (BPM) and tuning (see the module docstring)."""

    name: str
    figure: str
    title: str
    sigmas: tuple[float, ...]
    tunings: tuple[str, ...]
    #: Per tuning, the centre (BPM) of the window of each σ, in the order of ``sigmas``.
    centres: tuple[tuple[str, tuple[float, ...]], ...]
    quick: SigmaMapGrid
    full: SigmaMapGrid
    #: Integrator and step of every point, chosen from measured accuracy
    #: (`metrosync.paper.studies.STEPPING`).
    stepping: Stepping
    preset: str = "default"
    target: float = TARGET_BPM
    #: Nominal BPMs where the theory measures K and α (N = 32 growth runs, cached).
    theory_bpms: tuple[float, ...] = tuple(float(b) for b in range(140, 221, 10))

    def __post_init__(self) -> None:
        known = dict(self.centres)
        missing = [t for t in self.tunings if t not in known]
        if missing:
            raise ParameterError(f"`centres` has no windows for tuning(s) {missing}.")
        bad = [t for t in self.tunings if len(known[t]) != len(self.sigmas)]
        if bad:
            raise ParameterError(
                f"`centres` of tuning {bad[0]!r} must give one centre per σ ({len(self.sigmas)})."
            )

    def grid(self, mode: str) -> SigmaMapGrid:
        return getattr(self, _check_mode(mode))

    def window(self, tuning: str, sigma: float, mode: str) -> tuple[float, ...]:
        """The nominal BPMs swept for ``tuning`` and ``sigma`` in ``mode``."""
        g = self.grid(mode)
        centre = dict(self.centres)[tuning][self.sigmas.index(sigma)]
        k = int(round(g.half_width / g.step))
        return tuple(float(f"{centre + i * g.step:.6g}") for i in range(-k, k + 1))

    def bpms(self, mode: str) -> tuple[float, ...]:
        """Every BPM of any window (the dataset's ``bpm`` coordinate)."""
        every = {b for t in self.tunings for s in self.sigmas for b in self.window(t, s, mode)}
        return tuple(sorted(every))

    def points(self, mode: str) -> list[PointSpec]:
        """One `simulate` call per tuning, σ, N and ω₀ of the windows."""
        g = self.grid(mode)
        out = []
        for tuning in self.tunings:
            for sigma in self.sigmas:
                for n in g.ns:
                    for bpm in self.window(tuning, sigma, mode):
                        kwargs = {
                            "n": int(n),
                            "bpm": bpm,
                            "sigma_bpm": float(sigma),
                            "runs": g.stats.runs,
                            "duration": g.stats.duration,
                            **self.stepping.kwargs(),
                            "preset": self.preset,
                            # The same draws for every σ and tuning (see the module docstring).
                            "seed": point_seed(self.name, f"n{n:04d}_bpm{bpm:07.2f}"),
                        }
                        if changes := model_changes(tuning):
                            kwargs["changes"] = changes
                        where = {"tuning": tuning, "sigma": float(sigma), "n": int(n), "bpm": bpm}
                        out.append(make_point(kwargs, keep="r_eq", index=(len(out),), coords=where))
        return out

    def point_label(self, spec: PointSpec) -> str:
        c = spec.coords
        return f"{c['tuning']}, σ = {c['sigma']:g}, N = {c['n']}, ω₀ = {c['bpm']:g} BPM"

    def run(self, mode: str, out: Path, compute: Compute):
        """Refuse unreachable windows first; then the points, assembled and analysed (the
        theory's measurements cached under ``out/points/theory``)."""
        check(self, mode)
        dataset, specs, computed = run_points(self, mode, out, compute)
        return analyse(self, mode, dataset, Path(out) / "points" / "theory"), specs, computed

    def assemble(self, mode: str, specs: list[PointSpec], parts: list[xr.Dataset]) -> xr.Dataset:
        """One dataset of every point's per-run r_eq (NaN outside its window)."""
        g = self.grid(mode)
        bpms = self.bpms(mode)
        shape = (len(self.tunings), len(self.sigmas), len(g.ns), len(bpms), g.stats.runs)
        r_eq = np.full(shape, np.nan)
        status = np.full(shape, STATUS_ABSENT, dtype=np.int8)
        for spec, part in zip(specs, parts, strict=True):
            c = spec.coords
            i = (
                self.tunings.index(c["tuning"]),
                self.sigmas.index(c["sigma"]),
                g.ns.index(c["n"]),
                bpms.index(c["bpm"]),
            )
            r_eq[i] = part.r_eq.values
            status[i] = part.status.values
        dims = ("tuning", "sigma", "n", "bpm", "run")
        ds = xr.Dataset(
            {
                "r_eq": (dims, r_eq, {"long_name": "equilibrium r per run (crossing phases)"}),
                "status": (dims, status, {"long_name": "run status bits (-1: not swept)"}),
            },
            coords={
                "tuning": list(self.tunings),
                "sigma": ("sigma", list(self.sigmas), {"units": "BPM"}),
                "n": list(g.ns),
                "bpm": ("bpm", list(bpms), {"units": "BPM", "long_name": "nominal ω₀"}),
                "run": np.arange(g.stats.runs),
            },
        )
        ds["in_window"] = ds.status.isel(n=0, run=0) != STATUS_ABSENT
        ds.attrs.update(
            runs=g.stats.runs,
            duration=g.stats.duration,
            dt=self.stepping.dt,
            integrator=self.stepping.integrator,
            preset=self.preset,
            target_bpm=self.target,
            warnings=" | ".join(sorted({p.attrs.get("warnings", "none") for p in parts})),
        )
        return ds


def check(study: SigmaMapStudy, mode: str) -> None:
    """Refuse, before any work, a window or theory BPM a tuning cannot reach."""
    from ..model import get_preset

    design = get_preset(study.preset, warn=False).metronome
    for tuning in study.tunings:
        tuned = design.__class__(**{**vars(design), "tuning": tuning})
        every = {b for s in study.sigmas for b in study.window(tuning, s, mode)}
        tuned.l2_for_bpm(np.array(sorted(every | set(study.theory_bpms))))


def model_changes(tuning: str) -> dict:
    """The model changes of a tuning (none for the default, small-amplitude)."""
    return {} if tuning == "small-amplitude" else {"tuning": tuning}


def analyse(study: SigmaMapStudy, mode: str, ds: xr.Dataset, theory_cache: Path) -> xr.Dataset:
    """Add ω_c(N), ω_c(∞), the theory's ω_c and σ* to an assembled σ map."""
    ds = _critical(ds)
    ds = _theory(study, mode, ds, theory_cache)
    methods = [*METHODS, "rise, largest N", "theory"]
    at = np.full((ds.sizes["tuning"], len(methods)), np.nan)
    err = np.full_like(at, np.nan)
    sigmas = ds.sigma.values
    for i in range(ds.sizes["tuning"]):
        for j, m in enumerate(methods):
            if m == "theory":
                row = ds.theory_omega_c.isel(tuning=i).values
                half = 0.5 * (ds.theory_omega_c_high - ds.theory_omega_c_low).isel(tuning=i).values
            elif m == "rise, largest N":
                row = ds.omega_c_rise.isel(tuning=i, n=-1).values
                half = ds.omega_c_rise_err.isel(tuning=i, n=-1).values
            else:
                # An extrapolation `critical` does not trust says nothing about σ*.
                trusted = ds[f"fit_note_{m}"].isel(tuning=i).values == ""
                row = np.where(trusted, ds[f"omega_inf_{m}"].isel(tuning=i).values, np.nan)
                half = ds[f"omega_inf_{m}_err"].isel(tuning=i).values
            at[i, j], err[i, j] = sigma_at(sigmas, row, half, study.target, seed=i * 7 + j)
    ds = ds.assign_coords(estimator=methods)
    ds["sigma_at_target"] = (
        ("tuning", "estimator"),
        at,
        {"units": "BPM", "long_name": f"σ at which ω_c(∞) = {study.target:g} BPM"},
    )
    ds["sigma_at_target_err"] = (("tuning", "estimator"), err, {"units": "BPM"})
    return ds


def _critical(ds: xr.Dataset) -> xr.Dataset:
    shape = (ds.sizes["tuning"], ds.sizes["sigma"])
    per_n = {f"omega_c_{m}{e}": np.full((*shape, ds.sizes["n"]), np.nan)
             for m in METHODS for e in ("", "_err")}  # fmt: skip
    inf = {f"omega_inf_{m}{e}": np.full(shape, np.nan) for m in METHODS for e in ("", "_err")}
    notes = {m: np.full(shape, "", dtype=object) for m in METHODS}
    r_mean = np.full((*shape, ds.sizes["n"], ds.sizes["bpm"]), np.nan)
    sigma_r = np.full_like(r_mean, np.nan)
    forms = {}
    for i, tuning in enumerate(ds.tuning.values):
        for j, sigma in enumerate(ds.sigma.values):
            mask = ds.in_window.sel(tuning=tuning, sigma=sigma).values
            part = ds[["r_eq"]].sel(tuning=tuning, sigma=sigma).isel(bpm=np.nonzero(mask)[0])
            crit = critical_frequency(part, n_boot=N_BOOT, seed=17 * i + j)
            for m in METHODS:
                for e in ("", "_err"):
                    per_n[f"omega_c_{m}{e}"][i, j] = crit[f"omega_c_{m}{e}"].values
                    inf[f"omega_inf_{m}{e}"][i, j] = crit.attrs[f"omega_c_inf_{m}{e}"]
                forms[m] = crit.attrs[f"fit_form_{m}"]
                notes[m][i, j] = crit.attrs.get(f"fit_note_{m}", "")
            r_mean[i, j][:, mask] = crit.r_mean.values
            sigma_r[i, j][:, mask] = crit.sigma_r.values
    bpm = {"units": "BPM"}
    for name, values in per_n.items():
        ds[name] = (("tuning", "sigma", "n"), values, bpm)
    for name, values in inf.items():
        ds[name] = (("tuning", "sigma"), values, {**bpm, "long_name": "ω_c extrapolated to N → ∞"})
    untrusted = {"long_name": "why the N → ∞ fit is not trusted ('' = trusted)"}
    for m, values in notes.items():
        ds[f"fit_note_{m}"] = (("tuning", "sigma"), values.astype(str), untrusted)
    ds["r_mean"] = (("tuning", "sigma", "n", "bpm"), r_mean, {"long_name": "mean r_eq"})
    ds["sigma_r"] = (("tuning", "sigma", "n", "bpm"), sigma_r, {"long_name": "σ_r"})
    ds.attrs.update({f"fit_form_{m}": f for m, f in forms.items()}, n_boot=N_BOOT)
    return ds


def _theory(study: SigmaMapStudy, mode: str, ds: xr.Dataset, cache: Path) -> xr.Dataset:
    """The reduced theory's ω_c(σ) for each tuning (K, α measured once, cached)."""
    from ..theory import reduced_theory

    names = ("theory_omega_c", "theory_omega_c_low", "theory_omega_c_high", "theory_omega_half")
    values = {name: np.full((ds.sizes["tuning"], ds.sizes["sigma"]), np.nan) for name in names}
    simulate_n = 20_000 if study.grid(mode).theory_simulate else None
    for i, tuning in enumerate(study.tunings):
        th = reduced_theory(study.preset, bpms=study.theory_bpms, sigmas=study.sigmas,
                            tuning=tuning, cache=cache, simulate_n=simulate_n)  # fmt: skip
        values["theory_omega_c"][i] = th.omega_c.values
        # More coupling moves the crossing down: "low" comes from K + its error.
        values["theory_omega_c_low"][i] = th.omega_c_low.values
        values["theory_omega_c_high"][i] = th.omega_c_high.values
        if "omega_half" in th:
            values["theory_omega_half"][i] = th.omega_half.values
    text = {
        "theory_omega_c": "predicted ω_c (N → ∞): K(ω₀) = K_c(α, σ_ω)",
        "theory_omega_c_low": "prediction with K + its error",
        "theory_omega_c_high": "prediction with K − its error",
        "theory_omega_half": "reduced phase model, N → ∞: r_eq = 1/2 (NaN: not run)",
    }
    for name, v in values.items():
        ds[name] = (("tuning", "sigma"), v, {"units": "BPM", "long_name": text[name]})
    ds.attrs["theory_bpms"] = list(study.theory_bpms)
    return ds


def sigma_at(sigmas, omega, err, target: float, *, draws: int = 4000, seed: int = 0):
    """σ where ω_c(σ) reaches ``target``, by linear interpolation between the bracketing
    σ, and its error from ``draws`` Monte Carlo draws of ω_c within ``err``.

    Returns (σ*, error); (NaN, NaN) when ``target`` is not bracketed. Draws that no
    longer bracket it are left out of the error.
    """
    sigmas, omega, err = (np.asarray(v, dtype=float) for v in (sigmas, omega, err))
    central = _interpolate(sigmas, omega, target)
    if not math.isfinite(central):
        return math.nan, math.nan
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal((draws, omega.size)) * np.nan_to_num(err, nan=0.0)
    samples = np.array([_interpolate(sigmas, omega + row, target) for row in noise])
    samples = samples[np.isfinite(samples)]
    return central, float(np.std(samples, ddof=1)) if samples.size > 1 else math.nan


def _interpolate(x: np.ndarray, y: np.ndarray, level: float) -> float:
    """First x where y rises through ``level`` (linear); NaN when it does not."""
    for i in range(len(y) - 1):
        if np.isfinite(y[i]) and np.isfinite(y[i + 1]) and y[i] <= level < y[i + 1]:
            return float(x[i] + (level - y[i]) * (x[i + 1] - x[i]) / (y[i + 1] - y[i]))
    return math.nan


SIGMA_MAP = SigmaMapStudy(
    name="sigma_map",
    figure="σ map",
    title="The onset ω_c against the spread σ, for both tunings",
    sigmas=(0.5, 0.75, 1.0, 1.25, 1.5),
    tunings=("small-amplitude", "steady-swing"),
    centres=(
        ("small-amplitude", (160.0, 172.5, 185.0, 192.5, 200.0)),
        ("steady-swing", (155.0, 167.5, 180.0, 187.5, 195.0)),
    ),
    # A window of at least 7 points: the steepest rise is a 5-point local fit.
    quick=SigmaMapGrid(ns=(16, 32, 64), half_width=15.0, step=5.0, stats=Statistics(8, 300.0)),
    # 750 s: at N = 256 near the onset the mean r_eq over the last quarter is within 0.03
    # of its value at 1000 or 1500 s (measured, 20 runs); 10 runs place the steepest
    # rise within about 1-2 BPM at N = 256.
    full=SigmaMapGrid(
        ns=(64, 128, 256),
        half_width=12.5,
        step=2.5,
        stats=Statistics(10, 750.0),
        theory_simulate=True,
    ),  # fmt: skip
    # The paper's scheme and step: `located` reads r_eq 0.065 higher on average at
    # dt = 0.02 s (more than the 10 runs' SE of 0.04) and loses the onset at 0.04 s
    # (−0.26 at N = 256, 172.5 BPM, σ = 0.75); benchmarks/reproduce_accuracy.py.
    stepping=PAPER_STEPPING,
)

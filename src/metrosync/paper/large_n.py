"""The large-N study in the report: where the onset sits for N = 64 … 4096, and claim 4.

Contract: `read_large_n(path)` reads one merged sweep of the study
(`studies/large_n/*.toml`, run by `metrosync sweep`: r_eq over ``n``, ``bpm`` and
``run`` at one σ) and returns a `LargeN`:

- ω_c(N) from the steepest rise of r̄(ω₀) and its N → ∞ fit (`sweeps.critical`), with
  the fit's spread when the smallest or the largest N is left out;
- ω_c(∞) from the finite-size-scaling collapse, with Kuramoto's exponents and with
  fitted ones (`sweeps.scaling`), each with the spread over fit windows and N sets;
- how sharp the transition is at the largest N: the steepest slope of r̄ and the
  span of ω₀ over which r̄ climbs from 10 % to 90 % of its rise;
- what the statistics rest on: runs a point and the largest standard error of a
  point's mean r_eq; the work in oscillator-steps.

`onset(study)` picks the ω_c(∞) to believe, and says why: the collapse whose
exponents collapse the data (χ²/dof ≤ `COLLAPSES`), Kuramoto's first; otherwise the
fit of the steepest rise. `large_n_lines` writes the report's section, which ends with
what the study settles (`settled_lines`: at which σ the onset sits at 185 BPM, how
sharp it is at the largest N, whether it scales as Kuramoto's, and how the onset
compares with the σ map and the reduced theory when the same reproduction made the
σ map), and `claim_4_check` the check that claim 4's verdict adds from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from .._input_files import check_input_file
from ..errors import ParameterError
from ..sweeps.critical import critical_frequency, plot_critical
from ..sweeps.scaling import (
    KURAMOTO_EXPONENTS,
    ScalingEstimate,
    mean_and_error,
    plot_collapse,
    sweep_scaling,
)
from .claims import Verdict, verdict_of

#: χ²/dof up to which the data are said to collapse onto one curve.
COLLAPSES = 3.0
#: The paper's large-N onset and the distance within which claim 4 places it (BPM);
#: the same tolerance as the claim's check on Fig. 10 (`paper.claims`).
OMEGA_C_PAPER = 185.0
OMEGA_C_TOLERANCE = 5.0


@dataclass(frozen=True)
class LargeN:
    """One σ of the large-N study (see the module docstring); frequencies in BPM."""

    path: Path
    sigma_bpm: float
    tuning: str
    sizes: tuple[int, ...]
    critical: xr.Dataset
    kuramoto: ScalingEstimate
    free: ScalingEstimate
    steepest: float
    rise_inf: tuple[float, float, float]
    rise_span: tuple[float, float]
    runs: tuple[int, int]
    largest_error: float
    work: float
    r: xr.DataArray

    @property
    def rise_error(self) -> float:
        """The error of the steepest rise's ω_c(∞): over runs and over size sets."""
        _, stat, syst = self.rise_inf
        return math.hypot(stat, 0.0 if math.isnan(syst) else syst)

    @property
    def rise_width(self) -> float:
        return self.rise_span[1] - self.rise_span[0]


def read_large_n(path: str | Path, *, n_boot: int = 200, seed: int = 0) -> LargeN:
    """The `LargeN` of the merged sweep at ``path`` (one σ, several N, a BPM grid)."""
    path = Path(path)
    try:
        check_input_file(path, "`large_n` sweep")
    except ParameterError as error:
        raise ParameterError(
            f"{error} Give the merged sweep of the large-N study "
            f"(`metrosync sweep studies/large_n/sigma_0.75.toml --out FILE.nc`)."
        ) from None
    try:
        with xr.open_dataset(path, engine="h5netcdf") as opened:
            ds = opened.load()
    except (OSError, ValueError) as error:
        raise ParameterError(f"`large_n`: {str(path)!r} is not a NetCDF sweep: {error}") from None
    if "n" not in ds.dims or ds.sizes["n"] < 2:
        raise ParameterError(
            f"{path} is not a large-N study: it needs r_eq over several N (`n`), a `bpm` "
            f"grid and runs; run `metrosync sweep studies/large_n/sigma_0.75.toml --out FILE`."
        )
    critical = critical_frequency(ds, n_boot=n_boot, seed=seed)
    kuramoto, r = sweep_scaling(ds, exponents="kuramoto", n_boot=min(n_boot, 50), seed=seed)
    free, _ = sweep_scaling(ds, exponents="free", n_boot=min(n_boot, 50), seed=seed)
    bpm = critical.bpm.values
    top = critical.r_mean.values[-1]
    # A sweep with a fixed run count (no `target_error`) holds every run at every point.
    runs = ds.n_runs if "n_runs" in ds else xr.full_like(ds.r_eq_mean, ds.sizes["run"], int)
    errors = ds.r_eq_error.values if "r_eq_error" in ds else mean_and_error(r.values)[1]
    steps = round(float(ds.attrs["fixed_duration"]) / float(ds.attrs["fixed_dt"]))
    return LargeN(
        path=path,
        sigma_bpm=float(ds.attrs.get("fixed_sigma_bpm", math.nan)),
        tuning=str(ds.attrs.get("model_tuning", "")),
        sizes=tuple(int(n) for n in critical.n.values),
        critical=critical,
        kuramoto=kuramoto,
        free=free,
        steepest=float(np.nanmax(np.diff(top) / np.diff(bpm))),
        rise_inf=(
            float(critical.attrs["omega_c_inf_rise"]),
            float(critical.attrs["omega_c_inf_rise_err"]),
            float(critical.attrs["omega_c_inf_rise_syst"]),
        ),
        rise_span=rise_span(bpm, top),
        runs=(int(runs.min()), int(runs.max())),
        largest_error=float(np.nanmax(errors)),
        work=float((runs * ds.n).sum()) * steps,
        r=r,
    )


def rise_span(bpm: np.ndarray, r_mean: np.ndarray, low=0.1, high=0.9) -> tuple[float, float]:
    """ω₀ where r̄ first reaches ``low`` and ``high`` of the way from its smallest to its
    largest value (linear between grid points)."""
    floor, ceiling = np.nanmin(r_mean), np.nanmax(r_mean)
    out = []
    for share in (low, high):
        level = floor + share * (ceiling - floor)
        k = int(np.argmax(r_mean >= level))
        if k == 0:
            out.append(float(bpm[0]))
            continue
        x0, x1, y0, y1 = bpm[k - 1], bpm[k], r_mean[k - 1], r_mean[k]
        out.append(float(x0 + (level - y0) * (x1 - x0) / (y1 - y0)))
    return out[0], out[1]


def onset(study: LargeN) -> tuple[float, float, str]:
    """(ω_c(∞), its error, which estimate and why) for ``study``."""
    k, f = study.kuramoto, study.free
    if k.best.chi2_dof <= COLLAPSES:
        return (
            k.x_c,
            k.x_c_err,
            f"the collapse with Kuramoto's exponents (χ²/dof = {k.best.chi2_dof:.2f})",
        )
    if f.best.chi2_dof <= COLLAPSES:
        return (
            f.x_c,
            f.x_c_err,
            (
                f"the collapse with fitted exponents (χ²/dof = {f.best.chi2_dof:.2f}; with "
                f"Kuramoto's it is {k.best.chi2_dof:.1f}: the data do not collapse with them)"
            ),
        )
    value, stat, syst = study.rise_inf
    return (
        value,
        study.rise_error,
        (
            f"the fit of the steepest rise in N (± {stat:.2f} over runs, ± {syst:.2f} when "
            "the smallest or the largest N is left out; no collapse fits: χ²/dof "
            f"{k.best.chi2_dof:.1f} with Kuramoto's exponents, {f.best.chi2_dof:.1f} fitted)"
        ),
    )


def claim_4_check(studies: list[LargeN]) -> tuple[str, bool]:
    """Claim 4's check from the study: does the N → ∞ onset sit within the tolerance of
    185 BPM at the paper's σ (the first study)? Returns (the check's words, its answer)."""
    first = studies[0]
    value, error, _ = onset(first)
    words = (
        f"the N → ∞ onset (N ≤ {first.sizes[-1]}, σ = {first.sigma_bpm:g} BPM) lies within "
        f"{OMEGA_C_TOLERANCE:g} BPM of ω_c = {OMEGA_C_PAPER:g} BPM ({value:.1f} ± {error:.1f})"
    )
    return words, bool(abs(value - OMEGA_C_PAPER) <= OMEGA_C_TOLERANCE + error)


def large_n_lines(
    studies: list[LargeN], figures: Path, base: Path, sigma_map: xr.Dataset | None = None
) -> list[str]:
    """The report's section on the large-N study, its figures written to ``figures``;
    ``sigma_map``, the same reproduction's σ map when it made one, for the comparison."""
    lines = ["## The transition at large N: finite-size scaling", ""]
    lines += [
        "| σ (BPM) | N | runs a point | largest s.e. of r̄ | ω_c(∞), Kuramoto exponents | "
        "ω_c(∞), fitted exponents | β/ν̄, 1/ν̄ fitted | ω_c(∞), steepest rise | "
        "steepest slope at largest N | 10–90 % rise |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for s in studies:
        k, f = s.kuramoto, s.free
        lines.append(
            f"| {s.sigma_bpm:g} | {', '.join(map(str, s.sizes))} | {s.runs[0]}–{s.runs[1]} | "
            f"{s.largest_error:.4f} | {k.x_c:.1f} ± {k.x_c_err:.1f} (χ²/dof "
            f"{k.best.chi2_dof:.2f}) | {f.x_c:.1f} ± {f.x_c_err:.1f} (χ²/dof "
            f"{f.best.chi2_dof:.2f}) | {f.a:.2f} ± {f.a_err:.2f}, {f.b:.2f} ± {f.b_err:.2f} | "
            f"{s.rise_inf[0]:.1f} ± {s.rise_error:.1f} | "
            f"{s.steepest:.3f} /BPM | {s.rise_span[0]:.1f}–{s.rise_span[1]:.1f} BPM |"
        )
    lines.append("")
    for s in studies:
        value, error, why = onset(s)
        lines.append(
            f"- σ = {s.sigma_bpm:g} BPM: the onset at N → ∞ is {value:.1f} ± {error:.1f} BPM, "
            f"from {why}. At N = {s.sizes[-1]} r̄ climbs from 10 % to 90 % of its rise over "
            f"{s.rise_width:.1f} BPM. {s.work:.2g} oscillator-steps."
        )
        stem = f"large_n_sigma_{s.sigma_bpm:g}"
        figures.mkdir(parents=True, exist_ok=True)
        plot_critical(s.critical, figures / f"{stem}_critical.png")
        best = s.kuramoto if s.kuramoto.best.chi2_dof <= COLLAPSES else s.free
        mean, err = mean_and_error(s.r.values)
        collapse_path = figures / f"{stem}_collapse.png"
        plot_collapse(
            best.best,
            s.r.bpm.values,
            s.r.n.values,
            mean,
            err,
            path=collapse_path,
            x_label="ω₀",
            c_label="ω_c",
            units="BPM",
        )
        critical_path = figures / f"{stem}_critical.png"
        lines.append(f"  ![r_eq(ω₀) for each N]({critical_path.relative_to(base)})")
        lines.append(f"  ![the collapse]({collapse_path.relative_to(base)})")
    lines += ["", *settled_lines(studies, sigma_map)]
    words, holds = claim_4_check(studies)
    lines += ["", f"Claim 4 from this study: {words}: {'yes' if holds else 'no'}.", ""]
    return lines


def sigma_at_paper_onset(studies: list[LargeN]) -> tuple[float, float, bool] | None:
    """σ at which the N → ∞ onset sits at 185 BPM, on the line through the onsets of the
    two studies of the first study's tuning furthest apart in σ: (σ, its error from the
    two onsets' errors, whether 185 BPM lies between them). None with fewer than two σ."""
    same = [s for s in studies if s.tuning == studies[0].tuning]
    low = min(same, key=lambda s: s.sigma_bpm)
    high = max(same, key=lambda s: s.sigma_bpm)
    (w1, e1, _), (w2, e2, _) = onset(low), onset(high)
    if high.sigma_bpm == low.sigma_bpm or w1 == w2:
        return None
    span, rise = high.sigma_bpm - low.sigma_bpm, w2 - w1
    sigma = low.sigma_bpm + (OMEGA_C_PAPER - w1) * span / rise
    error = abs(span) / rise**2 * math.hypot((OMEGA_C_PAPER - w2) * e1, (OMEGA_C_PAPER - w1) * e2)
    return sigma, error, min(w1, w2) <= OMEGA_C_PAPER <= max(w1, w2)


def scaling_words(study: LargeN) -> str:
    """Whether the study's r_eq scale as Kuramoto oscillators with random frequencies do."""
    k, f = study.kuramoto, study.free
    a0, b0 = KURAMOTO_EXPONENTS
    fitted = (
        f"fitted, β/ν̄ = {f.a:.2f} ± {f.a_err:.2f} and 1/ν̄ = {f.b:.2f} ± {f.b_err:.2f} "
        f"(χ²/dof = {f.best.chi2_dof:.2f})"
    )
    if k.best.chi2_dof <= COLLAPSES:
        return (
            f"with Kuramoto's exponents (β/ν̄ = {a0:g}, 1/ν̄ = {b0:g}) the r_eq collapse "
            f"(χ²/dof = {k.best.chi2_dof:.2f}); {fitted}: the scaling is Kuramoto's"
        )
    far = max(abs(f.a - a0) / f.a_err, abs(f.b - b0) / f.b_err)
    ending = (
        "the transition does not scale as Kuramoto's at these sizes"
        if far > 2 or f.best.chi2_dof > COLLAPSES
        else "the fitted exponents do not rule Kuramoto's out, but his do not collapse the data"
    )
    return (
        f"with Kuramoto's exponents (β/ν̄ = {a0:g}, 1/ν̄ = {b0:g}) the r_eq do not collapse "
        f"(χ²/dof = {k.best.chi2_dof:.1f}); {fitted}"
        f"{'' if f.best.chi2_dof <= COLLAPSES else ', no collapse either'}: {ending}"
    )


def _map_at(sigma_map: xr.Dataset, study: LargeN) -> xr.Dataset | None:
    """The σ map's row for the study's tuning, linear in σ at the study's σ; None when
    the map has not that tuning or does not span that σ."""
    if study.tuning not in sigma_map.tuning.values:
        return None
    row = sigma_map.sel(tuning=study.tuning)
    if not row.sigma.min() <= study.sigma_bpm <= row.sigma.max():
        return None
    names = ["omega_inf_rise", "omega_inf_rise_err", "theory_omega_c", "theory_omega_c_low",
             "theory_omega_c_high"]  # fmt: skip
    return row[names].interp(sigma=study.sigma_bpm)


def settled_lines(studies: list[LargeN], sigma_map: xr.Dataset | None = None) -> list[str]:
    """What the study settles: one paragraph (see the module docstring)."""
    first = studies[0]
    out = ["**What the study settles.**"]
    found = sigma_at_paper_onset(studies)
    if found is not None:
        sigma, error, between = found
        out.append(
            f"The N → ∞ onset sits at {OMEGA_C_PAPER:g} BPM for σ = {sigma:.3f} ± {error:.3f} "
            f"BPM ({first.tuning} tuning; {'between' if between else 'extrapolated from'} "
            f"the study's σ on a line)."
        )
    for s in studies:
        value, error, _ = onset(s)
        at = f"{value - OMEGA_C_PAPER:+.1f} BPM from {OMEGA_C_PAPER:g}"
        out.append(
            f"At σ = {s.sigma_bpm:g} BPM ({s.tuning} tuning) the N → ∞ onset is {value:.1f} ± "
            f"{error:.1f} BPM ({at}); at N = {s.sizes[-1]} r̄ climbs from 10 % to 90 % of its "
            f"rise over {s.rise_width:.1f} BPM ({s.rise_span[0]:.1f}–{s.rise_span[1]:.1f} BPM, "
            f"at most {s.steepest:.3f} per BPM); {scaling_words(s)}."
        )
        if sigma_map is not None and (row := _map_at(sigma_map, s)) is not None:
            largest = int(sigma_map.n.max())
            out.append(
                f"The σ map of this reproduction (N ≤ {largest}, {sigma_map.attrs['runs']} "
                f"runs × {sigma_map.attrs['duration']:g} s a point) extrapolates to "
                f"{float(row.omega_inf_rise):.1f} ± {float(row.omega_inf_rise_err):.1f} BPM "
                f"there, and the reduced theory's threshold is "
                f"{float(row.theory_omega_c):.1f} BPM [{float(row.theory_omega_c_low):.1f}, "
                f"{float(row.theory_omega_c_high):.1f}]; the study measures the full model "
                f"itself up to N = {s.sizes[-1]}, so its onset needs the shortest "
                f"extrapolation, and it is the one to believe."
            )
    return [" ".join(out)]


def amend_claim_4(verdict: Verdict, studies: list[LargeN]) -> Verdict:
    """Claim 4's verdict with its check of where the transition sits taken from the
    large-N study (N up to 4096, extrapolated) instead of Fig. 10's largest N."""
    if "checks" not in verdict.values:  # Fig. 10 did not run: claim 4 is not assessed
        return verdict
    checks = {k: v for k, v in verdict.values["checks"].items() if "transition sits" not in k}
    words, holds = claim_4_check(studies)
    checks[words] = holds
    numbers = (
        f"{verdict.numbers} From the large-N study (its section below), the check of where "
        f"the transition sits is replaced: {words}: {'yes' if holds else 'no'}."
    )
    values = {**verdict.values, "checks": checks, "large_n": True}
    return Verdict(verdict.claim, verdict_of(checks), numbers, verdict.study, values)

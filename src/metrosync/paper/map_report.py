"""REPORT.md sections of the σ map and the claims map, and the closing conclusion.

Contract: `sigma_map_section(ds)` and `claims_map_section(ds)` render the datasets of
`metrosync.paper.sigma_map` and `metrosync.paper.claims_map` as Markdown lines;
`conclusion(datasets)` writes the plain-language conclusion that ends REPORT.md from
whichever of them were run (by study name). Every number is read from the data.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .claims import CLAIM_TEXT
from .map_figures import VERDICT_MARKS
from .sigma_map import READINGS_OF_TABLES

#: A σ* within this many standard errors of a reading of Tables 1–2 is consistent with it.
CONSISTENT_SE = 2.0


def _pm(value: float, err: float, digits: int = 1) -> str:
    if not math.isfinite(value):
        return "—"
    return f"{value:.{digits}f} ± {err:.{digits}f}" if math.isfinite(err) else f"{value:.{digits}f}"


def which_reading(sigma: float, err: float) -> str:
    """Which reading of Tables 1–2 a spread σ* ± err (BPM) matches, in words."""
    if not math.isfinite(sigma):
        return "outside the σ swept"
    err = err if math.isfinite(err) and err > 0 else 0.05
    near = [name for name, v in READINGS_OF_TABLES.items() if abs(sigma - v) <= CONSISTENT_SE * err]
    if near:
        return " and ".join(near)
    beats, periods = READINGS_OF_TABLES["beats per tick"], READINGS_OF_TABLES["periods per tick"]
    return (
        f"neither: {sigma / beats:.2f} × the beats-per-tick spread "
        f"({abs(sigma - beats) / err:.0f} SE from it, "
        f"{abs(periods - sigma) / err:.0f} SE from periods per tick)"
    )


def sigma_map_section(ds: xr.Dataset) -> list[str]:
    target = ds.attrs.get("target_bpm", 185.0)
    ns = ", ".join(str(int(n)) for n in ds.n.values)
    s = [
        "## The σ map: where the onset sits as σ varies",
        "",
        f"Fig. 10's sweep for every spread σ and tuning: N = {ns}, {ds.attrs['runs']} runs × "
        f"{ds.attrs['duration']:g} s a point, on a window of ω₀ around each onset. ω_c(N) is "
        "where σ_r peaks (*peak*) and where r̄ rises fastest (*rise*), with bootstrap errors "
        f"over runs, extrapolated to N → ∞ by `metrosync.sweeps.critical` "
        f"({ds.attrs.get('fit_form_rise', '')}). The theory is the reduced Kuramoto–Sakaguchi "
        "model (`metrosync theory`): K(ω₀) and α(ω₀) measured on the full model, and the onset "
        "where K reaches the exact threshold K_c(α, σ_ω) for N → ∞ (its range: K ± its error).",
        "",
        f"| tuning | σ (BPM) | ω_c(∞), peak | ω_c(∞), rise | rise at N = {int(ds.n[-1])} "
        "| theory: threshold | theory: r = 1/2 | rise − threshold |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for tuning in ds.tuning.values:
        for sigma in ds.sigma.values:
            x = ds.sel(tuning=tuning, sigma=sigma)
            th, lo, hi = (float(x[k]) for k in ("theory_omega_c", "theory_omega_c_low",
                                                 "theory_omega_c_high"))  # fmt: skip
            gap, se = _gap(x)
            peak, rise = (
                _pm(float(x[f"omega_inf_{m}"]), float(x[f"omega_inf_{m}_err"]))
                + (" †" if str(x[f"fit_note_{m}"].item()) else "")
                for m in ("peak", "rise")
            )
            largest = _pm(float(x.omega_c_rise.isel(n=-1)), float(x.omega_c_rise_err.isel(n=-1)))
            s.append(
                f"| {tuning} | {sigma:g} | {peak} | {rise} | {largest} "
                f"| {th:.1f} [{lo:.1f}, {hi:.1f}] | {_num(float(x.theory_omega_half))} "
                f"| {gap:+.1f} ({gap / se:+.1f} SE) |"
            )
    notes = [
        f"{t}, σ = {sg:g}, {m}: {note}"
        for t in ds.tuning.values
        for sg in ds.sigma.values
        for m in ("peak", "rise")
        if (note := str(ds[f"fit_note_{m}"].sel(tuning=t, sigma=sg).item()))
    ]
    if notes:
        s += ["", "† `metrosync.sweeps.critical` does not trust this extrapolation (left out "
              "of σ* below): " + "; ".join(notes) + "."]  # fmt: skip
    if (note := theory_half_note(ds)) is not None:
        s += ["", note]
    s += ["", f"Where ω_c reaches the paper's {target:g} BPM:", ""]
    s += [f"| tuning | σ* from ω_c(∞), peak | from ω_c(∞), rise | from the rise at N = "
          f"{int(ds.n[-1])} | from the theory | reading of Tables 1–2 |",
          "|---|---|---|---|---|---|"]  # fmt: skip
    for tuning in ds.tuning.values:
        x = ds.sel(tuning=tuning)
        cells = [_pm(float(x.sigma_at_target.sel(estimator=m)),
                     float(x.sigma_at_target_err.sel(estimator=m)), 2)
                 for m in ("peak", "rise", "rise, largest N", "theory")]  # fmt: skip
        value, err, source = headline_sigma(x)
        s.append(f"| {tuning} | " + " | ".join(cells)
                 + f" | {which_reading(value, err)} ({source}) |")  # fmt: skip
    s += ["", agreement(ds), ""]
    return s


def theory_half_note(ds: xr.Dataset) -> str | None:
    """Why the "theory: r = 1/2" column is empty, when it is (None when it has values)."""
    if np.isfinite(ds.theory_omega_half.values).any():
        return None
    return (
        'The column "theory: r = 1/2" is "—": its ω is where the reduced phase model '
        "itself, simulated with 20 000 oscillators for each σ, reaches r_eq = 1/2, which "
        "takes seconds a σ and tuning; quick mode leaves that simulation out (the threshold "
        "column needs none), and `metrosync reproduce --full` runs it."
    )


def headline_sigma(x: xr.Dataset) -> tuple[float, float, str]:
    """σ* of one tuning from the steepest rise: extrapolated to N → ∞ where `critical`
    trusts the fit, else at the largest N. Returns (σ*, error, which)."""
    for estimator, text in (("rise", "ω_c(∞)"), ("rise, largest N", f"N = {int(x.n[-1])}")):
        value = float(x.sigma_at_target.sel(estimator=estimator))
        if math.isfinite(value):
            return value, float(x.sigma_at_target_err.sel(estimator=estimator)), text
    return math.nan, math.nan, "no estimate"


def _gap(x: xr.Dataset) -> tuple[float, float]:
    """Simulated ω_c(∞) (rise) minus the theory's threshold, and their combined error."""
    half = 0.5 * float(x.theory_omega_c_high - x.theory_omega_c_low)
    gap = float(x.omega_inf_rise - x.theory_omega_c)
    se = math.hypot(float(x.omega_inf_rise_err), half)
    return gap, se if se > 0 else math.nan


def _num(value: float) -> str:
    return f"{value:.1f}" if math.isfinite(value) else "—"


def agreement(ds: xr.Dataset) -> str:
    """One paragraph: how far the simulated ω_c(∞) lies from the theory's threshold."""
    parts = []
    for tuning in ds.tuning.values:
        gaps = [_gap(ds.sel(tuning=tuning, sigma=s)) for s in ds.sigma.values]
        g = np.array([a for a, _ in gaps])
        z = np.array([a / b for a, b in gaps])
        ok = np.isfinite(z)
        parts.append(
            f"{tuning} tuning: the simulated onset (rise) lies {np.nanmean(g):+.1f} BPM from "
            f"the predicted threshold on average (from {np.nanmin(g):+.1f} to "
            f"{np.nanmax(g):+.1f}), "
            f"within 2 combined standard errors at {int(np.sum(np.abs(z[ok]) <= 2))} of "
            f"{int(ok.sum())} spreads"
        )
    return (
        "Agreement of theory and simulation: "
        + "; ".join(parts)
        + ". The theory has no free parameter: K and α are measured on the full model "
        f"(continuous time, dt = 10⁻⁴ s), the simulations use {_stepping(ds)}, and "
        "the finite-N extrapolation carries its own model error beyond the bootstrap's."
    )


def _stepping(ds: xr.Dataset) -> str:
    """The σ map's integrator and step, in words."""
    a = ds.attrs
    integrator, dt = a.get("integrator", "verlet"), float(a.get("dt", 0.01))
    if integrator == "verlet" and dt == 0.01:
        return "the paper's scheme and step (verlet, dt = 0.01 s)"
    return f"{integrator} at dt = {dt:g} s (its accuracy measured against the paper's dt = 0.01 s)"


def claims_map_section(ds: xr.Dataset) -> list[str]:
    levels = [lv for lv in ds.level.values if (ds.verdict.sel(level=lv) != "").any()]
    order = np.argsort(ds["rank"].values)
    s = [
        "## The claims map: which reading reproduces which claim",
        "",
        "Each row is one reading of the paper's parameters: σ of Tables 1–2 per beat "
        "(0.75 BPM) or per period (1.5 BPM); the small-amplitude or steady-swing tuning; "
        "the published drive and friction (c_θ = 5×10⁻⁵, M = 6×10⁻⁴: overturns), M/10 "
        "(today's default) or c_θ × 10 with the published M; J(N) by the law J₀ + N j or "
        "constant at 0.25515 kg m²; and today's reading once more without the escapement's "
        "reaction on the disk (the −Σ𝕄_i term of eq. (metron2a) off). The z-study "
        "reads its two drives through the reading (small = the reading's M/10, large = its M). "
        "Claims are judged by the same criteria as above; a claim whose runs mostly overturn "
        "is *not reproduced*. Score: 1 per claim reproduced, ½ per claim partly reproduced. "
        "✓ reproduced, ½ partly, ? inconclusive, ✗ not reproduced.",
        "",
    ]
    head = "| rank | reading | " + " | ".join(
        f"{c} ({lv})" for lv in levels for c in ds.claim.values
    ) + " | score |"  # fmt: skip
    s += [head, "|" + "---|" * (3 + len(levels) * ds.sizes["claim"])]
    for i in order:
        row = ds.isel(reading=i)
        marks = [VERDICT_MARKS.get(str(row.verdict.sel(claim=c, level=lv).item()), "?") or " "
                 for lv in levels for c in ds.claim.values]  # fmt: skip
        total = " / ".join(_num(float(row.total.sel(level=lv))).replace(".0", "")
                           for lv in levels)  # fmt: skip
        s.append(f"| {int(row['rank'])} | {row.reading.item()} | " + " | ".join(marks)
                 + f" | {total} |")  # fmt: skip
    if "best" in levels:
        s += ["", "The best readings again, at the paper's statistics:", ""]
        for i in order:
            row = ds.isel(reading=i)
            if not (row.verdict.sel(level="best") != "").any():
                continue
            s += [f"### {row.reading.item()}", "", f"{row.description.item()}.", ""]
            for c in ds.claim.values:
                v = row.sel(claim=c, level="best")
                s.append(f"- **Claim {c}, {v.verdict.item()}.** {v.numbers.item()}")
            s.append("")
    return s + [""]


def _judged(ds: xr.Dataset) -> xr.DataArray:
    """Each reading's verdicts at its most thorough level (best where it ran)."""
    best = ds.verdict.sel(level="best")
    return xr.where(best != "", best, ds.verdict.sel(level="screen"))


def conclusion(datasets: dict[str, xr.Dataset]) -> list[str]:
    """The closing section, in plain words, from the σ map and the claims map."""
    cmap, smap = datasets.get("claims_map"), datasets.get("sigma_map")
    if cmap is None and smap is None:
        return []
    s = ["## Conclusion", ""]
    if cmap is not None:
        judged = _judged(cmap)
        score = xr.where(judged == "reproduced", 1.0, xr.where(judged == "partly reproduced",
                                                               0.5, 0.0)).sum("claim")  # fmt: skip
        top = float(score.max())
        # Ties are common (half-claims): name them all, in the map's rank order.
        tied = sorted(np.flatnonzero(score.values == top), key=lambda i: int(cmap["rank"][i]))
        best = int(tied[0])
        held = [int(c) for c in cmap.claim.values if judged.isel(reading=best).sel(claim=c) ==
                "reproduced"]  # fmt: skip
        part = [int(c) for c in cmap.claim.values if judged.isel(reading=best).sel(claim=c) ==
                "partly reproduced"]  # fmt: skip
        claims = f"claims {_list(held)} reproduced" + (f" and {_list(part)} partly" if part else "")
        if len(tied) == 1:
            s.append(
                f"Of the {cmap.sizes['reading']} readings tried, the one that reproduces most "
                f"of the paper is **{cmap.reading.values[best]}** "
                f"({cmap.description.values[best]}): score {top:g} of 5, {claims}."
            )
        else:
            names = _list(f"**{cmap.reading.values[i]}**" for i in tied)
            s.append(
                f"Of the {cmap.sizes['reading']} readings tried, {len(tied)} tie as the ones "
                f"that reproduce most of the paper, each scoring {top:g} of 5 (at the paper's "
                f"statistics where a reading was run again, else at the screen's): {names}. "
                f"The map ranks first the one whose screen scored highest and whose onset "
                f"sits nearest 185 BPM ({cmap.description.values[best]}): {claims}."
            )
        nobody = [
            int(c) for c in cmap.claim.values if not (judged.sel(claim=c) == "reproduced").any()
        ]
        for c in nobody:
            s += [
                "",
                f"No reading reproduces claim {c} in full ({CLAIM_TEXT[c].rstrip('.')}): "
                + _why_not(cmap, judged, c),
            ]
    if smap is not None:
        s += ["", sigma_sentence(smap)]
    while len(s) > 2 and s[2] == "":  # one blank line under the heading
        del s[2]
    return s + [""]


def _why_not(ds, judged, claim: int) -> str:
    """What every reading misses of ``claim``, and how many reproduce it partly."""
    best = ds.failed.sel(level="best")
    failed = xr.where(ds.verdict.sel(level="best") != "", best, ds.failed.sel(level="screen"))
    sets = [set(filter(None, str(f).split(" | "))) for f in failed.sel(claim=claim).values]
    # Overturning readings miss everything; what the others miss in common is the finding.
    sets = [x for x in sets if not any("overturn" in part for part in x)] or sets
    common = set.intersection(*sets) if sets else set()
    partly = int((judged.sel(claim=claim) == "partly reproduced").sum())
    missing = (
        "what no reading whose pendulums stay below the horizontal shows is: "
        + _list(sorted(common))
        if common
        else "each reading misses a different part of it"
    )
    return f"{missing}; {partly} of {ds.sizes['reading']} readings reproduce it partly."


def sigma_sentence(ds: xr.Dataset) -> str:
    target = ds.attrs.get("target_bpm", 185.0)
    parts = []
    for tuning in ds.tuning.values:
        value, err, source = headline_sigma(ds.sel(tuning=tuning))
        parts.append(f"σ = {_pm(value, err, 2)} BPM with the {tuning} tuning "
                     f"(steepest rise, {source}: {which_reading(value, err)})")  # fmt: skip
    return (
        f"The paper's onset at {target:g} BPM needs " + "; ".join(parts) + ". Where the "
        "transition sits is set by the spread of the metronomes' frequencies, which the paper "
        "prints in a unit that admits two readings, and by what a nominal BPM means."
    )


def tuning_bullet(datasets: dict[str, xr.Dataset]) -> str:
    """The discrepancy bullet on the tuning: what each study used and what the other gives."""
    used = {name: str(ds.attrs["tuning"]) for name, ds in datasets.items() if "tuning" in ds.attrs}
    kinds = sorted(set(used.values())) or ["small-amplitude"]
    s = (
        "- **Tuning.** A metronome's marking is its tick rate; the model's default tuning puts "
        "the *small-amplitude* frequency on the nominal BPM, so a metronome marked 192 BPM "
        "ticks at about 184.7 BPM at its 0.76 rad swing (docs/model.md §6.3). The studies "
        f"above ({', '.join(f'`{n}`' for n in used) or 'all'}) used the {' and '.join(kinds)} "
        "tuning; `--set tuning=steady-swing` makes a metronome tick at its marking."
    )
    smap, cmap = datasets.get("sigma_map"), datasets.get("claims_map")
    if smap is not None and len(smap.tuning) > 1 and 0.75 in smap.sigma.values:
        x = smap.sel(sigma=0.75)
        onsets = []
        for t in smap.tuning.values:
            one = x.sel(tuning=t)
            onsets.append(f"{_pm(float(one.omega_inf_rise), float(one.omega_inf_rise_err))} BPM "
                          f"with the {t} tuning")  # fmt: skip
        s += " At σ = 0.75 BPM the onset ω_c(∞) (steepest rise) is " + "; ".join(onsets)
        s += " (the σ map)."
    if cmap is not None:
        rows = [r for r in cmap.reading.values if str(r).startswith("σ-beat/")
                and str(r).endswith("/M/10/J-law")]  # fmt: skip
        judged = _judged(cmap)
        s += " Claims 1–5 with today's other readings (σ per beat, M/10, J by the law): "
        s += "; ".join(
            f"{r.split('/')[1]}: "
            + " ".join(f"{c}{VERDICT_MARKS.get(str(judged.sel(reading=r, claim=c).item()), '?')}"
                       for c in cmap.claim.values)
            for r in rows
        ) + " (the claims map)."  # fmt: skip
    return s


def _list(items) -> str:
    items = [str(i) for i in items]
    if not items:
        return "none"
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]

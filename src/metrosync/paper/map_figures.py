"""Figures of the σ map and the claims map (PNG + PDF, like `metrosync.paper.figures`).

Contract: `plot_sigma_map(ds, stem)` and `plot_claims_map(ds, stem)` take the study's
dataset (`metrosync.paper.sigma_map`, `metrosync.paper.claims_map`), write
``<stem>.png`` and ``<stem>.pdf`` and return the paths.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from ._canvas import new_figure, palette, save_formats

#: Colour of each verdict in the claims map (colour-blind safe: blue, light blue, grey,
#: orange).
VERDICT_COLORS = {
    "reproduced": "#2166ac",
    "partly reproduced": "#92c5de",
    "inconclusive": "#d9d9d9",
    "not reproduced": "#f4a582",
    "": "#ffffff",
}
VERDICT_MARKS = {"reproduced": "✓", "partly reproduced": "½", "inconclusive": "?",
                 "not reproduced": "✗", "": ""}  # fmt: skip
STYLES = {"small-amplitude": "-", "steady-swing": "--"}


def plot_sigma_map(ds: xr.Dataset, stem: Path) -> list[Path]:
    """(a) ω_c(∞) against σ for each tuning, both estimators with bootstrap errors, and
    the reduced theory's prediction (band: K ± its error); the paper's 185 BPM and the
    two readings of Tables 1–2 are marked. (b) r̄(ω₀) at the largest N for every σ."""
    from .sigma_map import READINGS_OF_TABLES

    fig, (left, right) = new_figure(1, 2, figsize=(12.5, 4.8), constrained_layout=True)
    sigma = ds.sigma.values
    for k, tuning in enumerate(ds.tuning.values):
        one = ds.sel(tuning=tuning)
        color = f"C{k}"
        for m, marker, dx in (("peak", "o", -0.01), ("rise", "s", 0.01)):
            left.errorbar(sigma + dx, one[f"omega_inf_{m}"], yerr=one[f"omega_inf_{m}_err"],
                          fmt=marker, color=color, ms=5, capsize=3, mfc="none" if m == "peak"
                          else color, label=f"simulated ω_c(∞), {m}, {tuning}")  # fmt: skip
        left.fill_between(sigma, one.theory_omega_c_low, one.theory_omega_c_high, color=color,
                          alpha=0.2, lw=0)  # fmt: skip
        left.plot(sigma, one.theory_omega_c, STYLES.get(str(tuning), "-"), color=color, lw=1.2,
                  label=f"theory: linear threshold, {tuning}")  # fmt: skip
        if np.isfinite(one.theory_omega_half).any():
            left.plot(sigma, one.theory_omega_half, ":", color=color, lw=1,
                      label=f"theory: reduced model r = 1/2, {tuning}")  # fmt: skip
    target = ds.attrs.get("target_bpm", 185.0)
    left.axhline(target, color="0.4", lw=0.8, ls="--")
    left.annotate(f"paper's ω_c = {target:g} BPM", (sigma[0], target), fontsize=8,
                  xytext=(2, 3), textcoords="offset points")  # fmt: skip
    for text, value in READINGS_OF_TABLES.items():
        left.axvline(value, color="0.6", lw=0.8, ls=":")
        left.annotate(f"Tables 1–2 as {text}", (value, left.get_ylim()[0]), rotation=90,
                      fontsize=7, xytext=(3, 4), textcoords="offset points",
                      va="bottom")  # fmt: skip
    left.set(xlabel="σ (BPM, spread of nominal frequencies)", ylabel="ω_c (nominal BPM)",
             title="onset of synchronization against σ")  # fmt: skip
    left.legend(fontsize=6.5, loc="upper left")
    n = int(ds.n.values[-1])
    colors = palette("plasma", np.linspace(0.05, 0.85, ds.sizes["sigma"]))
    for tuning in ds.tuning.values:
        for color, s in zip(colors, sigma, strict=True):
            r = ds.r_mean.sel(tuning=tuning, sigma=s, n=n)
            ok = np.isfinite(r.values)
            right.plot(ds.bpm.values[ok], r.values[ok], STYLES.get(str(tuning), "-"), marker="o",
                       ms=3, color=color, lw=1.1,
                       label=f"σ = {s:g}" if tuning == ds.tuning.values[0] else None)  # fmt: skip
    right.axvline(target, color="0.4", lw=0.8, ls="--")
    right.set(xlabel="ω₀ (nominal BPM)", ylabel="r (mean over runs)", ylim=(0, 1.02),
              title=f"N = {n}: solid small-amplitude, dashed steady-swing tuning")  # fmt: skip
    right.legend(fontsize=8, loc="lower right")
    fig.suptitle(
        f"{ds.attrs.get('figure', 'σ map')}: {ds.attrs.get('mode', '')} mode, "
        f"{ds.attrs.get('runs')} runs × {ds.attrs.get('duration', 0):g} s a point, "
        f"N = {', '.join(str(int(v)) for v in ds.n.values)}",
        fontsize=9,
    )
    return save_formats(fig, stem)


def plot_claims_map(ds: xr.Dataset, stem: Path) -> list[Path]:
    """One row per reading (best first), one cell per claim and level, coloured by
    verdict; the total score at the right."""
    from matplotlib.patches import Patch

    order = np.argsort(ds["rank"].values)
    levels = [lv for lv in ds.level.values if (ds.verdict.sel(level=lv) != "").any()]
    rows, cols = len(order), len(levels) * ds.sizes["claim"]
    fig, ax = new_figure(figsize=(3.0 + 0.55 * cols + 4.2, 1.2 + 0.32 * rows),
                      constrained_layout=True)  # fmt: skip
    for y, i in enumerate(order):
        for k, level in enumerate(levels):
            for j, claim in enumerate(ds.claim.values):
                v = str(ds.verdict.isel(reading=i).sel(claim=claim, level=level).item())
                x = k * (ds.sizes["claim"] + 0.5) + j
                ax.add_patch(_cell(x, y, VERDICT_COLORS.get(v, "#ffffff")))
                ax.text(x + 0.5, y + 0.5, VERDICT_MARKS.get(v, "?"), ha="center", va="center",
                        fontsize=9)  # fmt: skip
        totals = [ds.total.isel(reading=i).sel(level=lv).item() for lv in levels]
        text = " / ".join("—" if not np.isfinite(t) else f"{t:g}" for t in totals)
        ax.text(len(levels) * (ds.sizes["claim"] + 0.5) + 0.2, y + 0.5, text, va="center",
                fontsize=8)  # fmt: skip
    ax.set_yticks(np.arange(rows) + 0.5, [str(ds.reading.values[i]) for i in order], fontsize=7)
    ticks, labels = [], []
    for k, level in enumerate(levels):
        for j, claim in enumerate(ds.claim.values):
            ticks.append(k * (ds.sizes["claim"] + 0.5) + j + 0.5)
            labels.append(f"{claim}\n{level}" if j == 2 else f"{claim}")
    ax.set_xticks(ticks, labels, fontsize=8)
    ax.xaxis.tick_top()
    ax.set_xlim(0, len(levels) * (ds.sizes["claim"] + 0.5) + 2.2)
    ax.set_ylim(rows, 0)
    for side in ("right", "bottom", "left", "top"):
        ax.spines[side].set_visible(False)
    ax.tick_params(length=0)
    handles = [Patch(color=c, label=v) for v, c in VERDICT_COLORS.items() if v]
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.01),
              ncol=4, frameon=False)  # fmt: skip
    ax.set_title(
        "claims 1–5 under each reading (score at right: 1 per claim reproduced, ½ per claim "
        f"partly; {ds.attrs.get('mode', '')} mode)",
        fontsize=9,
    )
    return save_formats(fig, stem)


def _cell(x: float, y: float, color: str):
    from matplotlib.patches import Rectangle

    return Rectangle((x + 0.04, y + 0.04), 0.92, 0.92, color=color, lw=0)

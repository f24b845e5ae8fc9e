"""The theory figure: K(ω₀) against the Sakaguchi thresholds, α(ω₀), and ω_c(σ)."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr


def plot_theory(ds: xr.Dataset, path=None):
    """Panels from a `predict.reduced_theory` dataset; written to ``path`` when given.

    (a) K(ω₀) measured (band: ±1σ) and estimated, with K_c(α(ω₀), σ) for each σ: the
    crossings are the predicted ω_c. (b) α(ω₀). (c) ω_c against σ, and where the
    reduced model's r reaches 1/2. (d) The reduced model's r_eq(ω₀), when it was run.
    Returns the figure.
    """
    import matplotlib

    from ..plots import finish_figure, new_figure

    curves = "r_reduced" in ds
    fig = new_figure(path, figsize=(18.5 if curves else 14, 4.2), layout="constrained")
    axes = fig.subplots(1, 4 if curves else 3)
    bpm = ds.bpm.values
    n_text = "N → ∞" if ds.attrs["n"] == "inf" else f"N = {ds.attrs['n']}"
    ax = axes[0]
    ax.fill_between(bpm, ds.k - ds.k_err, ds.k + ds.k_err, color="C0", alpha=0.25, lw=0)
    ax.plot(bpm, ds.k, "o-", color="C0", ms=4, label=f"K measured ({ds.attrs['method']})")
    ax.plot(bpm, ds.k_estimate, "--", color="C0", lw=1, label="K analytic estimate")
    colors = matplotlib.colormaps["plasma"](np.linspace(0.1, 0.8, ds.sizes["sigma"]))
    for color, sigma in zip(colors, ds.sigma.values, strict=True):
        ax.plot(
            bpm, ds.k_c.sel(sigma=sigma), ":", color=color, lw=1.2, label=f"K_c, σ = {sigma:g} BPM"
        )
        wc = float(ds.omega_c.sel(sigma=sigma))
        if np.isfinite(wc):
            ax.axvline(wc, color=color, lw=0.8, alpha=0.6)
    ax.set(
        xlabel="ω₀ (nominal BPM)",
        ylabel="K (rad/s)",
        yscale="log",
        title=f"coupling and Sakaguchi threshold, {n_text}",
    )
    ax.legend(fontsize=7, loc="upper left")
    ax = axes[1]
    deg = 180 / math.pi
    ax.fill_between(
        bpm,
        (ds.alpha - ds.alpha_err) * deg,
        (ds.alpha + ds.alpha_err) * deg,
        color="C1",
        alpha=0.25,
        lw=0,
    )
    ax.plot(bpm, ds.alpha * deg, "o-", color="C1", ms=4, label="measured")
    ax.plot(bpm, ds.alpha_estimate * deg, "--", color="C1", lw=1, label="analytic estimate")
    ax.set(xlabel="ω₀ (nominal BPM)", ylabel="α (degrees)", title="phase lag")
    ax.legend(fontsize=8)
    ax = axes[2]
    sigma = ds.sigma.values
    low = np.nan_to_num(ds.omega_c - ds.omega_c_low)
    high = np.nan_to_num(ds.omega_c_high - ds.omega_c)
    ax.errorbar(
        sigma,
        ds.omega_c,
        yerr=[low, high],
        fmt="o-",
        capsize=3,
        color="C2",
        label=f"predicted ω_c, {n_text}",
    )
    ax.axhline(185, color="0.5", ls="--", lw=0.8, label="paper: ω_c ≈ 185 BPM")
    if curves:
        ax.plot(sigma, ds.omega_half, "s--", color="C3", ms=4, label="reduced model: r = 1/2")
    ax.set(xlabel="σ (BPM, nominal)", ylabel="ω_c (nominal BPM)", title="predicted onset")
    ax.legend(fontsize=8)
    if curves:
        ax = axes[3]
        for color, sigma in zip(colors, ds.sigma.values, strict=True):
            ax.plot(
                bpm,
                ds.r_reduced.sel(sigma=sigma),
                "o-",
                ms=3,
                color=color,
                label=f"σ = {sigma:g} BPM",
            )
            wc = float(ds.omega_c.sel(sigma=sigma))
            if np.isfinite(wc):
                ax.axvline(wc, color=color, lw=0.8, alpha=0.6)
        ax.set(
            xlabel="ω₀ (nominal BPM)",
            ylabel="r_eq",
            ylim=(0, 1),
            title=f"reduced model, {n_text} (lines: ω_c)",
        )
        ax.legend(fontsize=7, loc="lower right")
    return finish_figure(fig, path)

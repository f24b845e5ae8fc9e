"""One plotting function per reproduced figure, laid out like the paper's own.

Contract: each function takes the study's assembled `xarray.Dataset` (from
`metrosync.paper.runner`) and a path stem, writes ``<stem>.png`` and
``<stem>.pdf``, and returns the list of written paths. Axes carry the paper's
quantities and units (t in s, ω₀ in BPM, θ₂(0) in rad); r is the run-mean of the
crossing-interpolated order parameter, the paper's experimental phase method.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from ._canvas import new_figure, palette, save_formats
from .map_figures import plot_claims_map, plot_sigma_map

#: Line styles and markers cycled with the colours, so that curves that coincide
#: (Fig. 11's N = 2 and 4 end at the same r) stay distinguishable.
_STYLES = ("-", "--", "-.", ":")
_MARKERS = "osD^v<>ph*"


#: Symbols that the studies' texts write in plain Unicode, as mathtext for the figures.
_MATH = {"c_θ": r"$c_\theta$", "c_φ": r"$c_\varphi$", "ω_c": r"$\omega_c$"}


def _math(text: str) -> str:
    """``text`` with subscripted symbols (``c_θ``) typeset instead of shown literally."""
    for plain, typeset in _MATH.items():
        text = text.replace(plain, typeset)
    return text


def _subtitle(ds: xr.Dataset) -> str:
    a = ds.attrs
    runs = ds.sizes.get("run", a.get("runs", "?"))
    mode = a.get("mode", "")
    return (
        f"{mode} mode: mean of {runs} runs × {a.get('duration', 0):g} s, "
        f"{a.get('integrator', 'verlet')}, dt = {a.get('dt')} s"
    )


def plot_order_in_time(ds: xr.Dataset, stem: Path) -> list[Path]:
    """Figs. 8 and 11: ⟨r⟩(t) over runs, one curve per case of the study.

    ds : a time-series study, with ``r_mean`` (case, time) and ``case`` labels.
    """
    fig, ax = new_figure(figsize=(6.4, 4.2), constrained_layout=True)
    cases = ds.case.values
    # A qualitative palette: neighbours in a sequential one (176 and 184 BPM) look alike.
    colors = palette("tab10", np.arange(cases.size) % 10)
    every = max(1, ds.sizes["time"] // 10)
    for k, (color, case) in enumerate(zip(colors, cases, strict=True)):
        ax.plot(ds.time, ds.r_mean.sel(case=case), lw=1.2, color=color, label=str(case),
                ls=_STYLES[k % len(_STYLES)], marker=_MARKERS[k % len(_MARKERS)], ms=4,
                markevery=(k * every // cases.size, every))  # fmt: skip
    ax.set_xlabel("t (s)")
    ax.set_ylabel("r (mean over runs)")
    ax.set_ylim(0, 1.02)
    ax.set_xlim(0, float(ds.time[-1]))
    ax.legend(title=ds.attrs.get("legend_title") or None, fontsize=8, loc="best")
    ax.set_title(_math(f"{ds.attrs['figure']}: {ds.attrs['title']}\n{_subtitle(ds)}"), fontsize=9)
    return save_formats(fig, stem)


def plot_sweep(ds: xr.Dataset, stem: Path) -> list[Path]:
    """Fig. 10: equilibrium r (top) and σ_r (bottom) against ω₀, one curve per N.

    ds : a sweep study, with ``r_eq_mean`` and ``sigma_r`` (n, bpm).
    """
    fig, (top, bottom) = new_figure(2, 1, figsize=(6.4, 7.0), sharex=True, constrained_layout=True)
    colors = palette("plasma", np.linspace(0.0, 0.85, ds.sizes["n"]))
    for color, n in zip(colors, ds.n.values, strict=True):
        kw = {"color": color, "marker": "o", "ms": 3, "lw": 1.2, "label": f"N = {int(n)}"}
        top.plot(ds.bpm, ds.r_eq_mean.sel(n=n), **kw)
        bottom.plot(ds.bpm, ds.sigma_r.sel(n=n), **kw)
    top.axvline(185, color="0.5", ls="--", lw=0.8, label=r"paper's $\omega_c$ = 185 BPM")
    bottom.axvline(185, color="0.5", ls="--", lw=0.8)
    top.set_ylabel("equilibrium r (mean over runs)")
    top.set_ylim(0, 1.02)
    bottom.set_ylabel(r"$\sigma_r$ (spread of r over runs)")
    bottom.set_xlabel("ω₀ (BPM)")
    top.legend(fontsize=8, loc="lower right")
    sigma = ds.attrs.get("sigma_bpm_study", float(ds.sigma_realized.mean()))
    top.set_title(f"{ds.attrs['figure']}: σ = {sigma:.3g} BPM\n{_subtitle(ds)}", fontsize=9)
    return save_formats(fig, stem)


def plot_z(ds: xr.Dataset, stem: Path) -> list[Path]:
    """The §6 figure: z against θ₂(0), one curve per regime; hollow markers = overturned.

    ds : the z-study, with ``z`` and ``status`` (regime, theta2).
    """
    fig, ax = new_figure(figsize=(6.4, 5.6), layout="constrained")
    markers = "osD^v"
    for i, regime in enumerate(ds.regime.values):
        z = ds.z.sel(regime=regime)
        bad = (ds.status.sel(regime=regime) != 0).values
        (line,) = ax.plot(
            ds.theta2,
            z,
            lw=1,
            marker=markers[i % len(markers)],
            ms=4,
            label=_math(str(regime)),
            ls="-" if ds.from_paper.values[i] else ":",
        )
        if bad.any():
            ax.plot(
                ds.theta2.values[bad],
                z.values[bad],
                ls="none",
                marker="o",
                ms=9,
                mfc="none",
                mec=line.get_color(),
            )
    ax.plot([], [], ls="none", marker="o", ms=9, mfc="none", mec="k", label="pendulum overturned")
    ax.axhline(0, color="0.7", lw=0.6)
    ax.set_xlabel("θ₂(0) (rad)")
    ax.set_ylabel("z: +1 in phase, −1 in anti-phase")
    ax.set_ylim(-1.05, 1.05)
    fig.legend(fontsize=7, loc="outside lower center", ncols=1)
    a = ds.attrs
    ax.set_title(
        f"z figure (§6): N = 2, {a['bpm']:g} BPM, θ₁(0) = {a['theta1_0']} rad, θ̇(0) = 0\n"
        f"{a.get('mode', '')} mode: t = {a.get('duration', 0):g} s, "
        f"{a.get('integrator', 'verlet')}, dt = {a.get('dt')} s",
        fontsize=9,
    )
    return save_formats(fig, stem)


def plot_comparison(ds: xr.Dataset, stem: Path) -> list[Path]:
    """Fig. 9: simulated against measured equilibrium r, N = 7, one point per ω₀.

    ds : ``r_sim``, ``sigma_r_sim``, ``r_exp`` (bpm).
    """
    fig, ax = new_figure(figsize=(4.8, 4.6), constrained_layout=True)
    ax.plot([0, 1], [0, 1], "k--", lw=0.8, label=r"$r_\mathrm{sim} = r_\mathrm{exp}$")
    # Error bars: σ of r over the simulated runs, and over the logs where there are several.
    xerr = ds.r_exp_std if "r_exp_std" in ds else None
    ax.errorbar(
        ds.r_exp,
        ds.r_sim,
        xerr=xerr,
        yerr=ds.sigma_r_sim,
        ls="none",
        marker="o",
        mfc="none",
        capsize=2,
        label="ω₀ of Table 1 (bars: σ over runs / logs)",
    )
    for bpm, x, y in zip(ds.bpm.values, ds.r_exp.values, ds.r_sim.values, strict=True):
        ax.annotate(f"{bpm:g}", (x, y), textcoords="offset points", xytext=(4, -10), fontsize=7)
    ax.set_xlabel(r"$r_\mathrm{exp}$ (measured, mean over logs)")
    ax.set_ylabel(r"$r_\mathrm{sim}$ (simulated, mean over runs)")
    ax.set_xlim(0, 1.02)
    ax.set_ylim(0, 1.02)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title("Fig. 9: simulated vs measured equilibrium r (N = 7)", fontsize=9)
    return save_formats(fig, stem)


def plot_estimation(ds: xr.Dataset, stem: Path) -> list[Path]:
    """§5: the three steps of the parameter estimation, against the true values.

    ds : the estimation study (`metrosync.paper.estimation`): the fitted data of each
    step and ``disk_amplitude`` (c_phi), the sensitivity curve.
    """
    fig, (decay, drive, disk) = new_figure(1, 3, figsize=(14.0, 4.4), constrained_layout=True)
    est = ds.estimate
    steps = (("decay", "c_theta (trajectory)", "o"), ("gate", "c_theta (light gate)", "s"))
    for prefix, row, marker in steps:
        label = rf"{row[9:-1]}: $c_\theta$ = {float(est.sel(parameter=row)):.4g}"
        (line,) = decay.plot(ds[f"{prefix}_x"], ds[f"{prefix}_y"], marker, ms=3, mfc="none",
                             label=label)  # fmt: skip
        decay.plot(ds[f"{prefix}_fit_x"], ds[f"{prefix}_fit_y"], "-", lw=1, color=line.get_color())
    decay.set_xlabel("t (s)")
    decay.set_ylabel("log swing amplitude: u(A) ≈ ln(A / rad)")
    decay.set_title(rf"1. free decay, drive off: true $c_\theta$ = {float(ds.true[0]):.3g} kg m²/s")
    decay.legend(fontsize=8)

    drive.plot(ds.drive_x, ds.drive_y, "o", ms=4, label="model runs of the fit")
    measured = ds.attrs["steady_amplitude_measured"]
    drive.axhline(measured, color="0.4", lw=0.8, label=f"measured amplitude {measured:.3f} rad")
    drive.axvline(float(ds.true.sel(parameter="M")), color="k", ls="--", lw=0.8, label="true M")
    drive.axvline(float(est.sel(parameter="M")), color="C3", lw=1,
                  label=f"estimate {float(est.sel(parameter='M')):.4g} N m s")  # fmt: skip
    drive.set_xscale("log")
    drive.set_xlabel("M (N m s)")
    drive.set_ylabel("steady amplitude (rad)")
    drive.set_title("2. steady amplitude, rigid support")
    drive.legend(fontsize=8)

    disk.plot(ds.c_phi, ds.disk_amplitude * 1e3, "o-", ms=3, lw=1,
              label=r"model, true $c_\theta$ and M")  # fmt: skip
    for row, key, style in (
        ("c_phi (published)", "disk_amplitude_measured", "--"),
        ("c_phi (control)", "disk_amplitude_measured_control", ":"),
    ):
        true = float(ds.true.sel(parameter=row))
        disk.axvline(true, color="k", ls=style, lw=0.8,
                     label=rf"true $c_\varphi$ = {true:g} ({row[7:-1]})")  # fmt: skip
        disk.axhline(ds.attrs[key] * 1e3, color="0.5", ls=style, lw=0.8)
    chained = float(est.sel(parameter="c_phi (published)"))
    if np.isfinite(chained):
        disk.axvline(chained, color="C3", lw=1, label=f"estimate for the published: {chained:.3g}")
    disk.set_xscale("log")
    disk.set_xlabel(r"$c_\varphi$ (kg m²/s)")
    disk.set_ylabel("disk amplitude (mrad)")
    disk.set_title(
        f"3. synchronized disk, N = {ds.attrs['n']}, {ds.attrs['disk_duration']:g} s runs"
    )
    disk.legend(fontsize=7, loc="lower left")
    fig.suptitle(_math(f"{ds.attrs['figure']}: {ds.attrs['title']} "
                       f"({ds.attrs.get('mode', '')} mode)"), fontsize=10)  # fmt: skip
    return save_formats(fig, stem)


#: Which function draws each study kind (by the study's class name).
PLOTTERS = {
    "TimeSeriesStudy": plot_order_in_time,
    "SweepStudy": plot_sweep,
    "ZStudy": plot_z,
    "EstimationStudy": plot_estimation,
    "SigmaMapStudy": plot_sigma_map,
    "ClaimsMapStudy": plot_claims_map,
}

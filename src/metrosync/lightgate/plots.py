"""Plot of an `analyze` result: r(t) per log and averaged, and the equilibrium window."""

from __future__ import annotations

from pathlib import Path

from .._words import plural
from ..plots import finish_figure, new_figure, order_axes


def plot_analysis(ds, path: Path | str | None = None):
    """r(t) of each log (thin) and their mean (thick); returns the figure.

    ds : an `analyze` dataset, r (time) and r_runs (log, time).
    path : write the figure there (atomically) when given.
    """
    fig = new_figure(path, figsize=(7, 4), layout="constrained")
    ax = fig.subplots()
    t = ds.time.values
    for k in range(ds.sizes["log"]):
        ax.plot(t, ds.r_runs.values[k], lw=0.6, alpha=0.5, color="0.5")
    ax.plot(
        t, ds.r.values, lw=1.5, color="C0", label=f"r, mean of {plural(ds.sizes['log'], 'log')}"
    )
    ax.set_title(
        f"light gate: {plural(ds.sizes['metronome'], 'metronome')}, "
        f"σ = {ds.attrs['sigma_bpm']:.3f} BPM"
    )
    order_axes(ax, t[-1], ds.attrs["equilibrium_window"], xlabel="t since first record (s)",
               window_label=rf"$r_\mathrm{{eq}}$ = {ds.attrs['r_eq']:.3f}")  # fmt: skip
    return finish_figure(fig, path)

"""Plot of an `analyze` result: r(t) per log and averaged, and the equilibrium window."""

from __future__ import annotations

from pathlib import Path

from ..plots import finish_figure, new_figure


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
    ax.plot(t, ds.r.values, lw=1.5, color="C0", label=f"r, mean of {ds.sizes['log']} log(s)")
    window = ds.attrs["equilibrium_window"]
    ax.axvspan(t[-1] - window, t[-1], color="0.9", zorder=0,
               label=f"r_eq = {ds.attrs['r_eq']:.3f}")  # fmt: skip
    ax.set_title(
        f"light gate: {ds.sizes['metronome']} metronomes, σ = {ds.attrs['sigma_bpm']:.3f} BPM"
    )
    ax.set_xlabel("t since first record (s)")
    ax.set_ylabel("r")
    ax.set_ylim(0, 1.02)
    ax.legend(loc="lower right")
    return finish_figure(fig, path)

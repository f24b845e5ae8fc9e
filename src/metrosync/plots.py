"""Plots of simulation results (matplotlib, headless)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def plot_order(ds, path: Path | str | None = None, *, ax=None):
    """r(t) averaged over runs, both phase definitions, with the equilibrium window.

    Returns the figure; writes it to ``path`` when given.
    """
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    else:
        fig = ax.figure
    t = ds.time.values
    ax.plot(t, ds.r.mean("run"), lw=1, label="r, analytic phase")
    with np.errstate(all="ignore"):
        ax.plot(t, ds.r_crossing.mean("run", skipna=True), lw=1, label="r, crossing phase")
    window = ds.attrs.get("equilibrium_window")
    if window:
        ax.axvspan(t[-1] - window, t[-1], color="0.9", zorder=0, label="equilibrium window")
    a = ds.attrs
    ax.set_title(
        f"N = {a['n']}, {a['bpm']} BPM, σ = {a['sigma_bpm']} BPM, mean of {a['runs']} runs"
    )
    ax.set_xlabel("t (s)")
    ax.set_ylabel("r")
    ax.set_ylim(0, 1.02)
    ax.legend(loc="lower right")
    if path is not None and own:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig

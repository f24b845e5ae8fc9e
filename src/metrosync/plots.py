"""Figures of results (matplotlib), and the two helpers every figure here uses.

Contract: a plotting function takes a dataset (or a result) and an optional
``path``. With a path, it draws on a plain `matplotlib.figure.Figure`, which needs
no GUI backend and is not registered with pyplot, writes it atomically in the
format of the path's suffix (`save_figure`) and returns it. Without a path, the
figure comes from pyplot, so that it shows in a notebook or with ``plt.show()``.
Nothing here changes matplotlib's backend.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._files import save_figure
from .errors import ParameterError


def new_figure(path: Path | str | None, **options):
    """A figure to draw on: pyplot's when ``path`` is None, else a plain `Figure`.

    ``options`` go to the figure (``figsize``, ``layout``, ...).
    """
    if path is None:
        import matplotlib.pyplot as plt

        return plt.figure(**options)
    from matplotlib.figure import Figure

    return Figure(**options)


def finish_figure(fig, path: Path | str | None, *, dpi: float = 120):
    """Write ``fig`` to ``path`` (atomically) when a path is given; returns ``fig``."""
    if path is not None:
        save_figure(fig, path, dpi=dpi)
    return fig


def plot_order(ds, path: Path | str | None = None, *, ax=None):
    """r(t) averaged over runs, both phase definitions, with the equilibrium window.

    ds : a `metrosync.simulate` dataset, r and r_crossing (time, run).
    path : write the figure there (PNG, PDF, SVG, ...) when given.
    ax : draw into these axes of a figure of yours instead (then no ``path``).

    Returns the figure.
    """
    if ax is None:
        fig = new_figure(path, figsize=(7, 4), layout="constrained")
        ax = fig.subplots()
    elif path is not None:
        raise ParameterError(
            "give `path` (a new figure, written there) or `ax` (your figure), not both."
        )
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
    return finish_figure(fig, path)

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
from ._words import plural
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
    """r(t) averaged over runs, both phase definitions, with the equilibrium window;
    with groups, also each group's r (analytic phase).

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
    # The crossing phase is undefined before a run's first crossings and after its last:
    # averaging whichever runs have one there would jump. Show the mean where all do.
    count = ds.r_crossing.notnull().sum("run")
    with np.errstate(all="ignore"):
        crossing = ds.r_crossing.mean("run").where(count == count.max())
    ax.plot(t, crossing, lw=1, label="r, crossing phase")
    a = ds.attrs
    if "r_group" in ds:
        labels = str(a["groups"]).split()
        for g, label in enumerate(labels):
            ax.plot(t, ds.r_group.isel(group=g).mean("run"), lw=1, ls="--",
                    label=f"r of group {g} ({label}), analytic")  # fmt: skip
        ensemble = f"N = {a['n']} in groups {' '.join(labels)} (N@BPM:σ)"
    else:
        ensemble = f"N = {a['n']}, {a['bpm']} BPM, σ = {a['sigma_bpm']} BPM"
    on_board = ", on a board" if a.get("platform") == "board" else ""
    ax.set_title(f"{ensemble}{on_board}, mean of {plural(a['runs'], 'run')}")
    order_axes(ax, t[-1], a.get("equilibrium_window"), xlabel="t (s)")
    return finish_figure(fig, path)


def order_axes(ax, end: float, window: float | None, *, xlabel: str,
               window_label: str = "equilibrium window") -> None:  # fmt: skip
    """Finish an r(t) panel: shade the final ``window`` (s) before ``end`` that r_eq
    averages (when there is one), label the axes, r from 0 to 1, legend."""
    if window:
        ax.axvspan(end - window, end, color="0.9", zorder=0, label=window_label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("r")
    ax.set_ylim(0, 1.02)
    ax.legend(loc="lower right")

"""Plots of one recorded run for the Python API (matplotlib).

`plot_run` stacks four panels over a shared time axis; each panel is also a function
of its own that draws into a given axes:

* `plot_angles`: θ_i(t) of every metronome;
* `plot_phase_differences`: Φ_i − Φ_0 wrapped to (−π, π], Φ the analytic phase
  atan2(−θ̇/ω, θ); they flatten as the metronomes lock;
* `plot_disk_angle`: φ(t);
* `plot_run_order`: r(t) (analytic and crossing phases) with the equilibrium window
  shaded and r_eq marked.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import numpy as np

from .recording import RecordedRun


def _colour(i: int):
    return matplotlib.colormaps["tab10"](i % 10)


def _legend_beside(ax, **options) -> None:
    """A legend to the right of the axes, where it covers no curve."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7,
              **options)  # fmt: skip


def plot_angles(run: RecordedRun, ax, *, start=None, end=None) -> None:
    """θ_i(t) of every metronome, rad."""
    keep = _keep(run, start, end)
    for i in range(run.n):
        ax.plot(run.time[keep], run.theta[keep, i], lw=0.6, color=_colour(i), label=f"{i}")
    ax.set_ylabel("θ (rad)")
    if run.n <= 10:
        _legend_beside(ax, title="metronome", title_fontsize=7)


def plot_phase_differences(run: RecordedRun, ax, *, start=None, end=None) -> None:
    """Φ_i − Φ_0 wrapped to (−π, π], as dots (a wrap is not a jump)."""
    keep = _keep(run, start, end)
    phase = np.arctan2(-run.theta_dot[keep] / run.omega, run.theta[keep])
    diff = np.angle(np.exp(1j * (phase[:, 1:] - phase[:, :1])))
    for i in range(1, run.n):
        ax.plot(run.time[keep], diff[:, i - 1], ".", ms=1.2, color=_colour(i))
    ax.set_ylim(-np.pi, np.pi)
    ax.set_yticks([-np.pi, 0, np.pi], ["−π", "0", "π"])
    ax.set_ylabel(r"$\Phi_i - \Phi_0$")


def plot_disk_angle(run: RecordedRun, ax, *, start=None, end=None) -> None:
    """The disk angle φ(t), rad, or on a board run the board's position, m."""
    keep = _keep(run, start, end)
    ax.plot(run.time[keep], run.phi[keep], lw=0.8, color="0.2")
    ax.set_ylabel("x (m)" if run.platform == "board" else "φ (rad)")


def plot_run_order(run: RecordedRun, ax, *, start=None, end=None) -> None:
    """r(t) of the run, both phase definitions, with the equilibrium window and r_eq."""
    keep = _keep(run, start, end)
    t = run.time[keep]
    ax.plot(t, run.r[keep], lw=0.8, label="r, analytic phase")
    ax.plot(t, run.r_crossing[keep], lw=0.8, label="r, crossing phase")
    window = run.equilibrium_window
    if math.isfinite(window):
        t_end = float(run.time[-1])
        ax.axvspan(t_end - window, t_end, color="0.9", zorder=0, label="equilibrium window")
        if math.isfinite(run.r_eq):
            ax.hlines(run.r_eq, t_end - window, t_end, colors="C3", lw=1.5,
                      label=rf"$r_\mathrm{{eq}}$ = {run.r_eq:.3f}")  # fmt: skip
    ax.set_ylim(0, 1.02)
    ax.set_ylabel("r")
    _legend_beside(ax)


def plot_run(ds, path: Path | str | None = None, *, run: int = 0, start=None, end=None):
    """Four stacked panels of one run: θ_i(t), Φ_i − Φ_0, φ(t), r(t).

    Parameters
    ----------
    ds : dataset from `metrosync.simulate(..., trajectories=True)`.
    path : write the figure there (PNG, PDF, SVG, ...) when given.
    run : which run.
    start, end : time window, s; default the whole recording.

    Returns
    -------
    The matplotlib figure: pyplot's without ``path``, a plain one written to ``path``
    otherwise (see `metrosync.plots`).
    """
    from ..plots import finish_figure, new_figure

    recorded = RecordedRun.from_dataset(ds, run)
    start, end = recorded.window(start, end)
    fig = new_figure(path, figsize=(9.5, 9), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    for draw, ax in zip(
        (plot_angles, plot_phase_differences, plot_disk_angle, plot_run_order), axes, strict=True
    ):
        draw(recorded, ax, start=start, end=end)
    axes[-1].set_xlim(start, end)
    axes[-1].set_xlabel("t (s)")
    a = recorded.attrs
    axes[0].set_title(
        f"N = {recorded.n}, {a.get('bpm', '?')} BPM, σ = {a.get('sigma_bpm', '?')} BPM, "
        f"run {recorded.run}"
    )
    return finish_figure(fig, path)


def _keep(run: RecordedRun, start, end) -> np.ndarray:
    start, end = run.window(start, end)
    return (run.time >= start) & (run.time <= end)

"""Pictures of a `track` result: the preview of what was found, and r(t) with the angles.

`plot_preview` draws the first frame with each metronome's searched sector, pivot and
number, so that a user can check what was found before trusting the numbers.
`plot_tracking` draws r(t) (as for the light gate) above the angles of the last
seconds, with the frames where a rod was lost marked.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._words import plural
from ..plots import finish_figure, new_figure, order_axes


def plot_preview(ds, path: Path | str | None = None):
    """The first frame with each metronome's sector, pivot and number; returns the figure.

    ds : a `metrosync.track` dataset (first_frame, pivot_x, pivot_y, vertical,
    sector_half_width, rod_inner, rod_outer).
    """
    from matplotlib.patches import Wedge

    picture = ds.first_frame.values
    h, w = picture.shape
    scale = ds.attrs["picture_scale"]
    fig = new_figure(path, figsize=(8, 8 * h / w + 0.4), layout="constrained")
    ax = fig.subplots()
    ax.imshow(picture, cmap="gray", vmin=0, vmax=255)
    for j in range(ds.sizes["metronome"]):
        x, y = float(ds.pivot_x[j]) * scale, float(ds.pivot_y[j]) * scale
        centre = float(ds.vertical[j])
        half = float(ds.sector_half_width[j])
        inner, outer = float(ds.rod_inner[j]) * scale, float(ds.rod_outer[j]) * scale
        # matplotlib's angles run counter-clockwise from +x with y up; the picture's y
        # runs down, so the upward direction is -90° there and clockwise is positive
        lo, hi = np.degrees(centre - half) - 90, np.degrees(centre + half) - 90
        color = f"C{j % 10}"
        ax.add_patch(Wedge((x, y), outer, lo, hi, width=outer - inner, fill=False,
                           color=color, lw=1.5))  # fmt: skip
        ax.plot([x, x + outer * np.sin(centre)], [y, y - outer * np.cos(centre)], color=color,
                lw=0.8, ls="--")  # fmt: skip
        ax.plot(x, y, "o", color=color, ms=6, mec="white")
        ax.annotate(str(j), (x, y), xytext=(6, 6), textcoords="offset points", color="white",
                    fontsize=12, weight="bold",
                    bbox=dict(boxstyle="round,pad=0.2", fc=color, ec="none"))  # fmt: skip
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_axis_off()
    ax.set_title(f"{plural(ds.sizes['metronome'], 'metronome')}: sector searched, pivot (dot), "
                 f"vertical (dashed)")  # fmt: skip
    return finish_figure(fig, path)


def plot_tracking(ds, path: Path | str | None = None, *, last: float = 6.0):
    """r(t) and, below, each rod's angle over the ``last`` seconds; returns the figure."""
    fig = new_figure(path, figsize=(8, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, height_ratios=(1.3, 1))
    t = ds.time.values
    top.plot(t, ds.r.values, lw=1.5, color="C0", label="r")
    top.set_title(f"video: {plural(ds.sizes['metronome'], 'metronome')}, "
                  f"σ = {ds.attrs['sigma_bpm']:.3f} BPM")  # fmt: skip
    order_axes(top, t[-1], ds.attrs["equilibrium_window"], xlabel="t since the first frame (s)",
               window_label=rf"$r_\mathrm{{eq}}$ = {ds.attrs['r_eq']:.3f}")  # fmt: skip
    frame_t = ds.frame_time.values
    keep = frame_t >= frame_t[-1] - last
    for j in range(ds.sizes["metronome"]):
        a = np.degrees(ds.angle.values[keep, j])
        bottom.plot(frame_t[keep], a, lw=1, color=f"C{j % 10}", label=f"{j}")
        lost = ds.angle_quality.values[keep, j] == 2
        if lost.any():
            bottom.plot(frame_t[keep][lost], np.zeros(lost.sum()), "x", color=f"C{j % 10}")
    bottom.axhline(0, color="0.6", lw=0.6)
    bottom.set_xlabel("t since the first frame (s)")
    bottom.set_ylabel("angle from the vertical (°)")
    bottom.legend(title="metronome", loc="upper right", fontsize="small",
                  ncol=min(ds.sizes["metronome"], 8))  # fmt: skip
    return finish_figure(fig, path)

"""Watch a run: the disk seen from above, beside r(t), as a GIF or an MP4.

Each frame shows the disk turned by φ, every metronome as a box on the rim, and its
pendulum seen from above: a rod along the rim's tangent (the plane it swings in)
whose visible length is proportional to sin θ_i, with a bob coloured by the
metronome's phase atan2(−θ̇/ω, θ) on a cyclic colour map. Synchronized metronomes
share a colour. Beside it, r(t) of the run with the equilibrium window shaded and a
cursor at the frame's time.

Frame k shows simulated time start + k·speedup/fps, so an animation of [start, end]
has floor((end − start)·fps/speedup) + 1 frames. States between records come from
`RecordedRun`'s Hermite interpolation of the recorded trajectories.

The format follows the file name: ``.gif`` (Pillow, always available) or ``.mp4``
(ffmpeg, when it is on PATH). Writes are atomic.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
from matplotlib import animation as mpl_animation
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from .._files import atomic_path
from ..errors import ParameterError
from ..progress import progress_bar
from .recording import RecordedRun

#: Largest number of frames `animate` renders (a guard against a forgotten speed-up).
MAX_FRAMES = 20_000
#: Pendulum rod length drawn from above at sin θ = 1, as a fraction of the disk radius.
ROD_SCALE = 0.35
PHASE_CMAP = "hsv"


def frame_count(start: float, end: float, fps: float, speedup: float) -> int:
    """Number of frames of the window [start, end]: floor((end − start)·fps/speedup) + 1."""
    return int(math.floor((end - start) * fps / speedup + 1e-9)) + 1


def frame_times(start: float, end: float, fps: float, speedup: float) -> np.ndarray:
    """(K,) simulated times of the frames: start + k·speedup/fps, k = 0 … K−1."""
    return start + np.arange(frame_count(start, end, fps, speedup)) * (speedup / fps)


def _check_positive(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.number):
        raise ParameterError(f"`{name}` must be a number > 0, got {value!r}.")
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"`{name}` must be a number > 0, got {value!r}.")
    return float(value)


def writer_for(path: Path, fps: float):
    """The matplotlib writer for ``path``'s suffix (.gif or .mp4)."""
    suffix = path.suffix.lower()
    if suffix == ".gif":
        return mpl_animation.PillowWriter(fps=fps)
    if suffix == ".mp4":
        if shutil.which("ffmpeg") is None:
            raise ParameterError(
                f"writing {path.name!r} needs ffmpeg on PATH; install it "
                f"(e.g. `apt-get install ffmpeg`) or write a .gif instead."
            )
        return mpl_animation.FFMpegWriter(fps=fps, codec="h264", extra_args=["-pix_fmt", "yuv420p"])
    raise ParameterError(f"the animation file must end in .gif or .mp4, got {str(path)!r}.")


class DiskView:
    """The figure and its artists; `draw(t)` moves them to simulated time t."""

    def __init__(self, run: RecordedRun, start: float, end: float, *, size=(8.0, 4.0)):
        self.run = run
        self.fig = Figure(figsize=size, layout="constrained")
        disk_ax, order_ax = self.fig.subplots(1, 2, width_ratios=(1, 1.25))
        radius = run.radius
        reach = radius * (1 + 1.6 * ROD_SCALE)
        disk_ax.set_xlim(-reach, reach)
        disk_ax.set_ylim(-reach, reach)
        disk_ax.set_aspect("equal")
        disk_ax.set_axis_off()
        disk_ax.add_patch(Circle((0, 0), radius, facecolor="0.93", edgecolor="0.55", lw=1.2))
        self.spokes = LineCollection([], colors="0.75", lw=0.8)
        self.guides = LineCollection([], colors="0.82", lw=0.8)
        self.rods = LineCollection([], colors="0.25", lw=1.6)
        disk_ax.add_collection(self.spokes)
        disk_ax.add_collection(self.guides)
        disk_ax.add_collection(self.rods)
        self.boxes = disk_ax.scatter(np.zeros(run.n), np.zeros(run.n), s=40, marker="s",
                                     c="0.45", zorder=3)  # fmt: skip
        self.bobs = disk_ax.scatter(
            np.zeros(run.n), np.zeros(run.n), s=55, zorder=4, c=np.zeros(run.n),
            cmap=PHASE_CMAP, norm=Normalize(-np.pi, np.pi), edgecolors="0.2", linewidths=0.5,
        )  # fmt: skip
        self.clock = disk_ax.text(0.0, 1.0, "", transform=disk_ax.transAxes, va="top", fontsize=9)
        disk_ax.text(1.0, 0.0, "colour = phase", transform=disk_ax.transAxes, ha="right",
                     va="bottom", fontsize=7, color="0.4")  # fmt: skip

        keep = (run.time >= start) & (run.time <= end)
        order_ax.plot(run.time[keep], run.r[keep], lw=1, color="C0", label="r (analytic phase)")
        window = run.equilibrium_window
        t_last = float(run.time[-1])
        if math.isfinite(window) and t_last - window < end:
            order_ax.axvspan(max(start, t_last - window), end, color="0.9", zorder=0,
                             label="equilibrium window")  # fmt: skip
        order_ax.set_xlim(start, end)
        order_ax.set_ylim(0, 1.02)
        order_ax.set_xlabel("t (s)")
        order_ax.set_ylabel("r")
        order_ax.legend(loc="lower right", fontsize=7)
        a = run.attrs
        title = f"N = {run.n}, {a.get('bpm', '?')} BPM, σ = {a.get('sigma_bpm', '?')} BPM"
        order_ax.set_title(f"{title}, run {run.run}", fontsize=9)
        self.cursor = order_ax.axvline(start, color="C3", lw=1.2)

    def draw(self, t: float) -> None:
        """Move every artist to simulated time ``t`` (s)."""
        run = self.run
        times = np.array([t])
        theta = run.theta_at(times)[0]
        phase = run.phase_at(times)[0]
        phi = float(run.phi_at(times)[0])
        angle = run.rim_angles + phi
        radial = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        tangent = np.stack([-np.sin(angle), np.cos(angle)], axis=-1)
        pivot = run.radius * radial
        rod = ROD_SCALE * run.radius
        tip = pivot + rod * np.sin(theta)[:, None] * tangent
        spoke_angles = phi + np.arange(4) * np.pi / 4
        ends = run.radius * np.stack([np.cos(spoke_angles), np.sin(spoke_angles)], axis=-1)
        self.spokes.set_segments([[-e, e] for e in ends])
        self.guides.set_segments(
            [[p - rod * u, p + rod * u] for p, u in zip(pivot, tangent, strict=True)]
        )
        self.rods.set_segments([[p, q] for p, q in zip(pivot, tip, strict=True)])
        self.boxes.set_offsets(pivot)
        self.bobs.set_offsets(tip)
        self.bobs.set_array(phase)
        r_now = float(run.r_at(times)[0])
        self.clock.set_text(f"t = {t:6.1f} s   r = {r_now:.2f}   φ = {phi:+.2f} rad")
        self.cursor.set_xdata([t, t])


def animate(
    ds,
    path: Path | str,
    *,
    run: int = 0,
    fps: float = 20.0,
    speedup: float = 1.0,
    start: float | None = None,
    end: float | None = None,
    dpi: float = 80.0,
    size: tuple[float, float] = (8.0, 4.0),
    progress: bool | None = None,
) -> int:
    """Render run ``run`` of ``ds`` (with trajectories) to a GIF or MP4.

    Parameters
    ----------
    ds : dataset from `metrosync.simulate(..., trajectories=True)`.
    path : output file, ``.gif`` or ``.mp4``.
    run : which run of the ensemble.
    fps : frames per second of the animation.
    speedup : simulated seconds per second of animation.
    start, end : simulated time window, s; default the whole recording.
    dpi, size : resolution and figure size (inches); pixels = size·dpi.
    progress : show a progress bar; default when stderr is a terminal.

    Returns
    -------
    The number of frames written.
    """
    import sys

    path = Path(path)
    fps = _check_positive("fps", fps)
    speedup = _check_positive("speedup", speedup)
    dpi = _check_positive("dpi", dpi)
    writer = writer_for(path, fps)
    recorded = RecordedRun.from_dataset(ds, run)
    start, end = recorded.window(start, end)
    count = frame_count(start, end, fps, speedup)
    if count > MAX_FRAMES:
        raise ParameterError(
            f"{count} frames exceed {MAX_FRAMES}; raise `speedup` (now {speedup:g}), "
            f"lower `fps` (now {fps:g}) or shorten the window."
        )
    times = frame_times(start, end, fps, speedup)
    view = DiskView(recorded, start, end, size=size)
    show = sys.stderr.isatty() if progress is None else progress
    with progress_bar(total=times.size, unit="frame", enabled=show, desc="animate") as bar:
        # The writers pick the format from the file name, so the temporary one keeps it.
        with atomic_path(path, keep_suffix=True) as tmp, writer.saving(view.fig, str(tmp), dpi):
            for t in times:
                view.draw(float(t))
                writer.grab_frame()
                bar.update(1)
    return int(times.size)

"""Watch a run: the disk seen from above (or the board on rollers from the side), beside
r(t), as a GIF or an MP4.

Each frame shows the disk turned by φ, every metronome as a box on the rim, and its
pendulum seen from above: a rod along the rim's tangent (the plane it swings in)
whose visible length is proportional to sin θ_i, with a bob coloured by the
metronome's phase atan2(−θ̇/ω, θ) on a cyclic colour map. Synchronized metronomes
share a colour. On a board run (the dataset's ``platform`` attribute) the frame shows
instead the board from the side on its two rollers, the pendulums swinging along it
(`BoardView`). Beside it, r(t) of the run with the equilibrium window shaded and a
cursor at the frame's time.

Frame k shows simulated time start + k·speedup/fps, so an animation of [start, end]
has floor((end − start)·fps/speedup) + 1 frames. States between records come from
`RecordedRun`'s Hermite interpolation of the recorded trajectories.

The format follows the file name: ``.gif`` (Pillow, always available) or ``.mp4``
(ffmpeg, when it is on PATH). Frames are streamed to the file one at a time
(`metrosync.show.frames`), so memory holds one frame however long the animation; the
figure's static parts are drawn once and each frame redraws only what moves. Without
a speed-up, one is chosen that fits the window in `TARGET_LENGTH` seconds. The size
of the frames and the time it will take are checked before the first is drawn:
frames larger than `MAX_SIDE` pixels a side are refused. Writes are atomic.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib import font_manager
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from PIL import Image, ImageDraw, ImageFont

from .. import interrupts
from .._files import atomic_path
from .._words import plural
from ..budget import Budget
from ..errors import ParameterError
from ..progress import progress_bar
from .frames import check_format, open_sink
from .recording import RecordedRun

#: Largest number of frames `animate` renders (a guard against a forgotten speed-up).
MAX_FRAMES = 20_000
#: Length (s) of an animation whose speed-up was not given.
TARGET_LENGTH = 30.0
#: Speed-ups chosen automatically: these times powers of ten.
NICE_SPEEDUPS = (1.0, 2.0, 2.5, 4.0, 5.0)
#: Frame size limits, pixels a side.
MAX_SIDE, MIN_SIDE = 4096, 100
#: Wall time of one 640 × 320 frame (drawing, colour reduction, encoding), s: measured
#: 25-35 ms on the 2-core development machine.
FRAME_SECONDS = 0.05
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


def auto_speedup(span: float, target: float = TARGET_LENGTH) -> float:
    """The smallest of 1, 2, 2.5, 4, 5 times a power of ten that shows ``span`` seconds
    in at most ``target`` seconds (at least 1: never slower than real time)."""
    need = span / target
    if need <= 1:
        return 1.0
    decade = 10.0 ** math.floor(math.log10(need))
    for nice in (*NICE_SPEEDUPS, 10.0):
        if nice * decade >= need * (1 - 1e-12):
            return nice * decade
    raise AssertionError("unreachable")


def frame_pixels(dpi: float, size: tuple[float, float]) -> tuple[int, int]:
    """(width, height) in pixels of frames of ``size`` inches at ``dpi``; refuses a
    size outside [`MIN_SIDE`, `MAX_SIDE`] pixels a side, naming the option to change."""
    dpi = _check_positive("dpi", dpi)
    if not (isinstance(size, tuple | list) and len(size) == 2):
        raise ParameterError(f"`size` must be (width, height) in inches, got {size!r}.")
    width_in, height_in = (_check_positive("size", float(v)) for v in size)
    width, height = int(width_in * dpi), int(height_in * dpi)  # as Agg sizes its canvas
    if max(width, height) > MAX_SIDE or min(width, height) < MIN_SIDE:
        low = MIN_SIDE / min(width_in, height_in)
        high = MAX_SIDE / max(width_in, height_in)
        raise ParameterError(
            f"`dpi` = {dpi:g} makes {width_in:g} x {height_in:g} in frames of {width} x "
            f"{height} pixels; frames must be {MIN_SIDE} to {MAX_SIDE} pixels a side: use a "
            f"`dpi` between {math.ceil(low)} and {math.floor(high)}, or another `size`."
        )
    return width, height


def plan(start: float, end: float, *, fps: float, speedup: float | None, dpi: float,
         size: tuple[float, float], path: Path) -> tuple[float, int, Budget]:  # fmt: skip
    """Check an animation of [start, end] before anything is drawn.

    Returns the speed-up (chosen when None), the frame count and the `Budget` (one
    frame's buffers, and the time for every frame).
    """
    fps = _check_positive("fps", fps)
    speedup = auto_speedup(end - start) if speedup is None else _check_positive("speedup", speedup)
    check_format(Path(path), fps)
    width, height = frame_pixels(dpi, size)
    count = frame_count(start, end, fps, speedup)
    if count > MAX_FRAMES:
        raise ParameterError(
            f"{plural(count, 'frame')} exceed {MAX_FRAMES}; raise `speedup` (now {speedup:g}), "
            f"lower `fps` (now {fps:g}) or shorten the window."
        )
    pixels = float(width * height)
    budget = Budget(
        "the animation",
        # the canvas, its saved background, the RGB copy and its palette image
        {"one frame's buffers": 13.0 * pixels},
        seconds=count * FRAME_SECONDS * max(1.0, pixels / (640 * 320)),
        work=f"{plural(count, 'frame')} of {width} x {height} pixels",
        fixes="raise `speedup`, lower `fps` or `dpi`, or shorten the window (`start`, `end`)",
    )
    return speedup, count, budget


class DiskView:
    """The figure and its artists; `draw(t)` moves them to simulated time t."""

    def __init__(self, run: RecordedRun, start: float, end: float, *, size=(8.0, 4.0)):
        self.run = run
        self.fig = Figure(figsize=size, layout="constrained")
        disk_ax, order_ax = self.fig.subplots(1, 2, width_ratios=(1, 1.25))
        disk_ax.set_aspect("equal")
        disk_ax.set_axis_off()
        platform = self._setup_platform(disk_ax)
        self.rods = LineCollection([], colors="0.25", lw=1.6)
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
        self.moving = (*platform, self.rods, self.boxes, self.bobs, self.cursor)
        self._background = None

    def _setup_platform(self, ax) -> tuple:
        """Draw the platform's still parts on ``ax``; returns the artists that move
        with it (besides rods, boxes and bobs)."""
        radius = self.run.radius
        reach = radius * (1 + 1.6 * ROD_SCALE)
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)
        ax.add_patch(Circle((0, 0), radius, facecolor="0.93", edgecolor="0.55", lw=1.2))
        self.spokes = LineCollection([], colors="0.75", lw=0.8)
        self.guides = LineCollection([], colors="0.82", lw=0.8)
        ax.add_collection(self.spokes)
        ax.add_collection(self.guides)
        return self.spokes, self.guides

    def render(self, t: float, dpi: float) -> Image.Image:
        """The frame at simulated time ``t``, an RGB image.

        The static parts are drawn on the first call only; later calls restore them
        and draw what moves. The clock line is drawn by Pillow with matplotlib's font:
        matplotlib lays out and rasterizes a text anew at every draw, which took over
        half of a frame's time.
        """
        canvas = self.fig.canvas
        if self._background is None:
            self.fig.set_dpi(dpi)
            canvas = FigureCanvasAgg(self.fig)
            self.clock.set_visible(False)
            for artist in self.moving:
                artist.set_animated(True)  # left out of the full draw
            canvas.draw()
            self.fig.set_layout_engine("none")  # freeze the layout the draw settled
            self._background = canvas.copy_from_bbox(self.fig.bbox)
            x, y = self.clock.get_transform().transform(self.clock.get_position())
            self._clock_at = (x, canvas.get_width_height()[1] - y)
            size = self.clock.get_fontsize() * dpi / 72  # points to pixels
            self._font = ImageFont.truetype(font_manager.findfont(self.clock.get_fontproperties()),
                                            size=size)  # fmt: skip
        self.draw(t)
        canvas.restore_region(self._background)
        for artist in self.moving:
            self.fig.draw_artist(artist)
        width, height = canvas.get_width_height()
        image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(), "raw", "RGBA", 0, 1)
        image = image.convert("RGB")
        ImageDraw.Draw(image).text(self._clock_at, self.clock.get_text(), font=self._font,
                                   fill=(0, 0, 0), anchor="la")  # fmt: skip
        return image

    def draw(self, t: float) -> None:
        """Move every artist to simulated time ``t`` (s)."""
        run = self.run
        times = np.array([t])
        theta = run.theta_at(times)[0]
        phase = run.phase_at(times)[0]
        phi = float(run.phi_at(times)[0])
        self._move_platform(t, theta, phi)
        self.bobs.set_array(phase)
        r_now = float(run.r_at(times)[0])
        self.clock.set_text(f"t = {t:6.1f} s   r = {r_now:.2f}   {self._position(phi)}")
        self.cursor.set_xdata([t, t])

    @staticmethod
    def _position(phi: float) -> str:
        return f"φ = {phi:+.2f} rad"

    def _move_platform(self, t: float, theta: np.ndarray, phi: float) -> None:
        """Turn the disk by φ and set each pendulum on it at angle θ."""
        run = self.run
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


class BoardView(DiskView):
    """A board on rollers seen from the side (Pantaleone 2002), in metres: the
    metronomes stand in a row on it, each pendulum's rod (pivot to slider) swinging
    along the board. The board is drawn about its mean motion (`RecordedRun.
    board_offset_at`), so that a drifting undamped board stays in view; the cans
    under it roll without slipping, moving half as far and turning by x/(2a)."""

    #: A 12 fl. oz can's radius, the board's thickness, the rod drawn above the pivot,
    #: the pivot's height above the board, m (drawing sizes, not model parameters).
    CAN, THICK, ROD, PIVOT = 0.033, 0.012, 0.08, 0.02

    def _setup_platform(self, ax) -> tuple:
        from matplotlib.patches import Rectangle

        n = self.run.n
        self.length = max(0.09 * (n + 0.5), 10 * self.CAN)
        self.spacing = self.length / (n + 0.5)
        self.deck = 2 * self.CAN + self.THICK  # the board's top
        reach = 0.62 * self.length
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-0.01, self.deck + self.PIVOT + 1.6 * self.ROD)
        ax.axhline(0.0, color="0.6", lw=1)
        self.board = Rectangle((-self.length / 2, 2 * self.CAN), self.length, self.THICK,
                               facecolor="#e8d9bf", edgecolor="#9a8a70", lw=1)  # fmt: skip
        ax.add_patch(self.board)
        self.cans = [Circle((0, self.CAN), self.CAN, facecolor="#d9dde3", edgecolor="0.45",
                            lw=1) for _ in range(2)]  # fmt: skip
        for can in self.cans:
            ax.add_patch(can)
        self.can_marks = LineCollection([], colors="0.45", lw=0.8)
        ax.add_collection(self.can_marks)
        return self.board, *self.cans, self.can_marks

    @staticmethod
    def _position(phi: float) -> str:
        return f"x = {100 * phi:+.2f} cm"

    def _move_platform(self, t: float, theta: np.ndarray, phi: float) -> None:
        x = float(self.run.board_offset_at(np.array([t]))[0])
        self.board.set_x(x - self.length / 2)
        marks, turn = [], x / (2 * self.CAN)
        for side, can in zip((-1, 1), self.cans, strict=True):
            centre = (float(side * 0.3 * self.length + x / 2), float(self.CAN))
            can.set_center(centre)
            # turning clockwise as it rolls to +x
            u = self.CAN * np.array([np.cos(-turn), np.sin(-turn)])
            marks.append([np.subtract(centre, u), np.add(centre, u)])
        self.can_marks.set_segments(marks)
        n = self.run.n
        pivot = np.stack([x + (np.arange(n) - (n - 1) / 2) * self.spacing,
                          np.full(n, self.deck + self.PIVOT)], axis=-1)  # fmt: skip
        # θ > 0 moves the centre of mass (below the pivot) along +x: the rod's top, the
        # slider, the other way.
        tip = pivot + self.ROD * np.stack([-np.sin(theta), np.cos(theta)], axis=-1)
        self.rods.set_segments([[p, q] for p, q in zip(pivot, tip, strict=True)])
        self.boxes.set_offsets(pivot - [0.0, 0.5 * self.PIVOT])
        self.bobs.set_offsets(tip)


def animate(
    ds,
    path: Path | str,
    *,
    run: int = 0,
    fps: float = 15.0,
    speedup: float | None = None,
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
    fps : frames per second of the animation (at most 50 for a GIF).
    speedup : simulated seconds per second of animation; default the one that shows
        the window in at most `TARGET_LENGTH` seconds (`auto_speedup`).
    start, end : simulated time window, s; default the whole recording.
    dpi, size : resolution and figure size (inches); pixels = size·dpi, at most
        `MAX_SIDE` a side.
    progress : show a progress bar; default when stderr is a terminal.

    Returns
    -------
    The number of frames written.
    """
    import sys

    path = Path(path)
    recorded = RecordedRun.from_dataset(ds, run)
    start, end = recorded.window(start, end)
    speedup, count, budget = plan(start, end, fps=fps, speedup=speedup, dpi=dpi, size=size,
                                  path=path)  # fmt: skip
    budget.check()
    times = frame_times(start, end, fps, speedup)
    view = (BoardView if recorded.platform == "board" else DiskView)(recorded, start, end,
                                                                      size=size)  # fmt: skip
    width, height = frame_pixels(dpi, size)
    show = sys.stderr.isatty() if progress is None else progress
    with progress_bar(total=times.size, unit="frame", enabled=show, desc="animate") as bar:
        # The writers pick the format from the file name, so the temporary one keeps it.
        with atomic_path(path, keep_suffix=True) as tmp:
            with open_sink(tmp, fps, width, height) as sink:
                for t in times:
                    interrupts.check()
                    frame = view.render(float(t), dpi)
                    if frame.size != (width, height):  # pragma: no cover - a guard
                        raise RuntimeError(f"frame {frame.size} is not {width} x {height}")
                    sink.add(frame)
                    bar.update(1)
    return int(times.size)

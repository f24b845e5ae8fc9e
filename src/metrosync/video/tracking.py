"""`track`: a video of metronomes → angles, passes, phases and r(t), as an `xarray.Dataset`.

Contract: ``track(path, *, count=None, regions=None, ...)`` opens the video (`reader`),
finds the metronomes in its first seconds (`detection`, or the regions given), measures
every rod's angle in every frame (`angles`), and times the upward passes through the
vertical to measure as the light gate does (`metrosync.observables.crossings`). The
dataset has the light-gate analysis's variables and conventions (a ``log`` dimension of
one, the video), so that the same plots and tools read it:

    r, r_runs                (time), (log, time)     Kuramoto order parameter
    frequency_bpm, frequency_bpm_runs   (metronome), (log, metronome)   ticks per minute
    period_jitter, passes_kept, passes_bridged   (log, metronome)
    asymmetry                (metronome)   tick/tock asymmetry, %
    amplitude                (metronome, swing)    half the peak-to-peak angle, rad
    crossing_time            (metronome, swing)    upward passes, s (NaN padded)
    angle, angle_quality, angle_confidence   (frame, metronome)   per frame
    frame_time               (frame)       the container's presentation times, s
    pivot_x, pivot_y, vertical   (metronome)   the pivot (pixels of the video as
                                  shown) and the picture direction taken as the
                                  vertical (rad from the picture's up, clockwise)
    sector_half_width, rod_inner, rod_outer   (metronome)   the region searched
    first_frame              (y, x)        the first picture as analysed, for the preview

and attrs ``r_eq``, ``sigma_bpm``, ``z`` (two metronomes: +1 in phase, −1 anti-phase;
NaN, with ``z_note`` saying why, when it cannot be measured), the video's facts, the
options (``readout`` with ``readout_source`` and ``readout_error``, NaN unless
estimated), what was lost, and the sound's check (``sound``, ``sound_latency``,
``sound_agrees``: 1, 0, or −1 without sound). Angles are about the vertical,
positive clockwise as seen, corrected for a camera turned ``view_angle`` degrees off
square (the horizontal is foreshortened by cos(view_angle)).

The vertical is the middle of the swing: the angle seen midway in time between two
turns (`swing_middle_in_time`), since metronomes swing symmetrically about it and the
perspective changes angles but not the times of the turns; ``vertical="picture"``
takes the picture's up direction instead (a camera held level and square-on, a
metronome out of beat: only then is the tick/tock asymmetry measured, since the middle
of the swing makes it zero by construction).

Before any frame is decoded, what the options and the header decide is checked: the
regions against the picture, ``grid_dt`` and ``equilibrium_window`` against the
length, and the memory of the whole request (`metrosync.video.budget`); the memory is
checked again once the metronomes are counted, and the time once the first frames
were tracked, from the rate measured on them.
"""

from __future__ import annotations

import math
import time as clock
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import xarray as xr

from .. import interrupts
from .._words import plural
from ..budget import format_seconds
from ..errors import ParameterError
from ..observables import crossings as ph
from . import detection
from .angles import RodGauge, finish, swing_middle_in_time
from .budget import tracking_budget
from .dataset import tracking_dataset
from .reader import DEFAULT_MAX_SIDE, open_video
from .regions import check_in_frame
from .shutter import estimate_readout, readout_verdict

__all__ = ["estimate_readout", "track"]

#: Seconds at the start used to find the metronomes, and the most pictures kept for it.
LEARN_SECONDS, LEARN_PICTURES = 6.0, 120
#: The time a frame takes to track is measured over at least this many frames and this
#: many seconds, after the first `WARM_UP_FRAMES` (which pay for the decoder's start).
CALIBRATION_FRAMES, CALIBRATION_SECONDS, WARM_UP_FRAMES = 32, 0.5, 4
#: Without a progress bar, the estimate of what is left is said again this often, s.
REPORT_EVERY = 60.0


def track(
    path: str | Path,
    *,
    count: int | None = None,
    regions: list[tuple[float, ...]] | None = None,
    max_side: int = DEFAULT_MAX_SIDE,
    view_angle: float = 0.0,
    vertical: str = "swing",
    readout: float | None = None,
    learn: float = LEARN_SECONDS,
    grid_dt: float = 0.1,
    equilibrium_window: float | None = None,
    max_gap: int = 3,
    progress: bool = False,
    sound: bool = True,
    report: Callable[[str], None] | None = None,
) -> xr.Dataset:
    """Track the metronomes in a video.

    Parameters
    ----------
    path : MP4, MOV, MKV or AVI file.
    count : the number of metronomes; default: as many as found.
    regions : metronomes given by hand, in the pixels of the video as shown (upright,
        full size): ``(x, y)`` a pivot, ``(x0, y0, x1, y1)`` a box around one swing
        (see `metrosync.video.regions`); default: found.
    max_side : longest side of the pictures analysed, pixels.
    view_angle : degrees between the camera's axis and the square-on direction, turned
        about the vertical; the measured angles are corrected for it.
    vertical : ``"swing"`` (the middle of the swing) or ``"picture"`` (straight up).
    readout : the rolling shutter's readout time, s (the time from the picture's first
        row to its last); each measurement is dated at its rod's row. 0: a global
        shutter; default: estimated from the rods' skew (`estimate_readout`).
    learn : seconds at the start used to find the metronomes.
    grid_dt : spacing of the r(t) grid, s.
    equilibrium_window : seconds at the end averaged for ``r_eq``; default a quarter.
    max_gap : longest run of frames without a clear rod that is interpolated.
    sound : when the video has an audio track, time its ticks against the passes
        (`metrosync.video.sound`); attrs ``sound`` and ``sound_latency``.
    progress : show a progress bar.
    report : called with a line that says what the header states, before any frame is
        decoded, then with one that says how long the frames left should take, measured
        on the first ones tracked (and again every `REPORT_EVERY` s without ``progress``).

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    _check(count, regions, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap,
           equilibrium_window)  # fmt: skip
    video = open_video(path)
    _check_against(video, regions, grid_dt, equilibrium_window)

    def plan(metronomes: int, **measured) -> None:
        options = dict(max_side=max_side, learn=learn, grid_dt=grid_dt)
        budget = tracking_budget(video, metronomes=metronomes, most_pictures=LEARN_PICTURES,
                                 **options, **measured)  # fmt: skip
        budget.check()

    # before a frame is decoded: what the options and the header alone make too large
    plan(count or (len(regions) if regions is not None else 1))
    started = clock.perf_counter()
    if report is not None:
        report(_facts(video, learn))
    pictures = _learning_pictures(video, max_side, learn)
    if pictures.shape[0] < 3:
        raise detection.DetectionError(
            f"{str(video.path)!r} holds {plural(pictures.shape[0], 'frame')} in its first "
            f"{learn:g} s: too few to see anything swing; film at least ten seconds."
        )
    # the pictures analysed are smaller than the video: given regions are scaled
    scale = pictures.shape[2] / video.upright_size[0]
    if regions is not None:
        scaled = [tuple(v * scale for v in given) for given in regions]
        found = detection.regions_given(scaled, pictures, scale=scale)
    else:
        found = detection.find_metronomes(pictures, count=count)
    bg, _ = detection.background(pictures)
    first = pictures[0].astype(np.uint8)
    del pictures
    n = len(found)
    plan(n)
    gauges = [RodGauge(region, bg) for region in found]

    def measured(per_frame: float, done: int, left: int) -> str:
        plan(n, seconds_per_frame=per_frame, frames=done + left, frames_done=done)
        then = ", then the sound" if sound and video.has_audio else ""
        return (f"{video.path.name}: tracking {plural(n, 'metronome')} at {per_frame * 1e3:.3g} "
                f"ms a frame, measured on the first {plural(done, 'frame')}: expect about "
                f"{_about(per_frame * left)} more for the other {left}{then}")  # fmt: skip

    times, raw, strength, skew = _measure(video, gauges, max_side, progress, measured, report)
    if video.loss:
        warnings.warn(f"{video.path}: {video.loss}.", UserWarning, stacklevel=2)
    if times.size < 4:
        raise detection.DetectionError(
            f"{str(video.path)!r} gave {plural(times.size, 'frame')}: too few to time a swing."
        )
    # the frames and the length read, which the header may not have known
    plan(n, frames=times.size, length=float(times[-1] - times[0]))
    angle = np.empty_like(raw)
    quality = np.empty(raw.shape, dtype=np.int8)
    confidence = np.empty_like(raw)
    upright = np.empty(n)
    seen_from_up = np.empty_like(raw)
    for j in range(n):
        angle[:, j], quality[:, j], confidence[:, j] = finish(raw[:, j], strength[:, j], times,
                                                              max_gap=max_gap)  # fmt: skip
        ok = np.isfinite(angle[:, j])
        seen_from_up[:, j] = angle[:, j]
        if vertical == "swing" and ok.any():
            upright[j] = swing_middle_in_time(times, angle[:, j])
        else:
            upright[j] = 0.0
        seen = angle[:, j] - upright[j]
        angle[:, j] = np.arctan(np.tan(seen) / math.cos(math.radians(view_angle)))
    # Each row of a rolling-shutter picture is taken later than the one above it.
    source, error = "given", float("nan")
    if readout is None:
        estimate = estimate_readout(video, gauges, bg.shape, times, seen_from_up, quality, skew)
        readout, error, source = readout_verdict(*estimate, float(np.median(np.diff(times))))
    shift = np.array([readout * video.stored_row(*gauge.point, bg.shape) for gauge in gauges])
    ds = tracking_dataset(video, found, times, angle, quality, confidence, upright, shift,
                    first=first, scale=scale,
                    grid_dt=grid_dt, equilibrium_window=equilibrium_window,
                    options=dict(max_side=max_side, view_angle=view_angle, vertical=vertical,
                                 readout=readout, readout_source=source,
                                 readout_error=error, learn=learn,
                                 max_gap=max_gap,
                                 count=-1 if count is None else count,
                                 regions_given=int(regions is not None)),
                    seconds=clock.perf_counter() - started)  # fmt: skip
    ds.attrs.update(sound="", sound_latency=float("nan"), sound_agrees=-1)
    if sound and video.has_audio:
        _add_sound(ds, video)
    return ds


def _add_sound(ds: xr.Dataset, video) -> None:
    """The audio track against the passes, in attrs (a warning when it cannot be used)."""
    from ..errors import MetrosyncError
    from .sound import sound_check

    passes = []
    for j in range(ds.sizes["metronome"]):
        t = ds.frame_time.values
        a = ds.angle.values[:, j]
        passes += [ph.zero_crossings(t, a), ph.zero_crossings(t, a, upward=False)]
    try:
        check = sound_check(video.path, passes)
    except MetrosyncError as error:
        # the error names the video's sound track; the picture's measurements stand
        warnings.warn(f"{str(error).rstrip('.')}; the sound was not used.", UserWarning,
                      stacklevel=3)  # fmt: skip
        return
    ds.attrs.update(sound=check.sentence(), sound_latency=check.latency,
                    sound_agrees=int(check.agree))  # fmt: skip


def _learning_pictures(video, max_side: int, learn: float) -> np.ndarray:
    """Up to `LEARN_PICTURES` pictures spread over the first ``learn`` seconds."""
    every = max(1, int(round(learn * max(video.nominal_fps, 1.0) / LEARN_PICTURES)))
    kept = [p for i, (_, p) in enumerate(video.frames(max_side=max_side, stop=learn))
            if i % every == 0]  # fmt: skip
    if not kept:
        return np.empty((0, 1, 1), dtype=np.float32)
    return np.stack(kept).astype(np.float32)


def _facts(video, learn: float) -> str:
    """What the header says the video holds, before any of it is decoded."""
    w, h = video.upright_size
    length = f"{video.duration:.1f} s" if math.isfinite(video.duration) else "unknown length"
    frames = video.frames_estimate
    count = f"about {plural(frames, 'frame')}" if frames else "frames uncounted"
    return (f"{video.path.name}: {w}x{h} {video.codec}, {length}, {count} at "
            f"{video.nominal_fps:.4g} fps nominal; finding the metronomes in the first "
            f"{learn:g} s")  # fmt: skip


def _about(seconds: float) -> str:
    """A duration in words: to a tenth of a second below 10 s, where whole seconds would
    round a short clip's work to nothing."""
    if seconds < 0.1:
        return "under 0.1 s"
    return f"{seconds:.1f} s" if seconds < 10 else format_seconds(seconds)


def _measure(video, gauges, max_side: int, progress: bool, measured, report):
    """Every frame's angle, strength and skew per gauge, with their frame times.

    Once the first frames are done (`CALIBRATION_FRAMES` and `CALIBRATION_SECONDS` after
    `WARM_UP_FRAMES`), the time a frame takes is measured and ``measured(per_frame, done,
    left)`` gives the line to ``report``: the work left is that rate times the frames
    left, counted from the video's length and the frame times read so far (a file may
    state a nominal rate its frames do not keep). Without a progress bar the line is
    given again every `REPORT_EVERY` s, from the rate measured so far.
    """
    from ..progress import progress_bar

    times: list[float] = []
    angles, strengths, skews = [], [], []
    level = None

    def take(t: float, picture: np.ndarray) -> None:
        nonlocal level
        small = float(picture[::8, ::8].mean())
        level = small if level is None else level
        gain = level / (small + 1e-6)
        row = [g.measure(picture, gain) for g in gauges]
        times.append(t)
        angles.append([a for a, _, _ in row])
        strengths.append([s for _, s, _ in row])
        skews.append([k for _, _, k in row])
        if len(times) % 256 == 0:
            interrupts.check()

    def left() -> int:
        if math.isfinite(video.duration) and len(times) > 1 and times[-1] > times[0]:
            interval = (times[-1] - times[0]) / (len(times) - 1)
            return max(int(round((video.duration - times[-1]) / interval)), 0)
        return max(video.frames_estimate - len(times), 0)

    def rate() -> float:
        return (clock.perf_counter() - warm) / max(len(times) - WARM_UP_FRAMES, 1)

    # the first frames without a bar: the line that follows them would break it
    frames = video.frames(max_side=max_side)
    warm = clock.perf_counter()
    calibrated = False
    try:
        for t, picture in frames:
            take(t, picture)
            if len(times) == WARM_UP_FRAMES:
                warm = clock.perf_counter()
            if (len(times) >= WARM_UP_FRAMES + CALIBRATION_FRAMES
                    and clock.perf_counter() - warm >= CALIBRATION_SECONDS):  # fmt: skip
                calibrated = True
                break
        if calibrated:
            line = measured(rate(), len(times), left())
            if report is not None:
                report(line)
            said = clock.perf_counter()
            again = not progress and report is not None
            with progress_bar(total=(len(times) + left()) or None, unit="frame",
                              enabled=progress, desc="tracking") as bar:  # fmt: skip
                bar.update(len(times))
                for t, picture in frames:
                    take(t, picture)
                    bar.update(1)
                    if again and clock.perf_counter() - said > REPORT_EVERY:
                        report(f"{video.path.name}: {plural(len(times), 'frame')} tracked, "
                               f"about {_about(rate() * left())} left")  # fmt: skip
                        said = clock.perf_counter()
    finally:
        frames.close()  # the file, now, also when a check or Ctrl-C stopped the work
    n = len(gauges)
    return (np.array(times), np.array(angles).reshape(-1, n),
            np.array(strengths).reshape(-1, n), np.array(skews).reshape(-1, n))  # fmt: skip


def _check_against(video, regions, grid_dt: float, equilibrium_window: float | None) -> None:
    """Refuse, once the video is open and before a frame is decoded, what its picture
    and length cannot give: regions outside the picture, a grid or a window too long."""
    if regions is not None:
        check_in_frame(regions, video.upright_size)
    if not math.isfinite(video.duration) or 0 < video.frames_estimate < 3:
        # unknown, or too short to see a swing at all (which the first frames say next,
        # and is what to mend): what the frames give is checked once they are read
        return
    name = video.path.name
    # two points k·dt, (k+1)·dt both inside the passes' span, which starts after 0 and
    # ends by the video's end, need dt below half its length
    if grid_dt > video.duration / 2:
        raise ParameterError(
            f"`grid_dt` {grid_dt:g} s is longer than half of {name} ({video.duration:.1f} s), "
            f"so the r(t) grid would have fewer than two points in it; give at most "
            f"{video.duration / 2:.3g} s (the default is 0.1 s)."
        )
    if equilibrium_window is not None and equilibrium_window >= video.duration:
        raise ParameterError(
            f"`equilibrium_window` {equilibrium_window:g} s is not shorter than {name} "
            f"({video.duration:.1f} s): r_eq averages r(t) over the last seconds of the span "
            f"the metronomes share, inside the video; give less, or leave it out (the last "
            f"quarter)."
        )


def _check(count, regions, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap,
           equilibrium_window):  # fmt: skip
    if count is not None and (isinstance(count, bool) or not isinstance(count, int | np.integer)
                              or not 1 <= count <= 64):  # fmt: skip
        raise ParameterError(f"`count` must be a whole number in 1..64, got {count!r}.")
    if regions is not None and len(regions) == 0:
        raise ParameterError("`regions` is empty: give at least one pivot or box, or leave it out.")
    if count is not None and regions is not None and count != len(regions):
        raise ParameterError(
            f"`count` {count} differs from the {len(regions)} regions given; leave one out."
        )
    if not (isinstance(max_side, int | np.integer) and 64 <= max_side <= 8192):
        raise ParameterError(f"`max_side` must be pixels in 64..8192, got {max_side!r}.")
    if not (math.isfinite(view_angle) and 0 <= view_angle < 80):
        raise ParameterError(
            f"`view_angle` must be degrees in [0, 80), got {view_angle!r}; beyond that the "
            f"swing is seen edge on."
        )
    if vertical not in ("swing", "picture"):
        raise ParameterError(f"`vertical` must be 'swing' or 'picture', got {vertical!r}.")
    if readout is not None and not (math.isfinite(readout) and 0 <= readout < 1):
        raise ParameterError(f"`readout` must be a time in [0, 1) s, got {readout!r}.")
    if not (math.isfinite(learn) and 1 <= learn <= 120):
        raise ParameterError(f"`learn` must be seconds in 1..120, got {learn!r}.")
    if not (math.isfinite(grid_dt) and grid_dt > 0):
        raise ParameterError(f"`grid_dt` must be a time > 0 s, got {grid_dt!r}.")
    if equilibrium_window is not None and not (
        math.isfinite(equilibrium_window) and equilibrium_window > 0
    ):
        raise ParameterError(
            f"`equilibrium_window` must be a time > 0 s, or None for the last quarter, got "
            f"{equilibrium_window!r}."
        )
    if not (isinstance(max_gap, int | np.integer) and 0 <= max_gap <= 100):
        raise ParameterError(f"`max_gap` must be a whole number of frames in 0..100, "
                             f"got {max_gap!r}.")  # fmt: skip

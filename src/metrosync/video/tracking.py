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

and attrs ``r_eq``, ``sigma_bpm``, ``z`` (two metronomes: +1 in phase, −1 anti-phase),
the video's facts, the options, what was lost, and the sound's check (``sound``,
``sound_latency``, ``sound_agrees``: 1, 0, or −1 without sound). Angles are about the vertical,
positive clockwise as seen, corrected for a camera turned ``view_angle`` degrees off
square (the horizontal is foreshortened by cos(view_angle)).

The vertical is the middle of the swing: the angle seen midway in time between two
turns (`swing_middle_in_time`), since metronomes swing symmetrically about it and the
perspective changes angles but not the times of the turns; ``vertical="picture"``
takes the picture's up direction instead (a camera held level and square-on, a
metronome out of beat: only then is the tick/tock asymmetry measured, since the middle
of the swing makes it zero by construction).
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
from ..errors import ParameterError
from ..observables import crossings as ph
from . import detection
from .angles import MEASURED, RodGauge, finish, swing_middle_in_time
from .dataset import tracking_dataset
from .reader import DEFAULT_MAX_SIDE, open_video

#: Seconds at the start used to find the metronomes, and the most pictures kept for it.
LEARN_SECONDS, LEARN_PICTURES = 6.0, 120


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
    report : called with a line that says what will be done and how long it should take,
        before the long part (a huge file is announced before it is read).

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    _check(count, regions, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap)
    video = open_video(path)
    started = clock.perf_counter()
    pictures = _learning_pictures(video, max_side, learn)
    if report is not None:
        report(_estimate(video, pictures.shape[0], clock.perf_counter() - started, learn))
    if pictures.shape[0] < 3:
        raise detection.DetectionError(
            f"{str(video.path)!r} holds {plural(pictures.shape[0], 'frame')} in its first "
            f"{learn:g} s: too few to see anything swing; film at least ten seconds."
        )
    # the pictures analysed are smaller than the video: given regions are scaled
    scale = pictures.shape[2] / video.upright_size[0]
    if regions is not None:
        scaled = [tuple(v * scale for v in given) for given in regions]
        found = detection.regions_given(scaled, pictures)
    else:
        found = detection.find_metronomes(pictures, count=count)
    bg, _ = detection.background(pictures)
    first = pictures[0].astype(np.uint8)
    del pictures
    gauges = [RodGauge(region, bg) for region in found]
    times, raw, strength, skew = _measure(video, gauges, max_side, progress)
    if video.loss:
        warnings.warn(f"{video.path}: {video.loss}.", UserWarning, stacklevel=2)
    if times.size < 4:
        raise detection.DetectionError(
            f"{str(video.path)!r} gave {plural(times.size, 'frame')}: too few to time a swing."
        )
    n = len(found)
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
    source = "given"
    if readout is None:
        readout, error = estimate_readout(video, gauges, bg.shape, times, seen_from_up,
                                          quality, skew)  # fmt: skip
        source = (
            f"estimated from the rods' skew, ± {error * 1e3:.1f} ms"
            if math.isfinite(error)
            else "not measurable from the rods (too few frames); taken as 0"
        )
    shift = np.array([readout * video.stored_row(*gauge.point, bg.shape) for gauge in gauges])
    ds = tracking_dataset(video, found, times, angle, quality, confidence, upright, shift,
                    first=first, scale=scale,
                    grid_dt=grid_dt, equilibrium_window=equilibrium_window,
                    options=dict(max_side=max_side, view_angle=view_angle, vertical=vertical,
                                 readout=readout, readout_source=source, learn=learn,
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
        warnings.warn(f"{video.path}: the sound was not used: {error}", UserWarning,
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


def _estimate(video, learned: int, seconds: float, learn: float) -> str:
    """What the tracking will read, and about how long it will take."""
    w, h = video.upright_size
    length = f"{video.duration:.1f} s" if math.isfinite(video.duration) else "unknown length"
    frames = video.frames_estimate
    line = (f"{video.path.name}: {w}x{h} {video.codec}, {length}, about {plural(frames, 'frame')} "
            f"at {video.nominal_fps:.4g} fps nominal")  # fmt: skip
    decoded = min(learn, video.duration if math.isfinite(video.duration) else learn)
    if frames and learned and seconds > 0 and decoded > 0:
        # the first pass decoded `decoded` seconds; measuring costs about as much again
        per_frame = 1.5 * seconds / max(decoded * max(video.nominal_fps, 1.0), 1.0)
        line += f"; expect about {_duration(per_frame * frames)} of work"
    return line


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _measure(video, gauges, max_side: int, progress: bool):
    from ..progress import progress_bar

    times, angles, strengths, skews = [], [], [], []
    level = None
    with progress_bar(total=video.frames_estimate or None, unit="frame", enabled=progress,
                      desc="tracking") as bar:  # fmt: skip
        for t, picture in video.frames(max_side=max_side):
            small = float(picture[::8, ::8].mean())
            level = small if level is None else level
            gain = level / (small + 1e-6)
            row = [g.measure(picture, gain) for g in gauges]
            times.append(t)
            angles.append([a for a, _, _ in row])
            strengths.append([s for _, s, _ in row])
            skews.append([k for _, _, k in row])
            bar.update(1)
            if len(times) % 256 == 0:
                interrupts.check()
    n = len(gauges)
    return (np.array(times), np.array(angles).reshape(-1, n),
            np.array(strengths).reshape(-1, n), np.array(skews).reshape(-1, n))  # fmt: skip


def estimate_readout(video, gauges, shape, times, seen, quality, skew) -> tuple[float, float]:
    """The rolling shutter's readout time from the rods' skew, and its standard error, s.

    A rolling shutter exposes a rod's outer half at another moment than its inner half,
    so a rod turning at ω looks bent by ω · readout · (their rows' difference as a
    fraction of the stored picture). The skew of every measured frame (`RodGauge`)
    against ω times that difference, less each metronome's mean (a rod drawn slightly
    bent), gives the readout by least squares; within 0..50 ms.
    """
    xs, ys = [], []
    for j, gauge in enumerate(gauges):
        good = (quality[:, j] == MEASURED) & np.isfinite(skew[:, j])
        if good.sum() < 20:
            continue
        phi = seen[:, j]
        omega = np.gradient(np.where(np.isfinite(phi), phi, 0.0), times)
        px, py = gauge.region.pivot
        rows = [video.stored_row(px + r * np.sin(phi), py - r * np.cos(phi), shape)
                for r in (gauge.radius_outer, gauge.radius_inner)]  # fmt: skip
        x = (omega * (rows[0] - rows[1]))[good]
        y = skew[good, j]
        keep = np.abs(y - np.median(y)) <= 5 * 1.4826 * np.median(np.abs(y - np.median(y))) + 1e-9
        xs.append(x[keep] - x[keep].mean())
        ys.append(y[keep] - y[keep].mean())
    if not xs:
        return 0.0, float("nan")
    x, y = np.concatenate(xs), np.concatenate(ys)
    sxx = float(np.dot(x, x))
    if sxx <= 0 or x.size < 20:
        return 0.0, float("nan")
    slope = float(np.dot(x, y) / sxx)
    residual = y - slope * x
    error = float(np.sqrt(np.dot(residual, residual) / (x.size - 1) / sxx))
    return float(np.clip(slope, 0.0, 0.05)), error


def _check(count, regions, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap):
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
    if not (isinstance(max_gap, int | np.integer) and 0 <= max_gap <= 100):
        raise ParameterError(f"`max_gap` must be a whole number of frames in 0..100, "
                             f"got {max_gap!r}.")  # fmt: skip

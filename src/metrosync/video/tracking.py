"""`track`: a video of metronomes → angles, passes, phases and r(t), as an `xarray.Dataset`.

Contract: ``track(path, *, count=None, pivots=None, ...)`` opens the video (`reader`),
finds the metronomes in its first seconds (`detection`, or the pivots given), measures
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
    pivot_x, pivot_y, vertical   (metronome)   the pivot (pixels of the analysed,
                                  upright picture) and the picture direction taken as
                                  the vertical (rad from the picture's up, clockwise)

and attrs ``r_eq``, ``sigma_bpm``, ``z`` (two metronomes: +1 in phase, −1 anti-phase),
the video's facts, the options, and what was lost. Angles are about the vertical,
positive clockwise as seen, corrected for a camera turned ``view_angle`` degrees off
square (the horizontal is foreshortened by cos(view_angle)).

The vertical is the middle of the swing (the median of (peak + trough) / 2), since
metronomes swing symmetrically about it; ``vertical="picture"`` takes the picture's up
direction instead (a camera held level, a metronome with an asymmetric swing).
"""

from __future__ import annotations

import math
import time as clock
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from .. import interrupts
from .._version import __version__
from ..errors import ParameterError
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from ..observables.zorder import z_order
from . import detection
from .angles import LOST, MEASURED, QUALITY_NAMES, RodGauge, finish, swing_middle
from .reader import DEFAULT_MAX_SIDE, open_video

#: Seconds at the start used to find the metronomes, and the most pictures kept for it.
LEARN_SECONDS, LEARN_PICTURES = 6.0, 180


def track(
    path: str | Path,
    *,
    count: int | None = None,
    pivots: list[tuple[float, float]] | None = None,
    max_side: int = DEFAULT_MAX_SIDE,
    view_angle: float = 0.0,
    vertical: str = "swing",
    readout: float = 0.0,
    learn: float = LEARN_SECONDS,
    grid_dt: float = 0.1,
    equilibrium_window: float | None = None,
    max_gap: int = 3,
    progress: bool = False,
) -> xr.Dataset:
    """Track the metronomes in a video.

    Parameters
    ----------
    path : MP4, MOV, MKV or AVI file.
    count : the number of metronomes; default: as many as found.
    pivots : pivots given by hand, (x, y) pixels of the upright picture scaled to
        ``max_side`` (the preview's pixels); default: found.
    max_side : longest side of the pictures analysed, pixels.
    view_angle : degrees between the camera's axis and the square-on direction, turned
        about the vertical; the measured angles are corrected for it.
    vertical : ``"swing"`` (the middle of the swing) or ``"picture"`` (straight up).
    readout : the rolling shutter's readout time, s (the time from the picture's first
        row to its last); each measurement is dated at its rod's row. 0: a global shutter.
    learn : seconds at the start used to find the metronomes.
    grid_dt : spacing of the r(t) grid, s.
    equilibrium_window : seconds at the end averaged for ``r_eq``; default a quarter.
    max_gap : longest run of frames without a clear rod that is interpolated.
    progress : show a progress bar.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    _check(count, pivots, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap)
    video = open_video(path)
    started = clock.perf_counter()
    pictures = _learning_pictures(video, max_side, learn)
    if pictures.shape[0] < 3:
        raise detection.DetectionError(
            f"{str(video.path)!r} holds {pictures.shape[0]} frame(s) in its first {learn:g} s: "
            f"too few to see anything swing; film at least ten seconds."
        )
    if pivots is not None:
        regions = detection.regions_from_pivots(pivots, pictures)
    else:
        regions = detection.find_metronomes(pictures, count=count)
    bg, _ = detection.background(pictures)
    del pictures
    gauges = [RodGauge(region, bg) for region in regions]
    times, raw, strength = _measure(video, gauges, max_side, progress)
    if video.loss:
        warnings.warn(f"{video.path}: {video.loss}.", UserWarning, stacklevel=2)
    if times.size < 4:
        raise detection.DetectionError(
            f"{str(video.path)!r} gave {times.size} frame(s): too few to time a swing."
        )
    height = bg.shape[0]
    n = len(regions)
    angle = np.empty_like(raw)
    quality = np.empty(raw.shape, dtype=np.int8)
    confidence = np.empty_like(raw)
    upright = np.empty(n)
    for j in range(n):
        angle[:, j], quality[:, j], confidence[:, j] = finish(raw[:, j], strength[:, j], times,
                                                              max_gap=max_gap)  # fmt: skip
        ok = np.isfinite(angle[:, j])
        upright[j] = 0.0 if vertical == "picture" or not ok.any() else swing_middle(angle[:, j])
        seen = angle[:, j] - upright[j]
        angle[:, j] = np.arctan(np.tan(seen) / math.cos(math.radians(view_angle)))
    # Each row of a rolling-shutter picture is taken later than the one above it.
    shift = np.array([readout * gauge.row / height for gauge in gauges])
    return _dataset(video, regions, times, angle, quality, confidence, upright, shift,
                    grid_dt=grid_dt, equilibrium_window=equilibrium_window,
                    options=dict(max_side=max_side, view_angle=view_angle, vertical=vertical,
                                 readout=readout, learn=learn, max_gap=max_gap,
                                 count=-1 if count is None else count,
                                 pivots_given=int(pivots is not None)),
                    seconds=clock.perf_counter() - started)  # fmt: skip


def _learning_pictures(video, max_side: int, learn: float) -> np.ndarray:
    """Up to `LEARN_PICTURES` pictures spread over the first ``learn`` seconds."""
    every = max(1, int(round(learn * max(video.nominal_fps, 1.0) / LEARN_PICTURES)))
    kept = [p.astype(np.uint8) for i, (_, p) in enumerate(video.frames(max_side=max_side,
            stop=learn)) if i % every == 0]  # fmt: skip
    if not kept:
        return np.empty((0, 1, 1), dtype=np.float32)
    return np.stack(kept).astype(np.float32)


def _measure(video, gauges, max_side: int, progress: bool):
    from ..progress import progress_bar

    times, angles, strengths = [], [], []
    level = None
    with progress_bar(total=video.frames_estimate or None, unit="frame", enabled=progress,
                      desc="tracking") as bar:  # fmt: skip
        for t, picture in video.frames(max_side=max_side):
            small = np.median(picture[::8, ::8])
            level = small if level is None else level
            gain = level / (small + 1e-6)
            row = [g.measure(picture, gain) for g in gauges]
            times.append(t)
            angles.append([a for a, _ in row])
            strengths.append([s for _, s in row])
            bar.update(1)
            if len(times) % 256 == 0:
                interrupts.check()
    n = len(gauges)
    return (np.array(times), np.array(angles).reshape(-1, n),
            np.array(strengths).reshape(-1, n))  # fmt: skip


def _dataset(
    video,
    regions,
    times,
    angle,
    quality,
    confidence,
    upright,
    shift,
    *,
    grid_dt,
    equilibrium_window,
    options,
    seconds,
) -> xr.Dataset:
    n = len(regions)
    passes, ups, downs, amps = [], [], [], []
    for j in range(n):
        t_j = times + shift[j]
        hysteresis = 0.15 * np.nanpercentile(np.abs(angle[:, j]), 90) if np.isfinite(
            angle[:, j]).any() else 0.0  # fmt: skip
        up = ph.zero_crossings(t_j, angle[:, j], hysteresis=hysteresis)
        down = ph.zero_crossings(t_j, angle[:, j], upward=False, hysteresis=hysteresis)
        ups.append(up)
        downs.append(down)
        kept, cycles = ph.passes_on_period_grid(up)
        passes.append((kept, cycles))
        amps.append(ph.swing_amplitudes(t_j, angle[:, j], kept))
    spans = [ph.channel_span(k, str(video.path), j) for j, (k, _) in enumerate(passes)]
    grid = ph.common_grid(spans, grid_dt)
    if grid.size < 2:
        raise ParameterError(
            f"the metronomes' passes share no span of two `grid_dt` ({grid_dt:g} s): the "
            f"video is too short, or a metronome was lost; film longer."
        )
    r = ph.order_on_grid(passes, grid)
    span = grid[-1] - grid[0]
    window = span / 4 if equilibrium_window is None else float(equilibrium_window)
    if not (0 < window <= span):
        raise ParameterError(
            f"`equilibrium_window` must be in (0, {span:g}] s (the span of the r(t) grid), "
            f"got {equilibrium_window!r}."
        )
    freq = np.array([ph.mean_frequency_bpm(k, c) for k, c in passes])
    jitter = np.array([ph.period_jitter(k, c) for k, c in passes])
    bridged = np.array([int(np.sum(c - 1)) for _, c in passes])
    asym = np.array([ph.beat_asymmetry(u, d) for u, d in zip(ups, downs, strict=True)])
    width = max(max(len(k) for k, _ in passes), 1)
    crossing = np.full((n, width), np.nan)
    amplitude = np.full((n, width), np.nan)
    for j, ((k, _), a) in enumerate(zip(passes, amps, strict=True)):
        crossing[j, : k.size] = k
        amplitude[j, : a.size] = a
    z = float("nan")
    if n == 2:
        z = _z(times, angle, grid[-1] - window)
    lost = (quality == LOST).mean(axis=0)
    data = {
        "r": (("time",), r, {"long_name": "Kuramoto order parameter"}),
        "r_runs": (("log", "time"), r[None], {"long_name": "Kuramoto order parameter per log"}),
        "frequency_bpm": (("metronome",), freq, {"units": "BPM", "long_name": "ticks per minute"}),
        "frequency_bpm_runs": (("log", "metronome"), freq[None],
                               {"units": "BPM", "long_name": "ticks per minute per log"}),
        "period_jitter": (("log", "metronome"), jitter[None],
                          {"units": "s", "long_name": "std of single-period intervals"}),
        "passes_kept": (("log", "metronome"), np.array([[k.size for k, _ in passes]]),
                        {"long_name": "upward passes through the vertical"}),
        "passes_bridged": (("log", "metronome"), bridged[None],
                           {"long_name": "passes missed (the rod lost) and bridged"}),
        "asymmetry": (("metronome",), asym,
                      {"units": "%", "long_name": "tick/tock asymmetry: (right half-swing - "
                                                  "left) / period"}),
        "crossing_time": (("metronome", "swing"), crossing,
                          {"units": "s", "long_name": "upward passes through the vertical"}),
        "amplitude": (("metronome", "swing"), amplitude,
                      {"units": "rad", "long_name": "half the peak-to-peak angle of the "
                                                    "swing after each upward pass"}),
        "angle": (("frame", "metronome"), angle,
                  {"units": "rad", "long_name": "rod angle from the vertical, clockwise as "
                                                "seen (NaN: lost)"}),
        "angle_quality": (("frame", "metronome"), quality, {"long_name": QUALITY_NAMES}),
        "angle_confidence": (("frame", "metronome"), confidence,
                             {"long_name": "confidence of the angle, 0..1"}),
        "frame_time": (("frame",), times,
                       {"units": "s", "long_name": "presentation time since the first frame"}),
        "frames_lost": (("metronome",), lost, {"long_name": "fraction of frames lost"}),
        "pivot_x": (("metronome",), np.array([r.pivot[0] for r in regions]),
                    {"units": "pixel", "long_name": "pivot, from the left"}),
        "pivot_y": (("metronome",), np.array([r.pivot[1] for r in regions]),
                    {"units": "pixel", "long_name": "pivot, from the top"}),
        "vertical": (("metronome",), upright,
                     {"units": "rad", "long_name": "picture direction taken as the vertical"}),
        "path": (("log",), np.array([str(video.path)]), {"long_name": "video file"}),
    }  # fmt: skip
    steps = np.diff(times)
    attrs = {
        "r_eq": float(equilibrium_order(r, grid, window)),
        "equilibrium_window": window,
        "sigma_bpm": ph.frequency_spread(freq),
        "z": z,
        "grid_dt": grid_dt,
        "instrument": "video",
        "video_codec": video.codec,
        "video_size": f"{video.upright_size[0]}x{video.upright_size[1]}",
        "video_rotation": video.rotation,
        "nominal_fps": video.nominal_fps,
        "measured_fps": float(1.0 / np.median(steps)),
        "frame_interval_spread": float(np.std(steps)),
        "frames": int(times.size),
        "loss": video.loss,
        "seconds_taken": seconds,
        "metrosync_version": __version__,
        **options,
    }
    ds = xr.Dataset(
        data,
        coords={
            "time": ("time", grid, {"units": "s", "long_name": "time since the first frame"}),
            "metronome": ("metronome", np.arange(n), {"long_name": "metronome, left to right"}),
            "log": ("log", np.arange(1), {"long_name": "video index"}),
        },
        attrs=attrs,
    )
    for name in ("angle", "angle_confidence", "angle_quality"):
        ds[name].encoding = {"zlib": True, "complevel": 1}
    return ds


def _z(times: np.ndarray, angle: np.ndarray, start: float) -> float:
    """z of two metronomes from their smoothed angles after ``start``."""
    from scipy.signal import savgol_filter

    keep = times >= start
    if keep.sum() < 16 or not np.all(np.isfinite(angle[keep])):
        return float("nan")
    t = times[keep]
    smooth = [savgol_filter(angle[keep, j], 7, 3) for j in (0, 1)]
    return z_order(t, smooth[0], smooth[1])


def _check(count, pivots, max_side, view_angle, vertical, readout, learn, grid_dt, max_gap):
    if count is not None and (isinstance(count, bool) or not isinstance(count, int | np.integer)
                              or not 1 <= count <= 64):  # fmt: skip
        raise ParameterError(f"`count` must be a whole number in 1..64, got {count!r}.")
    if pivots is not None and len(pivots) == 0:
        raise ParameterError("`pivots` is empty: give at least one (x, y), or leave it out.")
    if count is not None and pivots is not None and count != len(pivots):
        raise ParameterError(
            f"`count` {count} differs from the {len(pivots)} pivots given; leave one out."
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
    if not (math.isfinite(readout) and 0 <= readout < 1):
        raise ParameterError(f"`readout` must be a time in [0, 1) s, got {readout!r}.")
    if not (math.isfinite(learn) and 1 <= learn <= 120):
        raise ParameterError(f"`learn` must be seconds in 1..120, got {learn!r}.")
    if not (math.isfinite(grid_dt) and grid_dt > 0):
        raise ParameterError(f"`grid_dt` must be a time > 0 s, got {grid_dt!r}.")
    if not (isinstance(max_gap, int | np.integer) and 0 <= max_gap <= 100):
        raise ParameterError(f"`max_gap` must be a whole number of frames in 0..100, "
                             f"got {max_gap!r}.")  # fmt: skip


__all__ = ["MEASURED", "track"]

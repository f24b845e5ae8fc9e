"""The dataset `track` returns, from the measured angles: passes, phases, r and the rest.

Contract: `tracking_dataset` takes the per-frame angles (about the vertical), their
quality and confidence, and each metronome's time shift (the rolling shutter), times
the upward and downward passes (`metrosync.observables.crossings.zero_crossings`),
keeps the upward ones on the period grid as the light gate does, and builds the
`xarray.Dataset` described in `metrosync.video.tracking`, with the light-gate
analysis's names and conventions.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .._version import __version__
from .._words import plural
from ..errors import AnalysisError, ParameterError
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from ..observables.zorder import extrema_times, z_order
from .angles import LOST, QUALITY_NAMES

#: Frames of the smoothing filter z is measured through (a cubic over 7 frames).
SMOOTH_FRAMES = 7
#: Periods about a lost stretch in which the second rod's turns are not used for z.
GAP_MARGIN = 0.6


def tracking_dataset(
    video,
    regions,
    times,
    angle,
    quality,
    confidence,
    upright,
    shift,
    *,
    first,
    scale,
    grid_dt,
    equilibrium_window,
    options,
    seconds,
) -> xr.Dataset:
    """The dataset of `metrosync.video.tracking` (its docstring) from the measured angles."""
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
    spans = []
    for j, ((kept, _), region) in enumerate(zip(passes, regions, strict=True)):
        if kept.size < 2:
            x, y = (v / scale for v in region.pivot)
            raise AnalysisError(
                f"{video.path}: metronome {j} (pivot at {x:.0f}, {y:.0f} px) passes the vertical "
                f"{plural(kept.size, 'time')}, too few for a phase: film longer, check that "
                f"its rod is in view and swings, or give the others' pivots with `regions`."
            )
        spans.append((float(kept[0]), float(kept[-1])))
    grid = ph.common_grid(spans, grid_dt)
    if grid.size < 2:
        raise ParameterError(
            f"the metronomes' passes share no span of two `grid_dt` ({grid_dt:g} s): the "
            f"video is too short, or a metronome was lost; film longer."
        )
    r = ph.order_on_grid(passes, grid)
    window = ph.equilibrium_window(grid, equilibrium_window)
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
    z, z_note = float("nan"), "z is defined for two metronomes only"
    if n == 2:
        z, z_note = _z(times, angle, grid[-1] - window)
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
        "pivot_x": (("metronome",), np.array([r.pivot[0] / scale for r in regions]),
                    {"units": "pixel", "long_name": "pivot, from the left of the video"}),
        "pivot_y": (("metronome",), np.array([r.pivot[1] / scale for r in regions]),
                    {"units": "pixel", "long_name": "pivot, from the top of the video"}),
        "sector_half_width": (("metronome",), np.array([r.half_width for r in regions]),
                              {"units": "rad", "long_name": "half the angle swept, as seen"}),
        "rod_inner": (("metronome",), np.array([r.r_inner / scale for r in regions]),
                      {"units": "pixel", "long_name": "nearest radius the rod is seen at"}),
        "rod_outer": (("metronome",), np.array([r.r_outer / scale for r in regions]),
                      {"units": "pixel", "long_name": "farthest radius the rod is seen at"}),
        "first_frame": (("y", "x"), first,
                        {"long_name": "first frame, grey, as analysed (picture_scale of the "
                                      "video's size)"}),
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
        "z_note": z_note,
        "grid_dt": grid_dt,
        "picture_scale": scale,
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
    for name in ("angle", "angle_confidence", "angle_quality", "first_frame"):
        ds[name].encoding = {"zlib": True, "complevel": 1}
    return ds


def _z(times: np.ndarray, angle: np.ndarray, start: float) -> tuple[float, str]:
    """z of two metronomes from their smoothed angles after ``start``, and "" or, when
    z is NaN, why it could not be measured.

    times : (T,); angle : (T, 2), NaN where a rod was lost. Each stretch in which both
    rods are seen is smoothed on its own (a filter would spread a NaN over its width).
    Near a gap, the nearest turn of the first rod to a turn of the second may be the
    one lost, which would count as a whole half-period off: the second rod's turns
    within `GAP_MARGIN` periods of a gap are left out, not the whole window.
    """
    from scipy.signal import savgol_filter

    keep = times >= start
    t, a = times[keep], angle[keep]
    seen = np.all(np.isfinite(a), axis=1)
    smooth = np.full(a.shape, np.nan)
    edges = np.flatnonzero(np.diff(np.r_[0, seen.astype(np.int8), 0]))
    for lo, hi in zip(edges[::2], edges[1::2], strict=True):
        if hi - lo >= SMOOTH_FRAMES:
            smooth[lo:hi] = savgol_filter(a[lo:hi], SMOOTH_FRAMES, 3, axis=0)
    usable = np.isfinite(smooth[:, 0])
    window = f"the last {float(t[-1] - t[0]) if t.size else 0.0:.1f} s"
    if usable.sum() < 2 * SMOOTH_FRAMES:
        return float("nan"), (
            f"z not measured: both rods are seen together in {plural(int(usable.sum()), 'frame')} "
            f"of {window}, too few for a swing"
        )
    tops = extrema_times(t[usable], smooth[usable, 0])
    period = float(np.median(np.diff(tops))) if tops.size >= 2 else np.inf
    second = smooth[:, 1].copy()
    lost = t[~usable]
    if lost.size and np.isfinite(period):
        k = np.clip(np.searchsorted(lost, t), 1, lost.size)
        after = lost[np.minimum(k, lost.size - 1)]
        nearest = np.minimum(np.abs(t - lost[k - 1]), np.abs(t - after))
        second[nearest < GAP_MARGIN * period] = np.nan
    z = z_order(t, smooth[:, 0], second)
    if not np.isfinite(z):
        return float("nan"), f"z not measured: no whole swing of both rods seen in {window}"
    return z, ""

"""The dataset of a sound recording's analysis (`analysis.analyze_audio`): its variables
and what is checked of the options.

    tick_time, tick_strength, tick_rise   (tick)        onsets (s: the time of each
                                                         metronome's main impact),
                                                         loudness (dBFS), detection
                                                         curve there (dB)
    tick_channel_strength                 (tick, channel)  loudness per channel, dBFS
    tick_metronome, tick_is_tock, tick_interval, phase_difference   (tick)
                                          who ticked (−1: no metronome's), tick or tock
                                          (−1 unknown), beat to its next tick (s),
                                          phase in metronome 0's beat (rad)
    detection, threshold, level           (frame)       the detection curve and its
                                                         threshold (dB), power (dBFS)
    wave_min, wave_max                    (wave)        the waveform, for plots
    r_acoustic, r_floor, r_excess, ticks_per_beat, clusters, beat_period   (window)
    bpm, bpm_error, jitter, asymmetry, asymmetry_error, long_beat, ticks   (metronome)
    frequency_bpm, period_jitter          (metronome)   as the light gate's dataset
    r                                     (time)        as the light gate's (each
                                                         metronome's tick one way)

with ``r_eq`` and ``sigma_bpm`` (as the light gate's) and the recording's own
attributes (`recording_attrs`).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from . import detection as det
from .tempo import HINT_RANGE

#: Default refractory time, s: impacts closer than this are heard as one. The impacts of
#: one tick are grouped afterwards, from the recording's own tick structure.
REFRACTORY = 3e-3
#: Spacing of the r(t) grid, s (as the light gate's default).
GRID_DT = 0.1


def recording_attrs(recording, scan) -> dict:
    """What the dataset says of the recording itself: its file(s), format, level."""
    rate = recording.sample_rate
    return dict(
        path=str(recording.path),
        paths=list(getattr(recording, "names", ())) or [str(recording.path)],
        offsets=(np.asarray(getattr(recording, "offsets", [0])) / rate).tolist(),
        sample_rate=rate,
        channels=recording.channels,
        duration=recording.duration,
        format=f"{recording.format} {recording.subtype}",
        peak_dbfs=20 * math.log10(scan.peak),
        clipped_samples=scan.clipped,
    )


def pendulum_phases(kept: list, dt: float) -> xr.Dataset:
    """frequency_bpm, period_jitter (metronome) and r (time), as the light gate has them,
    through `observables.crossings`; the ticks of each metronome are its passes."""
    if not kept:
        return xr.Dataset(attrs={"r_eq": math.nan, "sigma_bpm": math.nan})
    freq = np.array([ph.mean_frequency_bpm(k, c) for k, c in kept])
    jitter = np.array([ph.period_jitter(k, c) for k, c in kept])
    spans = [(float(k[0]), float(k[-1])) for k, _ in kept if len(k) >= 2]
    grid = ph.common_grid(spans, dt) if len(spans) == len(kept) else np.empty(0)
    r = ph.order_on_grid(kept, grid) if grid.size else np.empty(0)
    r_eq = float(equilibrium_order(r, grid, 0.25 * (grid[-1] - grid[0]))) if grid.size else math.nan
    data = {
        "frequency_bpm": (("metronome",), freq, {"units": "BPM", "long_name": "mean frequency "
                          "(two beats per period), as the light gate's"}),
        "period_jitter": (("metronome",), jitter,
                          {"units": "s", "long_name": "std of single periods (tick to tick)"}),
        "r": (("time",), r, {"long_name": "order parameter of the pendulums from the ticks "
                             "(each metronome's tick taken as the same direction)"}),
    }  # fmt: skip
    coords = {"time": ("time", grid, {"units": "s", "long_name": "time in the recording"})}
    attrs = {"r_eq": r_eq, "sigma_bpm": ph.frequency_spread(freq)}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def check_bpm(bpm: float, heard: float) -> None:
    if abs(heard / bpm - 1) > HINT_RANGE:
        warnings.warn(
            f"the ticks sound like {heard:.1f} BPM, not near `bpm` {bpm:g}; the "
            f"analysis keeps the tempo it heard. Check the setting, or leave `bpm` out.",
            UserWarning,
            stacklevel=3,
        )


def beat_gaps(times: np.ndarray, number: np.ndarray) -> np.ndarray:
    """(K − 1,) time to the next tick where it is the next beat, else NaN."""
    gaps = np.diff(times)
    return np.where(np.diff(number) == 1, gaps, np.nan)


def check_options(bpm, metronomes, sensitivity, refractory, window, gap) -> None:
    if bpm is not None and not (math.isfinite(bpm) and 20 <= bpm <= 400):
        raise ParameterError(f"`bpm` must be a tempo in 20..400 BPM, got {bpm!r}.")
    if metronomes is not None and (
        isinstance(metronomes, bool)
        or not isinstance(metronomes, int | np.integer)
        or metronomes < 1
    ):
        raise ParameterError(f"`metronomes` must be a whole number >= 1, got {metronomes!r}.")
    if not (math.isfinite(sensitivity) and sensitivity > 0):
        raise ParameterError(f"`sensitivity` must be a number > 0, got {sensitivity!r}.")
    if refractory is not None and not (math.isfinite(refractory) and 0 < refractory < 1):
        raise ParameterError(
            f"`refractory` must be a time in (0, 1) s, got {refractory!r}; ticks closer "
            f"than it count as one."
        )
    if window is not None and not (math.isfinite(window) and window > 0):
        raise ParameterError(f"`order_window` must be a time > 0 s, got {window!r}.")
    if not (math.isfinite(gap) and 0 < gap < 0.5):
        raise ParameterError(
            f"`cluster_gap` must be a fraction of a beat in (0, 0.5), got {gap!r}."
        )


def assemble(recording, scan, ticks, acoustic, stats, label, is_tock, interval, phase):
    """The dataset's variables and coordinates (module docstring), from the analysis's
    parts."""
    rate = recording.sample_rate
    hop_s = scan.hop / rate
    chans = np.arange(recording.channels)
    data = {
        "tick_time": (("tick",), ticks.time, {"units": "s", "long_name": "tick onset"}),
        "tick_strength": (("tick",), ticks.strength,
                          {"units": "dBFS", "long_name": "tick loudness (envelope peak)"}),
        "tick_rise": (("tick",), ticks.rise,
                      {"units": "dB", "long_name": "detection curve at the tick"}),
        "tick_channel_strength": (("tick", "channel"), ticks.channel_strength,
                                  {"units": "dBFS", "long_name": "tick loudness per channel"}),
        "tick_metronome": (("tick",), label,
                           {"long_name": "metronome that ticked (-1: not told apart)"}),
        "tick_is_tock": (("tick",), is_tock,
                         {"long_name": "1 tock, 0 tick, -1 unknown (starts the other beat)"}),
        "tick_interval": (("tick",), interval,
                          {"units": "s", "long_name": "beat: time to the same metronome's "
                                                      "next tick (NaN: unknown or missed)"}),
        "phase_difference": (("tick",), phase,
                             {"units": "rad", "long_name": "tick phase of metronome 1 in "
                                                          "metronome 0's beat"}),
        "detection": (("frame",), scan.curve,
                      {"units": "dB", "long_name": "detection curve: rise of band power"}),
        "threshold": (("frame",), scan.threshold,
                      {"units": "dB", "long_name": "adaptive threshold on the curve"}),
        "level": (("frame",), scan.level, {"units": "dBFS", "long_name": "band power per hop"}),
        "wave_min": (("wave",), scan.wave_min, {"long_name": "waveform minimum (channel mix)"}),
        "wave_max": (("wave",), scan.wave_max, {"long_name": "waveform maximum (channel mix)"}),
        "r_acoustic": (("window",), acoustic.r,
                       {"long_name": "acoustic order parameter |<exp(2 pi i t/T)>|"}),
        "r_floor": (("window",), acoustic.floor,
                    {"long_name": "floor of r_acoustic for independent metronomes"}),
        "r_excess": (("window",), acoustic.excess,
                     {"long_name": "r_acoustic above its floor"}),
        "ticks_per_beat": (("window",), acoustic.ticks_per_beat,
                           {"long_name": "ticks per beat period"}),
        "clusters": (("window",), acoustic.clusters,
                     {"long_name": "distinct ticks per beat (clusters)"}),
        "beat_period": (("window",), acoustic.period,
                        {"units": "s", "long_name": "beat period in the window"}),
    }  # fmt: skip
    if stats:

        def per(name):
            return np.array([getattr(s, name) for s in stats])

        data |= {
            "bpm": (("metronome",), per("bpm"), {"units": "BPM", "long_name": "tempo"}),
            "bpm_error": (("metronome",), per("bpm_error"),
                          {"units": "BPM", "long_name": "standard error of the tempo"}),
            "jitter": (("metronome",), per("jitter"),
                       {"units": "s", "long_name": "std of beats about their kind's mean"}),
            "asymmetry": (("metronome",), per("asymmetry"),
                          {"units": "%", "long_name": "(long - short beat) / mean beat"}),
            "asymmetry_error": (("metronome",), per("asymmetry_error"),
                                {"units": "%", "long_name": "standard error of the asymmetry"}),
            "long_beat": (("metronome",), per("long_beat").astype(str),
                          {"long_name": "which beat is long"}),
            "beat_verdict": (("metronome",), np.array([s.verdict() for s in stats]),
                             {"long_name": "the beat in words"}),
            "ticks": (("metronome",), per("ticks"), {"long_name": "ticks heard"}),
            "missed_beats": (("metronome",), per("missed"), {"long_name": "beats not heard"}),
        }  # fmt: skip
    coords = {
        "tick": ("tick", np.arange(ticks.time.size), {"long_name": "tick index, in time order"}),
        "channel": ("channel", chans, {"long_name": "channel of the recording (0 = left)"}),
        "frame": ("frame", np.arange(scan.curve.size) * hop_s,
                  {"units": "s", "long_name": "start of each hop of the detection curve"}),
        "wave": ("wave", (np.arange(scan.wave_min.size) + 0.5) * hop_s * det.DISPLAY_HOPS,
                 {"units": "s", "long_name": "centre of each waveform column"}),
        "window": ("window", acoustic.time, {"units": "s", "long_name": "window centre"}),
    }  # fmt: skip
    if stats:
        coords["metronome"] = ("metronome", np.arange(len(stats)),
                               {"long_name": "metronome (0: alone, louder or left)"})  # fmt: skip
    ds = xr.Dataset(data, coords=coords)
    for name in ("detection", "threshold", "level"):
        ds[name].encoding = {"zlib": True, "complevel": 1}
    return ds

"""`analyze_audio`: a recording of metronomes → ticks, tempo, beat and synchrony.

Contract: ``analyze_audio(path, *, bpm=None, metronomes=None, ...)`` reads the file
(or files recorded together, `together`) in blocks (`reader`), finds every impact
(`detection`), groups them into ticks and tells the metronomes apart by sound and
tempo (`separation`), finds ticks another hid (`recovery`), times the ticks in
another's ring on the metronomes' learned sounds (`templates`), and measures: each
metronome's tempo, jitter and beat (`metronome`); its phases, r and frequency as the
light gate's (`observables.crossings`); the phase of each in metronome 0's beat
(`attribution`); and the acoustic order parameter and clusters of the ensemble,
which need no identities (`order`). It returns an `xarray.Dataset`:

    tick_time, tick_strength, tick_rise   (tick)        onsets (s, a tick's first
                                                         impact), loudness (dBFS),
                                                         detection curve there (dB)
    tick_channel_strength                 (tick, channel)  loudness per channel, dBFS
    tick_metronome, tick_is_tock, tick_interval, phase_difference   (tick)
                                          who ticked (−1 unknown or two at once), tick
                                          or tock (−1 unknown), beat to its next tick
                                          (s), phase in metronome 0's beat (rad)
    detection, threshold, level           (frame)       the detection curve and its
                                                         threshold (dB), power (dBFS)
    wave_min, wave_max                    (wave)        the waveform, for plots
    r_acoustic, r_floor, r_excess, ticks_per_beat, clusters, beat_period   (window)
    bpm, bpm_error, jitter, asymmetry, asymmetry_error, long_beat, ticks   (metronome)
    frequency_bpm, period_jitter          (metronome)   as the light gate's dataset
    r                                     (time)        as the light gate's (each
                                                         metronome's tick one way)

with the summary (``attrs["summary"]``), ``r_eq`` and ``sigma_bpm`` (as the light
gate's), how the metronomes were told apart and how sure (``attribution``,
``attribution_confidence``), the settings, and the tempo found.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from .._words import plural
from ..errors import AnalysisError, ParameterError
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from . import detection as det
from . import templates
from .attribution import phase_difference
from .fills import given_back
from .hidden import followers, hidden_count, hidden_trains
from .interleaved import join_interleaved
from .metronome import beat_statistics
from .order import CLUSTER_GAP, WINDOW_BEATS, acoustic_order, floor_and_excess, no_common_beat
from .reader import open_recording
from .recovery import nearer_another, recover
from .separation import separate, sureness, tick_length_words
from .subdivision import subdivided
from .summary import summary_text
from .tempo import HINT_RANGE, MIN_TICKS, beat_period
from .trains import Train, fold_parts, holders, off_the_beat

#: Default refractory time, s: impacts closer than this are heard as one. The impacts of
#: one tick are grouped afterwards, from the recording's own tick structure.
REFRACTORY = 3e-3
#: Below this attribution confidence the ensemble's beat is found from the ticks alone.
MIN_CONFIDENCE = 0.5
#: Spacing of the r(t) grid, s (as the light gate's default).
GRID_DT = 0.1


def analyze_audio(
    path: str | Path | list[str | Path],
    *,
    bpm: float | None = None,
    metronomes: int | None = None,
    band: tuple[float, float] | None = None,
    sensitivity: float = det.DEFAULT_SENSITIVITY,
    refractory: float | None = None,
    order_window: float | None = None,
    cluster_gap: float = CLUSTER_GAP,
    progress: bool = False,
) -> xr.Dataset:
    """Analyse a sound recording of one or more metronomes.

    Parameters
    ----------
    path : a WAV, FLAC, Ogg or MP3 file (see `metrosync.audio.reader`), mono or with a
        channel per microphone; or a list of files recorded together, one per
        microphone, aligned by their cross-correlation (`metrosync.audio.together`).
    bpm : the metronomes' setting, BPM; default: found from the ticks.
    metronomes : how many metronomes sound; default: the ticks per beat in the windows
        where they were least together (95th percentile), rounded.
    band : band-pass edges (Hz) of the detector, below half the sample rate; default
        `metrosync.audio.settings.DEFAULT_BAND`, its top lowered for a low sample rate.
    sensitivity : threshold above the detection curve's median, in its robust spreads.
    refractory : shortest time between two ticks, s; default 1/32 of the beat, within
        3–30 ms. Ticks closer than this are heard as one.
    order_window : window of the acoustic order parameter, s (default 16 beats).
    cluster_gap : largest gap within one cluster of ticks, fraction of a beat.
    progress : show a progress bar while reading.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    _check_options(bpm, metronomes, sensitivity, refractory, order_window, cluster_gap)
    if isinstance(path, list | tuple):
        if len(path) == 1:
            recording = open_recording(path[0])
        else:
            from .together import record_together

            recording = record_together(path, band=band)
    else:
        recording = open_recording(path)
    rate = recording.sample_rate
    from ..progress import progress_bar

    with progress_bar(total=recording.frames, unit="frame", enabled=progress,
                      desc="reading") as bar:  # fmt: skip
        scan = det.scan(recording, band=band, sensitivity=sensitivity, progress=bar)
    hop_s = scan.hop / rate
    if refractory is None:
        refractory = REFRACTORY
    hops = det.pick_ticks(scan, max(1, round(refractory / hop_s)))
    impacts = det.refine(recording, scan, hops)
    order = np.argsort(impacts.time, kind="stable")
    impacts = det.Ticks(impacts.time[order], impacts.strength[order],
                        impacts.channel_strength[order], impacts.rise[order])  # fmt: skip
    if impacts.time.size < MIN_TICKS:
        beat_period(impacts.time)  # raises the error that says what to try
    sep = separate(recording, impacts)
    heard = _median_bpm(sep)
    if bpm is not None and not (heard and abs(heard / bpm - 1) <= HINT_RANGE):
        hinted = separate(recording, impacts, bpm=bpm)
        near = _median_bpm(hinted)
        if near and abs(near / bpm - 1) <= HINT_RANGE:
            sep, heard = hinted, near
    heads = np.flatnonzero(sep.head)
    ticks = _subset(impacts, heads)
    where = np.full(impacts.time.size, -1, dtype=np.int64)
    where[heads] = np.arange(heads.size)
    trains = [_on_ticks(t, where) for t in sep.trains]
    trains = subdivided(ticks.time, trains)
    trains = join_interleaved(ticks.time, ticks.strength, trains)
    trains = given_back(ticks.time, trains)
    ticks, trains, recovered = recover(recording, scan, ticks, trains)
    settled = _settled(ticks, trains)
    if settled is not None:
        ticks, trains, more = recover(recording, scan, ticks, settled)
        recovered += more
    ticks, trains = _later_impacts_folded(ticks, trains)
    ticks, trains, likeness = _retimed(recording, scan, ticks, trains)
    trains, behind = _told_apart(ticks, trains)
    if trains and not behind:
        # the median of the metronomes' tempi; where the trains may have gone wrong (a
        # very noisy recording), from all the ticks, as without trains
        heard = float(np.median([60.0 / t.period for t in trains]))
        period, tempo_source = 60.0 / heard, "the median of the metronomes' own tempi"
        near = bpm is not None and abs(heard / bpm - 1) <= HINT_RANGE
        if sep.confidence < MIN_CONFIDENCE or near:
            try:
                period = beat_period(ticks.time, bpm if near else None)
                tempo_source = "given (bpm)" if near else "found from the ticks"
            except AnalysisError:
                pass
    else:
        # with hidden metronomes set aside, the tempo heard is the kept metronomes'
        heard = (
            float(np.median([60.0 / t.period for t in trains]))
            if trains
            else 60.0 / beat_period(ticks.time)
        )
        period = beat_period(ticks.time, bpm)
        tempo_source = "given (bpm)" if bpm is not None else "found from the ticks"
    if bpm is not None:
        _check_bpm(bpm, heard)
    span = ticks.time[-1] - ticks.time[0]
    per_beat = ticks.time.size * period / max(span + period, period)
    acoustic = acoustic_order(ticks.time, period, window=order_window, cluster_gap=cluster_gap)
    apart = no_common_beat([60.0 / t.period for t in trains], acoustic.window / period)
    if apart:
        # Nothing measured on a beat nobody keeps is kept (`no_common_beat`).
        nan = np.full(acoustic.r.shape, np.nan)
        acoustic = replace(acoustic, r=nan, ticks_per_beat=nan, clusters=nan)
        per_beat = math.nan
        tempo_source = "the median of the metronomes' own tempi; no common beat"
    # Synchronized metronomes tick as one; the windows where they were least together
    # count them best.
    heard_at_once = len(trains) if apart else np.nanpercentile(acoustic.ticks_per_beat, 95)
    busiest = max(1, round(float(heard_at_once)))
    note = sep.note
    if metronomes is not None:
        n = int(metronomes)
        source = "given"
    elif behind:
        n = len(trains) + behind["metronomes"]
        source = (f"{len(trains)} told apart by {sep.method}, " if trains else "") + (
            f"{behind['metronomes']} that could not be told apart, from their ticks per beat"
        )
    elif trains:
        n = len(trains)
        source = "one tick train" if n == 1 else f"told apart by {sep.method}"
    else:
        n = busiest
        source = "most ticks per beat in a window (95th percentile), rounded"
    if behind:
        note = ""
    elif trains and n != len(trains):
        note = (f"{plural(len(trains), 'metronome')} told apart, {n} expected"
                + (f"; {note}" if note else ""))  # fmt: skip
    elif trains and busiest > len(trains) and not apart:
        note = (f"up to {busiest} ticks per beat are heard but only "
                f"{plural(len(trains), 'metronome')} "
                f"told apart; the others sound alike and keep the same tempo")  # fmt: skip
    floor, excess = floor_and_excess(acoustic.r, n)
    acoustic = replace(acoustic, floor=floor, excess=excess)
    k = ticks.time.size
    label = nearer_another(ticks.time, trains, _labels(k, trains), likeness)
    label[templates.unlike(likeness, trains, ticks.time)] = -1  # a bump on the beat, not a tick
    is_tock = np.full(k, -1, dtype=np.int8)
    interval = np.full(k, np.nan)
    phase = np.full(k, np.nan)
    stats, kept = [], []
    for m, t in enumerate(trains):
        # a metronome's timing from its own ticks: one it took from another (that hid
        # its own) is that other's onset
        own, s = _own_statistics(ticks, t)
        stats.append(s)
        mine = label[own] == m
        is_tock[own[mine]] = s.is_tock[mine]
        gaps = np.full(own.size, np.nan)
        gaps[:-1] = _beats(ticks.time[own], s.beat_number)
        interval[own[mine]] = gaps[mine]
        kept.append(ph.kept_from_half_periods(ticks.time[own], s.beat_number,
                                              parity=1 if s.is_tock[0] else 0))  # fmt: skip
        if m > 0:
            mine = np.flatnonzero(label == m)
            phase[mine] = phase_difference(ticks.time[trains[0].index], ticks.time[mine],
                                           trains[0].period)  # fmt: skip
    wanted = WINDOW_BEATS * period if order_window is None else order_window
    if span < wanted:
        warnings.warn(
            f"the recording holds only {plural(k, 'tick')} over {span:.1f} s, less than one "
            f"window of the acoustic order parameter ({wanted:.1f} s): too short for steady "
            f"figures; record a minute or more.",
            UserWarning,
            stacklevel=2,
        )
    ds = _dataset(recording, scan, ticks, acoustic, stats, label, is_tock, interval, phase)
    pendulums = _pendulum_phases(kept, GRID_DT)
    ds = ds.merge(pendulums)
    ds.attrs.update(pendulums.attrs)
    ds.attrs.update(recording_attrs(recording, scan))
    ds.attrs.update(
        beat_period=period,
        bpm_ensemble=60.0 / period,
        tempo_source=tempo_source,
        metronomes=n,
        metronomes_source=source,
        impacts=int(impacts.time.size),
        ticks_recovered=recovered,
        tick_structure=tick_length_words(sep),
        ticks_per_beat=per_beat,
        band=list(scan.band),
        sensitivity=sensitivity,
        refractory=refractory,
        resolution=max(refractory, det.RESOLUTION),
        order_window=acoustic.window,
        order_step=acoustic.step,
        cluster_gap=cluster_gap,
        attribution=sep.method if len(trains) > 1 else "none",
        attribution_confidence=sep.confidence if trains else 0.0,
        attribution_sureness=sureness(sep.confidence) if trains else "",
        attribution_note=note,
        metronomes_hidden=behind["metronomes"] if behind else 0,
        no_common_beat=apart,
        metrosync_version=__version__,
    )
    if behind:
        ds.attrs.update(
            hidden_bpm=behind["bpm"],
            hidden_clusters=behind["clusters"],
            hidden_ticks_per_beat=behind["per_beat"],
            hidden_r_acoustic=behind["r"],
            hidden_note=(
                f"{behind['metronomes']} metronomes could not be told apart: they tick "
                f"together at about {behind['bpm']:.1f} BPM, one hidden behind another "
                f"most of the time; only what needs no identities is reported for them: "
                f"{behind['per_beat']:.2f} ticks per beat heard in "
                f"{behind['clusters']:.1f} distinct ticks per beat, acoustic R "
                f"{behind['r']:.3f} (their {plural(behind['ticks'], 'tick')})"
            ),
        )
    ds.attrs["summary"] = summary_text(ds)
    return ds


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


def _settled(ticks, trains: list[Train]) -> list[Train] | None:
    """The trains recovery left, looked at again once it has put other metronomes'
    ticks off their beats, or None where nothing changes; then to be recovered again:
    - a slow train is divided where the ticks between are free only now (corpus seed
      4/346: its tocks fell 2-25 ms from another metronome's ticks all along, at 3:2;
      that metronome's train held them until recovery put them off its beat, and the
      slow metronome was heard at half its tempo);
    - a train that follows a metronome told apart every few beats (`hidden.followers`)
      is dropped, and its ticks on that metronome's beats left to it (corpus seed 4/363:
      a fifth metronome of four, of a quarter of one's tempo and a jitter of 27 ms)."""
    out = subdivided(ticks.time, trains)
    divided = any(d.period != t.period for d, t in zip(out, trains, strict=True))
    jitters = [_own_statistics(ticks, t)[1].jitter for t in out]
    periods = [t.period for t in out]
    echoes = set(followers(periods, jitters)) - set(hidden_trains(periods, jitters))
    if not divided and not echoes:
        return None
    return [t for i, t in enumerate(out) if i not in echoes]


def _own_statistics(ticks, train: Train):
    """(own tick indices, `BeatStatistics`) of a metronome from its own ticks: one it
    took from another (that hid its own) is that other's onset."""
    own = train.index[~train.masked]
    own = own[~off_the_beat(ticks.time[own], train.beat[~train.masked])]
    return own, beat_statistics(ticks.time[own], train.period, ticks.strength[own])


def _told_apart(ticks, trains: list[Train]) -> tuple[list[Train], dict]:
    """(the trains of metronomes told apart, what is known of those that could not be:
    {} when none) (`hidden`)."""
    if len(trains) < 2:
        return trains, {}
    jitters = [_own_statistics(ticks, t)[1].jitter for t in trains]
    gone = hidden_trains([t.period for t in trains], jitters)
    if not gone:
        return trains, {}
    kept = [t for i, t in enumerate(trains) if i not in gone]
    held = np.zeros(ticks.time.size, dtype=bool)
    for t in kept:
        held[t.index] = True
    rest = ticks.time[~held]
    span = ticks.time[-1] - ticks.time[0]
    count, period, per_beat = hidden_count(rest, span, len(gone))
    r = clusters = math.nan
    if np.isfinite(period):
        order = acoustic_order(rest, period)
        r = float(np.nanmedian(order.r))
        clusters = float(np.nanmedian(order.clusters))
    behind = {"metronomes": count, "bpm": 60.0 / period, "clusters": clusters, "r": r,
              "ticks": int(rest.size), "per_beat": per_beat}  # fmt: skip
    return kept, behind


def _subset(ticks: det.Ticks, which: np.ndarray) -> det.Ticks:
    """The ticks ``which`` (indices or a mask) selects, every field alike."""
    return det.Ticks(*(getattr(ticks, f)[which] for f in det.Ticks.__dataclass_fields__))


def _later_impacts_folded(ticks, trains: list[Train]):
    """(ticks, trains) less each train of another's later impacts (`trains.fold_parts`)
    that only shows as one once recovery has completed the train it follows (pieces
    of it, at a quarter of the tempo, were joined after the parts were folded): its
    ticks are not ticks."""
    kept, _, folded = fold_parts(ticks.time, trains, [0] * len(trains), ticks.strength)
    if not folded:
        return ticks, trains
    keep = np.ones(ticks.time.size, dtype=bool)
    keep[np.concatenate(folded)] = False
    for t in kept:
        keep[t.index] = True  # a tick a metronome holds stays
    where = np.cumsum(keep) - 1
    return _subset(ticks, keep), [replace(t, index=where[t.index]) for t in kept]


def _retimed(recording, scan, ticks, trains: list[Train]):
    """(ticks, trains, likeness (K,)) with the ticks in another metronome's ring timed on
    the sum of the metronomes' sounds (`templates`), kept in time order, and how much
    each held tick sounds like its metronome (NaN where unknown)."""
    sounds = templates.learn(recording, scan, ticks.time, trains)
    times, likeness = templates.retime(recording, scan, ticks.time, trains, sounds)
    order = np.argsort(times, kind="stable")
    likeness = likeness[order]
    fields = det.Ticks.__dataclass_fields__
    ticks = det.Ticks(*(times[order] if f == "time" else getattr(ticks, f)[order]
                        for f in fields))  # fmt: skip
    where = np.empty(order.size, dtype=np.int64)
    where[order] = np.arange(order.size)
    return ticks, [replace(t, index=where[t.index]) for t in trains], likeness


def _pendulum_phases(kept: list, dt: float) -> xr.Dataset:
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


def _labels(k: int, trains: list[Train]) -> np.ndarray:
    """(K,) the metronome of each tick: the train that holds it as its own
    (`trains.holders`; −1: none, or two trains share it, their ticks fell together)."""
    return holders(k, trains).astype(np.int8)


def _on_ticks(train: Train, where: np.ndarray) -> Train:
    """The train with indices into the ticks instead of the impacts."""
    return replace(train, index=where[train.index])


def _median_bpm(sep) -> float:
    """The median of the metronomes' tempi, BPM (0 when none was found)."""
    return float(np.median([60.0 / t.period for t in sep.trains])) if sep.trains else 0.0


def _check_bpm(bpm: float, heard: float) -> None:
    if abs(heard / bpm - 1) > HINT_RANGE:
        warnings.warn(
            f"the ticks sound like {heard:.1f} BPM, not near `bpm` {bpm:g}; the "
            f"analysis keeps the tempo it heard. Check the setting, or leave `bpm` out.",
            UserWarning,
            stacklevel=3,
        )


def _beats(times: np.ndarray, number: np.ndarray) -> np.ndarray:
    """(K − 1,) time to the next tick where it is the next beat, else NaN."""
    gaps = np.diff(times)
    return np.where(np.diff(number) == 1, gaps, np.nan)


def _check_options(bpm, metronomes, sensitivity, refractory, window, gap) -> None:
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


def _dataset(recording, scan, ticks, acoustic, stats, label, is_tock, interval, phase):
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

"""`analyze_audio`: a recording of metronomes → ticks, tempo, beat and synchrony, by
the timing model (docs/sound.md, "The timing model").

``analyze_audio(path, *, bpm=None, metronomes=None, ...)`` reads the file (or files
recorded together, `together`) in blocks (`reader`) and finds every impact
(`detection`). The impacts are explained as metronomes and clutter by `decompose`:
candidate tempi by epoch folding (`periodicity`), each metronome a timing model
(`timing`, `wander`) whose tick and tock are learned from the recording, every impact
before and after the loudest (`structure`), with its sound (`sounds`); an impact heard
from elsewhere is another metronome's. The beats no onset was detected at are sought
where each metronome's timing puts them (`seek`), and each onset goes to the metronome
likeliest to have made it; every tick is then timed against its metronome's learned
waveform (`waveform`). Then it measures: each metronome's tempo, jitter and beat
(`metronome`); its phases, r and frequency as the light gate's
(`observables.crossings`); the phase of each in metronome 0's beat (`attribution`);
and the acoustic order parameter and clusters of the ensemble, which need no
identities (`order`).

It returns the `dataset` module's variables, and:

    tick_probability                      (tick)        the probability that the tick
                                                         is its metronome's
    beats_heard, explained, tick_impacts  (metronome)   share of its beats heard, the
                                                         mean probability of its ticks,
                                                         its learned tick in words

with the summary (``attrs["summary"]``), how the metronomes were told apart (by their
sound, or by their tempo and phase alone) and how sure (``attribution``,
``attribution_confidence``), the settings, the timing model's parameters
(``timing_model``, JSON of `settings.MODEL`), and the tempo found. Its ticks are the
metronomes' ticks; onsets no metronome explains (a bump, a voice) are clutter,
counted in ``attrs["tick_structure"]``, not ticks; where no metronome is found, every
onset is a tick of none (−1).
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from .._words import plural
from ..observables import crossings as ph
from . import detection as det
from .attribution import phase_difference
from .dataset import (
    GRID_DT,
    REFRACTORY,
    assemble,
    beat_gaps,
    check_bpm,
    check_options,
    pendulum_phases,
    recording_attrs,
)
from .decompose import Heard, belonging, decompose, one_tick_an_onset
from .metronome import beat_statistics
from .order import CLUSTER_GAP, WINDOW_BEATS, acoustic_order, floor_and_excess, no_common_beat
from .reader import open_recording
from .seek import seek
from .settings import MODEL
from .sounds import learn_sounds
from .structure import Structure
from .summary import summary_text
from .tempo import HINT_RANGE, MIN_TICKS, beat_period
from .voices import impact_features
from .waveform import retimed


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
    """Analyse a sound recording of one or more metronomes (module docstring).

    Parameters
    ----------
    path : a WAV, FLAC, Ogg or MP3 file (see `metrosync.audio.reader`), mono or with a
        channel per microphone; or a list of files recorded together, one per
        microphone, aligned by their cross-correlation (`metrosync.audio.together`).
    bpm : the metronomes' setting, BPM; default: found from the ticks. Where the
        metronomes heard are not near it, they are sought within ±15 % of it.
    metronomes : how many metronomes sound; default: as many as the timing model finds
        (or, where it finds none, the ticks per beat in the windows where they were
        least together, 95th percentile, rounded).
    band : band-pass edges (Hz) of the detector, below half the sample rate; default
        `metrosync.audio.settings.DEFAULT_BAND`, its top lowered for a low sample rate.
    sensitivity : threshold above the detection curve's median, in its robust spreads.
    refractory : shortest time between two impacts, s; default 3 ms. Impacts closer than
        this are heard as one.
    order_window : window of the acoustic order parameter, s (default 16 beats).
    cluster_gap : largest gap within one cluster of ticks, fraction of a beat.
    progress : show a progress bar while reading.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    check_options(bpm, metronomes, sensitivity, refractory, order_window, cluster_gap)
    recording = _open(path, band)
    rate = recording.sample_rate
    from ..progress import progress_bar

    with progress_bar(total=recording.frames, unit="frame", enabled=progress,
                      desc="reading") as bar:  # fmt: skip
        scan = det.scan(recording, band=band, sensitivity=sensitivity, progress=bar)
    refractory = REFRACTORY if refractory is None else refractory
    hops = det.pick_ticks(scan, max(1, round(refractory / (scan.hop / rate))))
    impacts = det.refine(recording, scan, hops)
    impacts = impacts.taken(np.argsort(impacts.time, kind="stable"))
    impacts = impacts.taken(det.heard_apart(impacts.time, refractory))
    if impacts.time.size < MIN_TICKS:
        beat_period(impacts.time)  # raises the error that says what to try
    sound = impact_features(recording, impacts.time).matrix()
    heard, owner = _metronomes(impacts, bpm, sound)
    by = _told_apart_by(heard, sound, impacts.time)
    if heard:
        # the beats no onset was detected at, sought where each metronome's timing puts
        # them, and every onset explained again with them
        found, whose = seek(recording, scan, impacts, heard)
        joined = impacts.joined(found)
        in_time = np.argsort(joined.time, kind="stable")
        impacts = joined.taken(in_time)
        owner = np.concatenate([owner, whose])[in_time]
        heard, owner = one_tick_an_onset(impacts.time, heard, owner)
        # each tick timed against its metronome's learned waveform, as a pulse is
        impacts = replace(impacts, time=retimed(recording, scan, impacts, heard))
    # The ticks: each metronome's main impacts; a tick's other impacts are not ticks, nor
    # is clutter (a bump, a voice). With no metronome found, every onset is a tick.
    is_tick = np.full(owner.size, not heard)
    for h in heard:
        is_tick[h.ticks] = True
    ticks = impacts.taken(is_tick)
    where = np.cumsum(is_tick) - 1
    probability = belonging(impacts.time, heard, owner)
    k = ticks.time.size
    label = np.full(k, -1, dtype=np.int8)
    tick_probability = np.full(k, np.nan)
    for m, h in enumerate(heard):
        label[where[h.ticks]] = m
        tick_probability[where[h.ticks]] = probability[m, h.ticks]
    tempi = [60.0 / _own_period(h) for h in heard]
    if tempi:
        heard_bpm = float(np.median(tempi))
        period, tempo_source = 60.0 / heard_bpm, "the median of the metronomes' own tempi"
    else:
        period = beat_period(ticks.time, bpm)
        heard_bpm = 60.0 / period
        tempo_source = "given (bpm)" if bpm is not None else "found from the ticks"
    if bpm is not None:
        check_bpm(bpm, heard_bpm)
    span = ticks.time[-1] - ticks.time[0]
    per_beat = k * period / max(span + period, period)
    acoustic = acoustic_order(ticks.time, period, window=order_window, cluster_gap=cluster_gap)
    apart = no_common_beat(tempi, acoustic.window / period)
    if apart:
        # Nothing measured on a beat nobody keeps is kept (`no_common_beat`).
        nan = np.full(acoustic.r.shape, np.nan)
        acoustic = replace(acoustic, r=nan, ticks_per_beat=nan, clusters=nan)
        per_beat = math.nan
        tempo_source = "the median of the metronomes' own tempi; no common beat"
    n, source, note = _count(heard, metronomes, acoustic, apart, by)
    floor, excess = floor_and_excess(acoustic.r, n)
    acoustic = replace(acoustic, floor=floor, excess=excess)
    is_tock = np.full(k, -1, dtype=np.int8)
    interval = np.full(k, np.nan)
    phase = np.full(k, np.nan)
    stats, kept = [], []
    for m, h in enumerate(heard):
        own = where[h.ticks]
        s = beat_statistics(ticks.time[own], _own_period(h), ticks.strength[own])
        stats.append(s)
        is_tock[own] = s.is_tock
        gaps = np.full(own.size, np.nan)
        gaps[:-1] = beat_gaps(ticks.time[own], s.beat_number)
        interval[own] = gaps
        kept.append(ph.kept_from_half_periods(ticks.time[own], s.beat_number,
                                              parity=1 if s.is_tock[0] else 0))  # fmt: skip
        if m > 0:
            phase[own] = phase_difference(ticks.time[where[heard[0].ticks]], ticks.time[own],
                                          _own_period(heard[0]))  # fmt: skip
    wanted = WINDOW_BEATS * period if order_window is None else order_window
    if span < wanted:
        warnings.warn(
            f"the recording holds only {plural(k, 'tick')} over {span:.1f} s, less than one "
            f"window of the acoustic order parameter ({wanted:.1f} s): too short for steady "
            f"figures; record a minute or more.",
            UserWarning,
            stacklevel=2,
        )
    ds = assemble(recording, scan, ticks, acoustic, stats, label, is_tock, interval, phase)
    ds["tick_probability"] = (
        "tick",
        tick_probability,
        {"long_name": "probability that the tick is its metronome's (NaN: no metronome's)"},
    )
    if heard:
        ds = ds.assign(_model_fit(heard, tick_probability, label))
    pendulums = pendulum_phases(kept, GRID_DT)
    ds = ds.merge(pendulums)
    ds.attrs.update(pendulums.attrs)
    confidence = float(np.nanmin(ds["explained"].values)) if heard else 0.0
    ds.attrs.update(recording_attrs(recording, scan))
    ds.attrs.update(
        beat_period=period,
        bpm_ensemble=60.0 / period,
        tempo_source=tempo_source,
        metronomes=n,
        metronomes_source=source,
        impacts=int(impacts.time.size),
        tick_structure=_impact_words(impacts.time.size, heard, int(np.sum(owner < 0))),
        ticks_per_beat=per_beat,
        band=list(scan.band),
        sensitivity=sensitivity,
        refractory=refractory,
        resolution=max(refractory, det.RESOLUTION),
        order_window=acoustic.window,
        order_step=acoustic.step,
        cluster_gap=cluster_gap,
        attribution=by,
        attribution_confidence=confidence,
        attribution_sureness=sureness(confidence) if len(heard) > 1 else "",
        attribution_meaning="the least mean probability, over the metronomes, that a "
        "metronome's ticks are its own",
        attribution_note=note,
        no_common_beat=apart,
        timing_model=json.dumps(asdict(MODEL)),
        metrosync_version=__version__,
    )
    ds.attrs["summary"] = summary_text(ds)
    return ds


def _open(path, band):
    """The recording at ``path``, or the files of a list recorded together, aligned."""
    if not isinstance(path, list | tuple):
        return open_recording(path)
    if len(path) == 1:
        return open_recording(path[0])
    from .together import record_together

    return record_together(path, band=band)


def _metronomes(impacts: det.Ticks, bpm: float | None, sound=None
                ) -> tuple[list[Heard], np.ndarray]:  # fmt: skip
    """The metronomes that explain the impacts (`decompose`), loudest first, and each
    impact's owner (−1: clutter). Given ``bpm``, where none heard is near it, they are
    sought within `HINT_RANGE` of it (a setting the user knows rules out a harmonic
    or a slower tempo the ticks also fit)."""
    heard, owner = decompose(
        impacts.time, impacts.strength, channel_levels=impacts.channel_strength,
        features=sound,
    )
    if bpm is not None and not any(abs(60.0 / _own_period(h) / bpm - 1) <= HINT_RANGE
                                   for h in heard):  # fmt: skip
        window = (bpm * (1 - HINT_RANGE), bpm * (1 + HINT_RANGE))
        window = (max(window[0], MODEL.bpm_range[0]), min(window[1], MODEL.bpm_range[1]))
        hinted, hinted_owner = decompose(
            impacts.time,
            impacts.strength,
            bpm_range=window,
            channel_levels=impacts.channel_strength,
            features=sound,
        )
        # taken where it explains the onsets as well: a third of a tempo heard, say, fits
        # every third tick as well as the tempo does, and leaves the rest unexplained
        if hinted and np.sum(hinted_owner >= 0) >= np.sum(owner >= 0):
            heard, owner = hinted, hinted_owner
    loudness = [float(np.mean(impacts.strength[h.ticks])) for h in heard]
    order = np.argsort(loudness, kind="stable")[::-1]
    relabel = np.full(len(heard) + 1, -1)
    relabel[order] = np.arange(order.size)
    return [heard[i] for i in order], np.where(owner >= 0, relabel[owner], -1)


def _told_apart_by(heard: list[Heard], sound: np.ndarray, times: np.ndarray) -> str:
    """How the metronomes differ: "sound" where each one's learned sound (`sounds`) sets
    its ticks apart from every other's, "tempo" (their timing: tempo and phase) where
    none does, "sound and tempo" in between; "none" for fewer than two."""
    if len(heard) < 2:
        return "none"
    sounds = learn_sounds(sound, [h.ticks for h in heard], [np.mod(h.beats, 2) for h in heard],
                          times)  # fmt: skip
    apart = [sounds.told_apart(m, [h.ticks for h in heard]) for m in range(len(heard))]
    return "sound" if all(apart) else "sound and tempo" if any(apart) else "tempo"


def sureness(confidence: float) -> str:
    """Words for an attribution confidence (the least of the metronomes' `explained`)."""
    if confidence >= 0.9:
        return "sure"
    if confidence >= 0.7:
        return "fairly sure"
    return "unsure: check the plot"


def _own_period(h: Heard) -> float:
    """A metronome's mean beat over the beats it was heard in, s (drift included)."""
    return 60.0 / h.followed.timing.mean_bpm(int(h.beats.min()), int(h.beats.max()))


def _count(heard: list[Heard], given, acoustic, apart, by: str) -> tuple[int, str, str]:
    """(how many metronomes, how that was found, a note where the count is in doubt)."""
    # Synchronized metronomes tick as one; the windows where they were least together
    # count them best.
    at_once = len(heard) if apart else np.nanpercentile(acoustic.ticks_per_beat, 95)
    busiest = max(1, round(float(at_once)))
    if given is not None:
        note = (
            ""
            if len(heard) == int(given)
            else (f"{plural(len(heard), 'metronome')} told apart, {int(given)} expected")
        )
        return int(given), "given", note
    if not heard:
        return busiest, "most ticks per beat in a window (95th percentile), rounded", ""
    source = "one tick train" if len(heard) == 1 else f"told apart by {by}"
    note = ""
    if busiest > len(heard) and not apart:
        note = (f"up to {busiest} ticks per beat are heard but only "
                f"{plural(len(heard), 'metronome')} told apart; the others sound alike and "
                f"keep the same tempo")  # fmt: skip
    return len(heard), source, note


def _model_fit(heard: list[Heard], tick_probability: np.ndarray, label: np.ndarray) -> dict:
    """Per metronome: the share of its beats heard, the mean probability of its ticks,
    and its learned tick in words."""
    share, explained, words = [], [], []
    for m, h in enumerate(heard):
        beats = h.beats
        share.append(beats.size / (int(beats.max() - beats.min()) + 1))
        explained.append(float(np.nanmean(tick_probability[label == m])))
        words.append(tick_words(h.followed.structure))
    return {
        "beats_heard": ("metronome", np.array(share),
                        {"long_name": "share of its beats whose tick was heard"}),
        "explained": ("metronome", np.array(explained),
                      {"long_name": "mean probability that its ticks are its own"}),
        "tick_impacts": ("metronome", np.array(words),
                         {"long_name": "its learned tick and tock: the impacts' offsets "
                                       "from the main one, share of beats heard"}),
    }  # fmt: skip


def tick_words(structures: tuple[Structure, Structure]) -> str:
    """A metronome's learned tick and tock in words, e.g. "tick: −23 ms (81 %),
    0 ms (main); tock: 0 ms (main), +18 ms (96 %)"."""
    parts = []
    for name, structure in zip(("tick", "tock"), structures, strict=True):
        main = structure.main_impact.offset
        impacts = [
            "0 ms (main)" if j == structure.main
            else f"{1e3 * (i.offset - main):+.0f} ms ({100 * i.presence:.0f} %)"
            for j, i in enumerate(structure.impacts)
        ]  # fmt: skip
        parts.append(f"{name}: " + ", ".join(impacts))
    return "; ".join(parts).replace("-", "−")


def _impact_words(impacts: int, heard: list[Heard], clutter: int) -> str:
    """How the impacts were explained, e.g. "120 ticks of 2 metronomes (2.9 impacts a
    tick), 4 onsets of clutter"."""
    ticks = sum(h.ticks.size for h in heard)
    if not heard:
        return "no metronome's tick found: every impact counted as a tick"
    per = (impacts - clutter) / max(ticks, 1)
    return (f"{plural(ticks, 'tick')} of {plural(len(heard), 'metronome')} "
            f"({per:.1f} impacts a tick), {plural(clutter, 'onset')} of clutter")  # fmt: skip

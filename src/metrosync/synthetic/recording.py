"""A recording of metronomes as a phone hears them, with the truth of every tick.

Entry point::

    make_recording(trains, *, sample_rate=44100, microphones=1,
                   impairments=Impairments(), duration=None, seed=0) -> Recording

trains : sequence of `TickTrain` (`metrosync.synthetic.trains`), one per metronome (1
    to 8): when each tick sounds, which are tocks, and the metronome's sound (a
    `metrosync.synthetic.ticks.Voice`).
sample_rate : 44100 or 48000 (any integer in [8000, 192000]) Hz, of the output.
microphones : an int C (1 to 8), or a sequence of C `Microphone(gains, delays)`, one
    gain and one delay (s, ≥ 0) per train. With C = 1 (the default) the microphone
    hears every train at gain 1 and delay 0. With C ≥ 2 the metronomes stand on a disk
    of radius 0.27 m (metronome i at angle 2πi/N) and the microphones at drawn places
    0.35–0.8 m from its centre, 0.1–0.3 m above it: delay = distance / 343 m/s
    rounded to whole samples, gain = (nearest microphone's distance / distance), so
    each metronome is loudest (gain 1) at its nearest microphone.
impairments : `Impairments` (`metrosync.synthetic.impairments`: the room, the phone,
    the hand), applied to each microphone separately after the trains are summed.
duration : length, s (default: the last tick + 1 s). A tick at or after the end is
    refused.

The model: each microphone hears the sum of the metronomes' ticks, each tick its
voice's waveform placed at the nearest sample to its time (plus the microphone's
delay), scaled by the train's gain and the tick's level, and, for a voice with a
precursor (`metrosync.synthetic.structures`), its precursor's sound placed its lead
before it (the train's leads, or drawn from the voice's `Precursor`); then the
impairments. Every draw comes from ``seed``: the same arguments give the same samples,
and a recording of voices without precursors is what it was before they existed.

Returns `Recording`:
    samples : float32, (S,) for one microphone, (S, C) for several, in [−1, 1].
    sample_rate : Hz.
    truth : one `TrainTruth` per train, in order: ``times`` (K,) the time of each
        tick at microphone 0, s, which is the onset of its loud (main) impact,
        rendered at the nearest sample (within half a sample); ``is_tock`` (K,)
        bool; ``voice``; ``gains`` (C,) and ``delays`` (C,) of that metronome at each
        microphone; ``arrivals(c)`` the ticks' times at microphone c; ``precursors``
        (K,) the onset of each tick's precursor at microphone 0, s (NaN where none
        sounded; None for a voice without precursors).
    applied : what the impairments drew (band corners, bump times and microphones, …).
    ``Recording.write(path)`` writes it (16-bit PCM by default) with soundfile.
    ``Recording.files(starts, clock_ppm)`` splits several microphones into one mono
    recording each, as from phones started ``starts`` s late whose clocks run fast by
    ``clock_ppm``, with the truth of each.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import signal

from .._words import plural
from ..errors import ParameterError
from .impairments import Impairments, impair
from .ticks import Voice, check_sample_rate
from .trains import BOUNCE_VARIANTS, MAX_TRAINS, TickTrain, check_seed

__all__ = ["MAX_MICROPHONES", "Microphone", "Recording", "TrainTruth", "make_recording"]

SPEED_OF_SOUND = 343.0  # m/s
DISK_RADIUS = 0.27  # m, as in the experiment
MAX_MICROPHONES = 8


@dataclass(frozen=True)
class Microphone:
    """One microphone: the gain and the delay (s, ≥ 0) at which it hears each train."""

    gains: tuple[float, ...]
    delays: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.gains) != len(self.delays):
            raise ParameterError(
                f"`gains` and `delays` need one value per train, got {len(self.gains)} "
                f"and {len(self.delays)}."
            )
        if not all(math.isfinite(g) and g >= 0 for g in self.gains):
            raise ParameterError(f"`gains` must be ≥ 0, got {self.gains!r}.")
        if not all(math.isfinite(d) and 0 <= d <= 0.1 for d in self.delays):
            raise ParameterError(f"`delays` must be in [0, 0.1] s, got {self.delays!r}.")


@dataclass(frozen=True, eq=False)
class TrainTruth:
    """The truth about one train in a recording.

    times : (K,) time of each tick at microphone 0 (the onset of its loud, main impact), s.
    is_tock : (K,) True for the tocks.
    voice : the metronome's sound.
    gains, delays : (C,) its gain and delay (s) at each microphone.
    precursors : (K,) onset of the precursor before each tick at microphone 0, s, NaN
        where none sounded (None: the voice has no precursor).
    """

    times: np.ndarray
    is_tock: np.ndarray
    voice: Voice
    gains: np.ndarray
    delays: np.ndarray
    precursors: np.ndarray | None = None

    def arrivals(self, channel: int) -> np.ndarray:
        """(K,) the onsets at microphone ``channel``, s."""
        return self.times + (self.delays[channel] - self.delays[0])


@dataclass(frozen=True, eq=False)
class Recording:
    """samples (S,) or (S, C) float32, sample_rate Hz, truth per train, applied draws."""

    samples: np.ndarray
    sample_rate: int
    truth: list[TrainTruth]
    applied: dict = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return self.samples.shape[0] / self.sample_rate

    @property
    def channels(self) -> int:
        return 1 if self.samples.ndim == 1 else self.samples.shape[1]

    def files(
        self, starts: Sequence[float] | None = None, clock_ppm: Sequence[float] | None = None
    ) -> list[Recording]:
        """One mono recording per microphone, as if each were a phone of its own
        started ``starts[c]`` s (≥ 0, default 0) after the first: its samples from
        there on, its truth the onsets at that microphone minus its start (ticks
        before the start left out; ``gains``, ``delays`` of that microphone).

        clock_ppm : (C,) how fast each phone's clock runs, parts per million (default
            0; phones differ by tens): a phone whose clock is fast by ε·10⁶ ppm takes
            (1 + ε) times as many samples per second as it says, so its file is
            resampled (FFT) to (1 + ε) times as many samples and its truth times
            are (t − start)·(1 + ε). Over a minute, 20 ppm moves the ticks by 1.2 ms.
        """
        starts = [0.0] * self.channels if starts is None else [float(s) for s in starts]
        if len(starts) != self.channels or not all(0 <= s < self.duration for s in starts):
            raise ParameterError(
                f"`starts` must hold {plural(self.channels, 'time')} in "
                f"[0, {self.duration:g}) s, got {starts!r}."
            )
        ppm = [0.0] * self.channels if clock_ppm is None else [float(p) for p in clock_ppm]
        if len(ppm) != self.channels or not all(abs(p) <= 1000 for p in ppm):
            raise ParameterError(
                f"`clock_ppm` must hold {self.channels} values in [-1000, 1000] ppm, got "
                f"{clock_ppm!r}."
            )
        samples = self.samples.reshape(self.samples.shape[0], -1)
        out = []
        for c, start in enumerate(starts):
            k = int(round(start * self.sample_rate))
            stretch = 1.0 + ppm[c] * 1e-6
            x = samples[k:, c]
            if stretch != 1.0:
                x = signal.resample(x, int(round(x.size * stretch))).astype(np.float32)
                x = np.clip(x, -1.0, 1.0)
            truth = []
            for t in self.truth:
                times = t.arrivals(c) - k / self.sample_rate
                keep = times >= 0
                before = None
                if t.precursors is not None:
                    before = (t.precursors - t.times + times)[keep] * stretch
                    before[before < 0] = np.nan
                truth.append(TrainTruth(times[keep] * stretch, t.is_tock[keep], t.voice,
                                        t.gains[c : c + 1], t.delays[c : c + 1],
                                        before))  # fmt: skip
            applied = dict(self.applied, start=k / self.sample_rate, clock_ppm=ppm[c])
            out.append(Recording(x.copy(), self.sample_rate, truth, applied))
        return out

    def write(self, path: Path | str, subtype: str = "PCM_16") -> Path:
        import soundfile as sf

        sf.write(str(path), self.samples, self.sample_rate, subtype=subtype)
        return Path(path)


# --- the recording -------------------------------------------------------------------


def make_recording(
    trains: Sequence[TickTrain],
    *,
    sample_rate: int = 44100,
    microphones: int | Sequence[Microphone] = 1,
    impairments: Impairments = Impairments(),  # noqa: B008 (frozen)
    duration: float | None = None,
    seed: int = 0,
) -> Recording:
    """A recording of ``trains`` with its ground truth (see the module docstring)."""
    trains = list(trains)
    if not 1 <= len(trains) <= MAX_TRAINS or not all(isinstance(t, TickTrain) for t in trains):
        raise ParameterError(
            f"`trains` must be 1 to {MAX_TRAINS} TickTrain, got {len(trains)} items."
        )
    check_sample_rate(sample_rate)
    if not isinstance(impairments, Impairments):
        raise ParameterError(
            f"`impairments` must be an Impairments (e.g. Impairments.phone()), got {impairments!r}."
        )
    rng = np.random.default_rng([28, check_seed(seed)])
    mics = _microphones(microphones, len(trains), rng)
    last = max((float(t.times[-1]) for t in trains if t.times.size), default=0.0)
    if duration is None:
        duration = last + 1.0
    if not (math.isfinite(duration) and duration > last):
        raise ParameterError(
            f"`duration` = {duration!r} s ends before the last tick at {last:.3f} s; "
            f"give a longer `duration` or None."
        )
    rate = impairments.resample_from or sample_rate
    n = int(round(duration * rate))
    gains = np.array([m.gains for m in mics]).T  # (N, C)
    shifts = np.round(np.array([m.delays for m in mics]).T * rate).astype(np.int64)
    x = np.zeros((n, len(mics)), dtype=np.float32)
    leads: list[np.ndarray | None] = []
    for i, train in enumerate(trains):
        leads.append(_precursor_leads(train, np.random.default_rng([35, seed, i])))
        dry = _render_train(train, rate, n, np.random.default_rng([30, seed, i]), leads[-1])
        for c in range(len(mics)):
            s = shifts[i, c]
            x[s:, c] += gains[i, c] * dry[: n - s]
    applied: dict = {}
    x = impair(x, rate, impairments, rng, applied)
    if rate != sample_rate:
        g = math.gcd(rate, sample_rate)
        x = signal.resample_poly(x, sample_rate // g, rate // g, axis=0).astype(np.float32)
        size = int(round(duration * sample_rate))
        x = np.pad(x[:size], ((0, max(0, size - x.shape[0])), (0, 0)))
    if impairments.quantize_bits:
        full = 2 ** (impairments.quantize_bits - 1)
        x = np.clip(np.round(x * full), -full, full - 1) * np.float32(1 / full)
    x = np.clip(x, -1.0, 1.0).astype(np.float32, copy=False)
    truth = [
        TrainTruth(
            t.times + shifts[i, 0] / rate,
            t.is_tock.copy(),
            t.voice,
            gains[i].copy(),
            shifts[i] / rate,
            None if leads[i] is None else t.times - leads[i] + shifts[i, 0] / rate,
        )  # fmt: skip
        for i, t in enumerate(trains)
    ]
    return Recording(x[:, 0] if len(mics) == 1 else x, int(sample_rate), truth, applied)


def _microphones(microphones, n_trains: int, rng) -> list[Microphone]:
    if isinstance(microphones, int) and not isinstance(microphones, bool):
        if not 1 <= microphones <= MAX_MICROPHONES:
            raise ParameterError(
                f"`microphones` must be 1 to {MAX_MICROPHONES}, got {microphones!r}."
            )
        if microphones == 1:
            return [Microphone((1.0,) * n_trains, (0.0,) * n_trains)]
        angle = 2 * np.pi * np.arange(n_trains) / n_trains
        sources = np.column_stack([DISK_RADIUS * np.cos(angle), DISK_RADIUS * np.sin(angle),
                                   np.zeros(n_trains)])  # fmt: skip
        where = rng.uniform(0, 2 * np.pi, microphones)
        radius = rng.uniform(0.35, 0.8, microphones)
        places = np.column_stack([radius * np.cos(where), radius * np.sin(where),
                                  rng.uniform(0.1, 0.3, microphones)])  # fmt: skip
        distance = np.linalg.norm(places[:, None, :] - sources[None, :, :], axis=-1)  # (C, N)
        gains = distance.min(axis=0) / distance
        return [
            Microphone(tuple(map(float, gains[c])), tuple(map(float, distance[c] / SPEED_OF_SOUND)))
            for c in range(microphones)
        ]
    mics = list(microphones)
    if not 1 <= len(mics) <= MAX_MICROPHONES or not all(isinstance(m, Microphone) for m in mics):
        raise ParameterError(
            f"`microphones` must be an int or 1 to {MAX_MICROPHONES} Microphone, got "
            f"{microphones!r}."
        )
    for m in mics:
        if len(m.gains) != n_trains:
            raise ParameterError(
                f"each Microphone needs one gain and delay per train ({n_trains}), got "
                f"{len(m.gains)}."
            )
    return mics


def _precursor_leads(train: TickTrain, rng) -> np.ndarray | None:
    """(K,) the lead of the precursor before each tick, s, NaN where none sounds (none
    before the recording's start): the train's, or drawn from its voice's precursors,
    the ticks' then the tocks'; None for a voice without precursors."""
    voice = train.voice
    if voice.precursor is None and voice.tock_precursor is None:
        return None
    if train.precursor_leads is not None:
        leads = train.precursor_leads.copy()
    else:
        leads = np.full(train.times.size, np.nan)
        for tock in (False, True):
            precursor = voice.precursor_of(tock=tock)
            which = train.is_tock == tock
            if precursor is not None and which.any():
                leads[which] = precursor.leads(int(which.sum()), rng)
    leads[train.times - leads < 0] = np.nan
    return leads


def _render_train(
    train: TickTrain, rate: int, n: int, rng, leads: np.ndarray | None = None
) -> np.ndarray:
    """(n,) the train's ticks and tocks at the metronome, each placed at its nearest
    sample; with bounce jitter, each tick one of `BOUNCE_VARIANTS` variants drawn
    from ``rng``; the precursors ``leads`` (K,) s before their ticks (NaN: none)."""
    out = np.zeros(n, dtype=np.float32)
    onsets = np.round(train.times * rate).astype(np.int64)
    levels = train.gain * (np.ones(onsets.size) if train.levels is None else train.levels)
    variants = 1 if train.bounce_jitter_s == 0 or not train.voice.sub_delays else BOUNCE_VARIANTS
    pick = rng.integers(variants, size=onsets.size)
    for tock in (False, True):
        for v in range(variants):
            which = (train.is_tock == tock) & (pick == v)
            if not which.any():
                continue
            voice = (
                train.voice if variants == 1 else _bounced(train.voice, train.bounce_jitter_s, rng)
            )
            wave = voice.waveform(rate, tock=tock)
            index = onsets[which, None] + np.arange(wave.size)[None, :]
            values = levels[which, None] * wave[None, :]
            inside = index < n
            if np.all(np.diff(onsets[which]) >= wave.size):
                out[index[inside]] += values[inside]  # no two overlap: each index once
            else:
                np.add.at(out, index[inside], values[inside])
    if leads is not None:
        _add_precursors(out, train, rate, levels, leads)
    return out


def _add_precursors(out, train: TickTrain, rate: int, levels, leads) -> None:
    """Add to ``out`` each tick's precursor, ``leads`` (K,) s before it (NaN: none),
    at its nearest sample, as loud against its tick as the voice says."""
    for tock in (False, True):
        which = (train.is_tock == tock) & np.isfinite(leads)
        if not which.any():
            continue
        wave = train.voice.precursor_waveform(rate, tock=tock)
        onsets = np.round((train.times[which] - leads[which]) * rate).astype(np.int64)
        index = onsets[:, None] + np.arange(wave.size)[None, :]
        values = levels[which, None] * wave[None, :]
        inside = (index >= 0) & (index < out.size)
        np.add.at(out, index[inside], values[inside])


def _bounced(voice: Voice, jitter: float, rng) -> Voice:
    """The voice with its secondary-impact delays moved by Gaussian ``jitter`` (s),
    kept at least 5 ms after the main impact and 2 ms after each other."""
    changes: dict[str, Any] = {"sub_delays": _moved(voice.sub_delays, jitter, rng)}
    if voice.tock_sub_delays:
        changes["tock_sub_delays"] = _moved(voice.tock_sub_delays, jitter, rng)
    return dataclasses.replace(voice, **changes)


def _moved(sub_delays: tuple[float, ...], jitter: float, rng) -> tuple[float, ...]:
    moved = np.sort(np.asarray(sub_delays) + rng.normal(0.0, jitter, len(sub_delays)))
    delays: list[float] = []
    for d in moved:
        delays.append(max(float(d), delays[-1] + 0.002 if delays else 0.005))
    return tuple(delays)

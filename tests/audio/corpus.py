"""A realistic test corpus: recordings of metronomes as a phone hears them, with the
ground truth of every tick.

Entry point::

    make_recording(trains, *, sample_rate=44100, microphones=1,
                   impairments=Impairments(), duration=None, seed=0) -> Recording

trains : sequence of `TickTrain`, one per metronome (1 to 8):
    ``TickTrain(times, is_tock, voice, gain=1.0, levels=None)`` — the onsets (s, at the
    metronome) of each tick's FIRST impact, which ticks are tocks, the metronome's
    sound (`metrosync.show.ticks.Voice`), its loudness, and optional per-tick level
    factors (K,). Build them with

    - ``steady_train(bpm, duration, *, phase=0, limp=0, drift_bpm_per_min=0,
      jitter_s=0, level_jitter_db=0, tock_first=False, voice=None, gain=1, seed=0)``:
      a free-running metronome; ``bpm`` ticks per minute (tick and tock each count),
      the first tick at ``phase`` beats (0 ≤ phase < 1), beats alternating
      (1 ± limp/2)·T (limp = (long − short)/mean beat, a fraction, as
      `metrosync.audio.metronome` measures it), the tempo rising by
      ``drift_bpm_per_min`` BPM per minute as the spring unwinds, each tick displaced
      by independent Gaussian jitter (s, std), each tick's level by Gaussian dB.
      Locked metronomes: the same ``bpm`` (and drift) with the phases you want;
    - ``simulated_trains(ds, *, run=0, voices=None, start=None, end=None)``: the ticks
      of a run of `metrosync.simulate(..., trajectories=True)`: every crossing of θ_i
      through its escapement angle, upward a tick, downward a tock (audio time 0 at
      ``start``);
    - ``metrosync.show.ticks.voices(n, seed)``: n voices that differ from each other.
      A train built by `steady_train` without a voice gets ``Voice.draw(seed)``; give
      ``voice=`` from `voices` to metronomes that should sound different, the same
      voice to metronomes of one make.

sample_rate : 44100 or 48000 (any integer in [8000, 192000]) Hz, of the output.
microphones : an int C (1 to 8), or a sequence of C `Microphone(gains, delays)`, one
    gain and one delay (s, ≥ 0) per train. With C = 1 (the default) the microphone
    hears every train at gain 1 and delay 0. With C ≥ 2 the metronomes stand on a disk
    of radius 0.27 m (metronome i at angle 2πi/N) and the microphones at drawn places
    0.35–0.8 m from its centre, 0.1–0.3 m above it: delay = distance / 343 m/s
    rounded to whole samples, gain = (nearest microphone's distance / distance), so
    each metronome is loudest (gain 1) at its nearest microphone.
impairments : `Impairments`, each switchable; `Impairments.phone()` turns on a
    realistic set. Applied in this order, each microphone separately:
    1. reverberation (``reverb_rt60`` s): convolution with the direct sound plus an
       exponentially decaying Gaussian-noise tail (−60 dB after rt60, starting 2 ms
       after the direct sound, ``reverb_drr_db`` dB below it in energy);
    2. background noise at ``snr_db``: ``noise`` ("pink" or "white") Gaussian noise
       whose power is ``snr_db`` dB below the mean power of the signal so far (whole
       recording, each microphone);
    3. handling bumps (``bumps``: how many): low-frequency thumps (a damped 25–90 Hz
       sinusoid, 40–120 ms, peak 0.5–2 times the signal's peak) at uniform random
       times, each on one random microphone;
    4. phone band limits (``phone_band``: True draws a high-pass corner in 100–300 Hz
       and a low-pass corner in 4–8 kHz; or give (low, high) Hz): Butterworth
       high-pass of order 2 and low-pass of order 4, causal as in a phone (they delay
       the tick's rise by well under 0.5 ms);
    5. compression (``compression``): a feed-forward compressor on the signal's level
       (instant peak detection with exponential release ``compression_release_s``,
       smoothed by the attack ``compression_attack_s``), gain reduction
       (1 − 1/ratio)·(level − threshold) above ``compression_threshold_db`` (dB
       relative to the signal's peak);
    6. level: the peak is scaled to 0.9 of full scale; with ``clipping`` = c in (0, 1)
       it is scaled to 1/c instead and clipped at ±1 (full scale);
    7. format: with ``resample_from`` = R the recording is made at R Hz and resampled
       (polyphase, linear phase: no delay) to ``sample_rate``; with ``quantize_bits``
       it is rounded to that many bits.
    Every draw comes from ``seed``: the same arguments give the same samples.
duration : length, s (default: the last tick + 1 s). A tick at or after the end is
    refused.

Returns `Recording`:
    samples : float32, (S,) for one microphone, (S, C) for several, in [−1, 1].
    sample_rate : Hz.
    truth : one `TrainTruth` per train, in order: ``times`` (K,) the onset of each
        tick's first impact at microphone 0, s (rendered at the nearest sample: within
        half a sample); ``is_tock`` (K,) bool; ``voice``; ``gains`` (C,) and
        ``delays`` (C,) of that metronome at each microphone; ``arrivals(c)`` the
        onsets at microphone c.
    applied : what the impairments drew (band corners, bump times and microphones, …).
    ``Recording.write(path)`` writes it (16-bit PCM by default) with soundfile.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import fft as sp_fft
from scipy import signal

from metrosync.errors import ParameterError
from metrosync.show.ticks import Voice

SPEED_OF_SOUND = 343.0  # m/s
DISK_RADIUS = 0.27  # m, as in the experiment
OUTPUT_PEAK = 0.9
MAX_TRAINS = 8
MAX_MICROPHONES = 8
#: Samples per level measurement of the compressor.
COMPRESSOR_BLOCK = 16


@dataclass(frozen=True, eq=False)
class TickTrain:
    """The ticks of one metronome.

    times : (K,) increasing onsets of each tick's first impact at the metronome, s, ≥ 0.
    is_tock : (K,) True where the tick is a tock.
    voice : the metronome's sound.
    gain : its loudness (the tick's peak is ``gain · voice.level`` before impairments).
    levels : (K,) optional factor on each tick's loudness.
    """

    times: np.ndarray
    is_tock: np.ndarray
    voice: Voice
    gain: float = 1.0
    levels: np.ndarray | None = None

    def __post_init__(self) -> None:
        times = np.asarray(self.times, dtype=float)
        is_tock = np.asarray(self.is_tock, dtype=bool)
        if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(times < 0):
            raise ParameterError(
                f"`times` must be a 1-D array of finite times ≥ 0 s, got {times!r}."
            )
        if np.any(np.diff(times) <= 0):
            raise ParameterError("`times` must be strictly increasing.")
        if is_tock.shape != times.shape:
            raise ParameterError(
                f"`is_tock` must have the shape of `times` {times.shape}, got {is_tock.shape}."
            )
        if not isinstance(self.voice, Voice):
            raise ParameterError(f"`voice` must be a Voice, got {self.voice!r}.")
        if not (math.isfinite(self.gain) and self.gain > 0):
            raise ParameterError(f"`gain` must be a number > 0, got {self.gain!r}.")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "is_tock", is_tock)
        if self.levels is not None:
            levels = np.asarray(self.levels, dtype=float)
            if levels.shape != times.shape or np.any(levels <= 0):
                raise ParameterError(
                    f"`levels` must be {times.shape} positive factors, got {levels!r}."
                )
            object.__setattr__(self, "levels", levels)


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


@dataclass(frozen=True)
class Impairments:
    """What the room, the phone and the hand do to the sound; all off by default.

    See the module docstring for each step and its order.
    """

    reverb_rt60: float | None = None
    reverb_drr_db: float = 6.0
    snr_db: float | None = None
    noise: str = "pink"
    bumps: int = 0
    phone_band: bool | tuple[float, float] = False
    compression: bool = False
    compression_threshold_db: float = -24.0
    compression_ratio: float = 4.0
    compression_attack_s: float = 0.003
    compression_release_s: float = 0.1
    clipping: float | None = None
    resample_from: int | None = None
    quantize_bits: int | None = None

    def __post_init__(self) -> None:
        if self.reverb_rt60 is not None and not (0.05 <= self.reverb_rt60 <= 3.0):
            raise ParameterError(
                f"`reverb_rt60` must be in [0.05, 3] s or None, got {self.reverb_rt60!r}."
            )
        if self.snr_db is not None and not (-20 <= self.snr_db <= 120):
            raise ParameterError(f"`snr_db` must be in [-20, 120] dB or None, got {self.snr_db!r}.")
        if self.noise not in ("pink", "white"):
            raise ParameterError(f"`noise` must be 'pink' or 'white', got {self.noise!r}.")
        if isinstance(self.bumps, bool) or not isinstance(self.bumps, int) or self.bumps < 0:
            raise ParameterError(f"`bumps` must be an integer ≥ 0, got {self.bumps!r}.")
        if not isinstance(self.phone_band, bool):
            low, high = self.phone_band
            if not (10 <= low < high):
                raise ParameterError(
                    f"`phone_band` must be True, False or (low, high) Hz with "
                    f"10 ≤ low < high, got {self.phone_band!r}."
                )
        if not self.compression_ratio >= 1:
            raise ParameterError(
                f"`compression_ratio` must be ≥ 1, got {self.compression_ratio!r}."
            )
        if not (self.compression_attack_s > 0 and self.compression_release_s > 0):
            raise ParameterError("`compression_attack_s` and `compression_release_s` must be > 0.")
        if self.clipping is not None and not (0 < self.clipping < 1):
            raise ParameterError(
                f"`clipping` must be in (0, 1) (the fraction of the peak that reaches full "
                f"scale) or None, got {self.clipping!r}."
            )
        if self.resample_from is not None and not (8000 <= self.resample_from <= 192000):
            raise ParameterError(
                f"`resample_from` must be a rate in [8000, 192000] Hz or None, got "
                f"{self.resample_from!r}."
            )
        if self.quantize_bits is not None and self.quantize_bits not in (8, 16, 24):
            raise ParameterError(
                f"`quantize_bits` must be 8, 16, 24 or None, got {self.quantize_bits!r}."
            )

    @classmethod
    def phone(cls, **changes) -> Impairments:
        """A phone on a table in a room, everything on: RT60 0.4 s, noise at 30 dB,
        two bumps, the phone's band, compression, 48 kHz resampled, 16 bits (no
        clipping: add ``clipping=0.8`` for a recording made too loud)."""
        base = dict(reverb_rt60=0.4, snr_db=30.0, bumps=2, phone_band=True,
                    compression=True, resample_from=48000, quantize_bits=16)  # fmt: skip
        base.update(changes)
        return cls(**base)


@dataclass(frozen=True, eq=False)
class TrainTruth:
    """The truth about one train in a recording.

    times : (K,) onset of each tick's first impact at microphone 0, s.
    is_tock : (K,) True for the tocks.
    voice : the metronome's sound.
    gains, delays : (C,) its gain and delay (s) at each microphone.
    """

    times: np.ndarray
    is_tock: np.ndarray
    voice: Voice
    gains: np.ndarray
    delays: np.ndarray

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

    def write(self, path: Path | str, subtype: str = "PCM_16") -> Path:
        import soundfile as sf

        sf.write(str(path), self.samples, self.sample_rate, subtype=subtype)
        return Path(path)


# --- tick trains ---------------------------------------------------------------------


def steady_train(
    bpm: float,
    duration: float,
    *,
    phase: float = 0.0,
    limp: float = 0.0,
    drift_bpm_per_min: float = 0.0,
    jitter_s: float = 0.0,
    level_jitter_db: float = 0.0,
    tock_first: bool = False,
    voice: Voice | None = None,
    gain: float = 1.0,
    seed: int = 0,
) -> TickTrain:
    """A free-running metronome (see the module docstring); ticks in [0, duration)."""
    if not (math.isfinite(bpm) and 10 <= bpm <= 600):
        raise ParameterError(f"`bpm` must be in [10, 600] ticks per minute, got {bpm!r}.")
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"`duration` must be > 0 s, got {duration!r}.")
    if not (0 <= phase < 1):
        raise ParameterError(f"`phase` must be in [0, 1) beats, got {phase!r}.")
    if not (0 <= limp < 0.5):
        raise ParameterError(f"`limp` must be in [0, 0.5) of a beat, got {limp!r}.")
    if not (math.isfinite(drift_bpm_per_min) and abs(drift_bpm_per_min) <= 0.5 * bpm):
        raise ParameterError(
            f"`drift_bpm_per_min` must be within ±bpm/2, got {drift_bpm_per_min!r}."
        )
    if not (0 <= jitter_s < 0.1 * 60 / bpm) or not (0 <= level_jitter_db <= 12):
        raise ParameterError(
            f"`jitter_s` must be in [0, a tenth of a beat) and `level_jitter_db` in [0, 12], "
            f"got {jitter_s!r} and {level_jitter_db!r}."
        )
    rng = np.random.default_rng([27, int(seed)])
    # Beats counted since t = 0: n(t) = b t + c t² with b = bpm/60 and c = drift/7200
    # (the tempo bpm + drift·t/60); tick k (unlimped) falls where n = k + phase.
    b, c = bpm / 60.0, drift_bpm_per_min / 7200.0
    last = b * duration + c * duration**2
    beats = np.arange(0, math.ceil(max(last, 0.0)) + 2) + phase
    if c == 0:
        t = beats / b
    else:
        disc = np.maximum(b * b + 4 * c * beats, 0.0)
        t = 2 * beats / (b + np.sqrt(disc))  # the root that tends to n/b as c → 0
    period = 1.0 / (b + 2 * c * t)
    k = np.arange(t.size)
    t = t + np.where(k % 2 == 1, limp / 2, 0.0) * period  # long beat first
    if jitter_s:
        t = t + rng.normal(0.0, jitter_s, t.size)
    is_tock = (k % 2 == 1) != tock_first
    keep = (t >= 0) & (t < duration)
    t, is_tock = t[keep], is_tock[keep]
    levels = None
    if level_jitter_db:
        levels = 10 ** (rng.normal(0.0, level_jitter_db, t.size) / 20)
    return TickTrain(t, is_tock, Voice.draw(seed) if voice is None else voice, gain, levels)


def simulated_trains(
    ds, *, run: int = 0, voices: Sequence[Voice] | None = None, start=None, end=None
) -> list[TickTrain]:
    """The ticks of run ``run`` of a simulated dataset (with trajectories), one train
    per metronome: upward crossings of the escapement angle are ticks, downward ones
    tocks; times from ``start`` (default: the first record) to ``end``."""
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times
    from metrosync.show.ticks import voices as draw_voices

    recorded = RecordedRun.from_dataset(ds, run)
    start, end = recorded.window(start, end)
    voices = draw_voices(recorded.n) if voices is None else list(voices)
    if len(voices) != recorded.n:
        raise ParameterError(
            f"`voices` must hold one voice per metronome ({recorded.n}), got {len(voices)}."
        )
    trains = []
    for i, times in enumerate(crossing_times(recorded)):
        times = times[(times >= start) & (times < end)]
        downward = recorded.theta_dot_at(times)[:, i] < 0
        trains.append(TickTrain(times - start, downward, voices[i]))
    return trains


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
    if (
        isinstance(sample_rate, bool)
        or not isinstance(sample_rate, int)
        or not (8000 <= sample_rate <= 192000)
    ):
        raise ParameterError(
            f"`sample_rate` must be an integer in [8000, 192000] Hz, got {sample_rate!r}."
        )
    rng = np.random.default_rng([28, int(seed)])
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
    x = np.zeros((n, len(mics)))
    for i, train in enumerate(trains):
        dry = _render_train(train, rate, n)
        for c in range(len(mics)):
            s = shifts[i, c]
            x[s:, c] += gains[i, c] * dry[: n - s]
    applied: dict = {}
    x = _impair(x, rate, impairments, rng, applied)
    if rate != sample_rate:
        g = math.gcd(rate, sample_rate)
        x = signal.resample_poly(x, sample_rate // g, rate // g, axis=0)
        size = int(round(duration * sample_rate))
        x = np.pad(x[:size], ((0, max(0, size - x.shape[0])), (0, 0)))
    if impairments.quantize_bits:
        full = 2 ** (impairments.quantize_bits - 1)
        x = np.clip(np.round(x * full), -full, full - 1) / full
    x = np.clip(x, -1.0, 1.0).astype(np.float32)
    truth = [
        TrainTruth(
            t.times + shifts[i, 0] / rate,
            t.is_tock.copy(),
            t.voice,
            gains[i].copy(),
            shifts[i] / rate,
        )  # fmt: skip
        for i, t in enumerate(trains)
    ]
    return Recording(x[:, 0] if len(mics) == 1 else x, sample_rate, truth, applied)


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


def _render_train(train: TickTrain, rate: int, n: int) -> np.ndarray:
    """(n,) the train's ticks and tocks at the metronome, each placed at its nearest
    sample."""
    out = np.zeros(n)
    onsets = np.round(train.times * rate).astype(np.int64)
    levels = train.gain * (np.ones(onsets.size) if train.levels is None else train.levels)
    for tock in (False, True):
        which = train.is_tock == tock
        if not which.any():
            continue
        wave = train.voice.waveform(rate, tock=tock)
        index = onsets[which, None] + np.arange(wave.size)[None, :]
        values = levels[which, None] * wave[None, :]
        inside = index < n
        # np.add.at: the ticks of a fast train may overlap.
        np.add.at(out, index[inside], values[inside])
    return out


def _impair(x: np.ndarray, rate: int, imp: Impairments, rng, applied: dict) -> np.ndarray:
    n, channels = x.shape
    if imp.reverb_rt60 is not None:
        applied["reverb_rt60"] = imp.reverb_rt60
        for c in range(channels):
            x[:, c] = signal.oaconvolve(x[:, c], _room_response(imp, rate, rng))[:n]
    if imp.snr_db is not None:
        power = np.mean(x**2, axis=0)
        noise = _noise(n, channels, imp.noise, rng)
        x = x + noise * np.sqrt(power / 10 ** (imp.snr_db / 10))[None, :]
        applied["snr_db"] = imp.snr_db
    if imp.bumps:
        peak = np.abs(x).max()
        bumps = []
        for _ in range(imp.bumps):
            t0, c = rng.uniform(0, n / rate), int(rng.integers(channels))
            length = rng.uniform(0.04, 0.12)
            t = np.arange(int(length * rate)) / rate
            f = rng.uniform(25, 90)
            thump = np.sin(2 * np.pi * f * t) * np.exp(-t / (length / 4)) * (1 - np.exp(-t / 0.002))
            thump *= rng.uniform(0.5, 2.0) * peak / np.abs(thump).max()
            k = int(t0 * rate)
            m = min(thump.size, n - k)
            x[k : k + m, c] += thump[:m]
            bumps.append((float(k / rate), c))
        applied["bumps"] = sorted(bumps)
    if imp.phone_band is not False:
        if imp.phone_band is True:
            low, high = float(rng.uniform(100, 300)), float(rng.uniform(4000, 8000))
        else:
            low, high = map(float, imp.phone_band)
        high = min(high, 0.45 * rate)
        sos = np.concatenate(
            [
                signal.butter(2, low, "highpass", fs=rate, output="sos"),
                signal.butter(4, high, "lowpass", fs=rate, output="sos"),
            ]
        )
        x = signal.sosfilt(sos, x, axis=0)
        applied["phone_band"] = (low, high)
    if imp.compression:
        x = _compress(x, rate, imp)
        applied["compression"] = (imp.compression_threshold_db, imp.compression_ratio)
    peak = max(np.abs(x).max(), 1e-12)
    if imp.clipping is not None:
        x = np.clip(x / (peak * imp.clipping), -1.0, 1.0)
        applied["clipping"] = imp.clipping
    else:
        x = x * (OUTPUT_PEAK / peak)
    return x


def _room_response(imp: Impairments, rate: int, rng) -> np.ndarray:
    """The direct sound (1) and a noise tail that falls 60 dB in rt60 (cut at −90 dB)."""
    rt60 = imp.reverb_rt60
    t = np.arange(int(1.5 * rt60 * rate)) / rate
    tail = rng.normal(0.0, 1.0, t.size) * 10 ** (-3 * t / rt60)
    tail[: int(0.002 * rate)] = 0.0
    tail *= np.sqrt(10 ** (-imp.reverb_drr_db / 10) / np.sum(tail**2))
    tail[0] = 1.0
    return tail


def _noise(n: int, channels: int, color: str, rng) -> np.ndarray:
    """(n, channels) unit-power Gaussian noise, white or pink (1/f power above 20 Hz)."""
    white = rng.standard_normal((n, channels), dtype=np.float32)
    if color == "white":
        return white
    size = sp_fft.next_fast_len(n, real=True)
    spectrum = sp_fft.rfft(white, size, axis=0)
    f = sp_fft.rfftfreq(size)
    spectrum /= np.sqrt(np.maximum(f, 20.0 / 44100)).astype(np.float32)[:, None]
    pink = sp_fft.irfft(spectrum, size, axis=0)[:n]
    return pink / pink.std(axis=0)


def _compress(x: np.ndarray, rate: int, imp: Impairments) -> np.ndarray:
    """Feed-forward compression, each channel: level (dB) = the peak envelope (instant
    attack, exponential release) smoothed by the attack time constant; computed on
    blocks of `COMPRESSOR_BLOCK` samples (0.36 ms at 44.1 kHz, ten times shorter than
    the attack) and interpolated."""
    n = x.shape[0]
    blocks = -(-n // COMPRESSOR_BLOCK)
    padded = np.zeros((blocks * COMPRESSOR_BLOCK, x.shape[1]))
    padded[:n] = np.abs(x)
    block_peak = padded.reshape(blocks, COMPRESSOR_BLOCK, -1).max(axis=1)
    level_db = 20 * np.log10(block_peak / max(block_peak.max(), 1e-12) + 1e-9)
    # Peak hold with exponential release, vectorised: the decaying maximum
    # max_m (L[m] − (k − m)·r) is the running maximum of L[m] + m·r, minus k·r.
    step = COMPRESSOR_BLOCK / rate
    r = 8.685889638 * step / imp.compression_release_s  # dB per block (e-fold per release)
    ramp = np.arange(blocks)[:, None] * r
    held = np.maximum.accumulate(level_db + ramp, axis=0) - ramp
    a = math.exp(-step / imp.compression_attack_s)
    b, den = [1 - a], [1, -a]
    zi = signal.lfilter_zi(b, den)[:, None] * held[:1]
    smooth = signal.lfilter(b, den, held, axis=0, zi=zi)[0]
    over = np.maximum(smooth - imp.compression_threshold_db, 0.0)
    gain_db = -(1 - 1 / imp.compression_ratio) * over
    centres = (np.arange(blocks) + 0.5) * COMPRESSOR_BLOCK
    samples = np.arange(n)
    gain = np.column_stack([np.interp(samples, centres, gain_db[:, c]) for c in range(x.shape[1])])
    return x * 10 ** (gain / 20)

"""What the room, the phone and the hand do to a synthetic recording
(`metrosync.synthetic.recording`): reverberation, noise, bumps, the phone's band,
compression, level and clipping, and the file's format.

`Impairments` holds them, each switchable and all off by default;
`Impairments.phone()` turns on a realistic set. `impair` applies them in this order,
each microphone separately, every draw from the recording's generator:

1. reverberation (``reverb_rt60`` s): convolution with the direct sound plus an
   exponentially decaying Gaussian-noise tail (−60 dB after rt60, starting 2 ms
   after the direct sound, ``reverb_drr_db`` dB below it in energy);
2. background noise at ``snr_db``: ``noise`` ("pink" or "white") Gaussian noise
   whose power is ``snr_db`` dB below the mean power of the signal so far (whole
   recording, each microphone);
3. handling bumps (``bumps``: how many): low-frequency thumps (a damped 40–150 Hz
   sinusoid, 50–150 ms, opened by a 1 ms broadband crack at 0.2–0.5 of its
   height; peak 0.5–2 times the signal's peak) at uniform random times, and one
   at each of ``bump_times`` (s), each on one random microphone;
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

Step 7 is `make_recording`'s, after `impair`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import signal

from ..errors import ParameterError

OUTPUT_PEAK = 0.9
#: Samples per level measurement of the compressor.
COMPRESSOR_BLOCK = 16


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
    bump_times: tuple[float, ...] = ()
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
        if not all(isinstance(t, (int, float)) and t >= 0 for t in self.bump_times):
            raise ParameterError(f"`bump_times` must be times ≥ 0 s, got {self.bump_times!r}.")
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
        base: dict[str, Any] = dict(reverb_rt60=0.4, snr_db=30.0, bumps=2, phone_band=True,
                                    compression=True, resample_from=48000,
                                    quantize_bits=16)  # fmt: skip
        base.update(changes)
        return cls(**base)


def impair(x: np.ndarray, rate: int, imp: Impairments, rng, applied: dict) -> np.ndarray:
    n, channels = x.shape
    if imp.reverb_rt60 is not None:
        applied["reverb_rt60"] = imp.reverb_rt60
        for c in range(channels):
            room = _room_response(imp, rate, rng).astype(np.float32)
            x[:, c] = signal.oaconvolve(x[:, c], room)[:n]
    if imp.snr_db is not None:
        power = np.mean(x.astype(float) ** 2, axis=0)
        noise = _noise(n, channels, imp.noise, rng)
        x += noise * np.sqrt(power / 10 ** (imp.snr_db / 10)).astype(np.float32)[None, :]
        applied["snr_db"] = imp.snr_db
    if imp.bumps or imp.bump_times:
        if any(t >= n / rate for t in imp.bump_times):
            raise ParameterError(
                f"`bump_times` must lie within the recording's {n / rate:.3f} s, "
                f"got {imp.bump_times!r}."
            )
        peak = float(np.abs(x).max())
        bumps = []
        for b in range(imp.bumps + len(imp.bump_times)):
            t0 = rng.uniform(0, n / rate) if b < imp.bumps else imp.bump_times[b - imp.bumps]
            c = int(rng.integers(channels))
            bumps.append((int(t0 * rate) / rate, c))
            k = int(t0 * rate)
            thump = _thump(rate, rng) * peak
            m = min(thump.size, n - k)
            x[k : k + m, c] += thump[:m]
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
        x = signal.sosfilt(sos.astype(np.float32), x, axis=0)
        applied["phone_band"] = (low, high)
    if imp.compression:
        x = _compress(x, rate, imp)
        applied["compression"] = (imp.compression_threshold_db, imp.compression_ratio)
    peak = max(float(np.abs(x).max()), 1e-12)
    if imp.clipping is not None:
        x *= np.float32(1 / (peak * imp.clipping))
        np.clip(x, -1.0, 1.0, out=x)
        applied["clipping"] = imp.clipping
    else:
        x *= np.float32(OUTPUT_PEAK / peak)
    return x


def _thump(rate: int, rng) -> np.ndarray:
    """A hand bumping the phone, peak 0.5–2: a damped 40–150 Hz sinusoid lasting
    50–150 ms (decay time a quarter of that), opened by the contact's broadband
    crack (1 ms decaying noise, 0.2–0.5 of the thump's peak)."""
    length = rng.uniform(0.05, 0.15)
    t = np.arange(int(length * rate)) / rate
    body = np.sin(2 * np.pi * rng.uniform(40, 150) * t) * np.exp(-t / (length / 4))
    body *= (1 - np.exp(-t / 0.002)) / np.abs(body).max()
    crack = rng.normal(0.0, 1.0, t.size) * np.exp(-t / 0.001)
    crack *= rng.uniform(0.2, 0.5) / np.abs(crack).max()
    return ((body + crack) * rng.uniform(0.5, 2.0)).astype(np.float32)


def _room_response(imp: Impairments, rate: int, rng) -> np.ndarray:
    """The direct sound (1) and a noise tail that falls 60 dB in rt60 (cut at −90 dB)."""
    rt60 = imp.reverb_rt60
    assert rt60 is not None  # called only with reverberation on
    t = np.arange(int(1.5 * rt60 * rate)) / rate
    tail = rng.normal(0.0, 1.0, t.size) * 10 ** (-3 * t / rt60)
    tail[: int(0.002 * rate)] = 0.0
    tail *= np.sqrt(10 ** (-imp.reverb_drr_db / 10) / np.sum(tail**2))
    tail[0] = 1.0
    return tail


def _noise(n: int, channels: int, color: str, rng) -> np.ndarray:
    """(n, channels) unit-power Gaussian noise, white or pink: 1/f power (−3 dB per
    octave) from 20 Hz up, through poles two per decade with a zero a quarter decade
    above each (within 0.5 dB of 1/f from 50 Hz to 20 kHz)."""
    white = rng.standard_normal((n, channels), dtype=np.float32)
    if color == "white":
        return white
    rate = 48000  # the shape is set in Hz at this rate; the noise is scaled after
    poles = 10.0 * 10 ** (np.arange(0, 8) / 2)
    poles = poles[poles * 10**0.25 < 0.45 * rate]
    z, p, k = signal.bilinear_zpk(-2 * np.pi * poles * 10**0.25, -2 * np.pi * poles, 1.0, rate)
    pink = signal.sosfilt(signal.zpk2sos(z, p, k).astype(np.float32), white, axis=0)
    return pink / pink.std(axis=0)


def _compress(x: np.ndarray, rate: int, imp: Impairments) -> np.ndarray:
    """Feed-forward compression, each channel: level (dB) = the peak envelope (instant
    attack, exponential release) smoothed by the attack time constant; computed on
    blocks of `COMPRESSOR_BLOCK` samples (0.36 ms at 44.1 kHz, ten times shorter than
    the attack)."""
    n = x.shape[0]
    blocks = -(-n // COMPRESSOR_BLOCK)
    padded = np.zeros((blocks * COMPRESSOR_BLOCK, x.shape[1]), dtype=np.float32)
    padded[:n] = np.abs(x)
    block_peak = padded.reshape(blocks, COMPRESSOR_BLOCK, -1).max(axis=1).astype(float)
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
    # Each block's gain for its samples: the level is smoothed over the attack (ten
    # blocks and more), so the steps between blocks are small.
    gain = np.repeat((10 ** (gain_db / 20)).astype(np.float32), COMPRESSOR_BLOCK, axis=0)[:n]
    return x * gain

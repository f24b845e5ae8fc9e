"""Each impact's sound, as numbers: the features by which `sounds` tells metronomes apart.

Contract: `impact_features(recording, times)` reads the few milliseconds after each
impact onset (K,) and returns `Features`, whose `matrix()` is (K, D).

The power spectrum of the first `FEATURE_LENGTH` of sound after the onset (tapered),
less that of as long just before it (the ringing of an earlier tick, which goes on),
is cut into `BANDS` bands spaced evenly in log frequency from `LOW_EDGE` to 16 kHz (or
0.45 × the rate); the feature is each band's level in dB (at least `BAND_RANGE` below
the loudest band: fainter bands hold noise) minus the mean over the bands: the
spectral shape, whatever the loudness. Two metronomes of different makes differ there
more than in loudness, and a microphone, a room or a phone's filter colours every tick
alike. The loudness itself (dB, weighted by `LEVEL_WEIGHT`) and, with several
channels, each channel's level minus their mean (dB: where the metronome stands
relative to the microphones) are added.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft, signal

from .detection import _segments
from .reader import Recording

FEATURE_LENGTH = 6e-3
#: Sound kept before the onset, s (the onset is timed to a fraction of a sample).
FEATURE_LEAD = 0.3e-3
BANDS = 16
LOW_EDGE = 500.0
HIGH_EDGE = 16000.0
LEVEL_WEIGHT = 0.5
#: Band levels, and a microphone's level of an onset, are counted down to this far (dB)
#: below the loudest band or microphone.
BAND_RANGE = 30.0
#: Smallest spread a metronome's sound is credited with, per feature, dB (`sounds`):
#: identical clicks vary by less, and must not be told apart by their rounding.
SPREAD_FLOOR = 1.0


@dataclass(frozen=True)
class Features:
    """What each impact sounds like.

    shape : (K, B) band levels minus their mean, dB.
    level : (K,) loudness over the bands, dB.
    channel_level : (K, C) each channel's level minus the channels' mean, dB.
    """

    shape: np.ndarray
    level: np.ndarray
    channel_level: np.ndarray

    def matrix(self) -> np.ndarray:
        """(K, D) the vectors clustered: shape, weighted loudness, channel balance."""
        parts = [self.shape, LEVEL_WEIGHT * (self.level - np.median(self.level))[:, None]]
        if self.channel_level.shape[1] > 1:
            parts.append(self.channel_level)
        return np.column_stack(parts)


def _bands(rate: int, nfft: int) -> np.ndarray:
    """(BANDS, nfft//2 + 1) 0/1 matrix summing the power spectrum into bands."""
    top = min(HIGH_EDGE, 0.45 * rate)
    edges = np.geomspace(min(LOW_EDGE, top / 4), top, BANDS + 1)
    freqs = np.fft.rfftfreq(nfft, 1.0 / rate)
    which = np.searchsorted(edges, freqs, side="right") - 1
    m = np.zeros((BANDS, freqs.size))
    inside = (which >= 0) & (which < BANDS)
    m[which[inside], np.flatnonzero(inside)] = 1.0
    return m


def impact_features(recording: Recording, times: np.ndarray, *, chunk: int = 4096) -> Features:
    """`Features` of the impacts at ``times`` (K,), s, sorted (see the module docstring)."""
    rate = recording.sample_rate
    lead = round(FEATURE_LEAD * rate)
    length = lead + round(FEATURE_LENGTH * rate)
    nfft = fft.next_fast_len(max(1024, 2 * length))
    taper = signal.windows.tukey(length, 0.3).astype(np.float32)
    bands = _bands(rate, nfft)
    # the same length before the onset too: what was already sounding is taken off
    starts = np.round(np.asarray(times) * rate).astype(np.int64) - lead - length
    k, c = starts.size, recording.channels
    shape = np.empty((k, BANDS))
    level = np.empty(k)
    channel = np.zeros((k, c))
    if k == 0:
        return Features(shape, level, channel)
    for first, seg in _segments(recording, starts, 2 * length, chunk):
        sl = slice(first, first + seg.shape[0])
        power = []
        for part in (seg[:, :length], seg[:, length:]):
            spectra = np.abs(fft.rfft(part * taper[None, :, None], n=nfft, axis=1)) ** 2
            power.append(np.einsum("bf,nfc->nbc", bands, spectra))
        before, after = power
        per_channel = np.maximum(after - before, 1e-3 * after) + 1e-14
        mixed = 10 * np.log10(per_channel.mean(axis=2))
        # bands far below the loudest hold noise and the rounding of the onset
        mixed = np.maximum(mixed, mixed.max(axis=1, keepdims=True) - BAND_RANGE)
        level[sl] = 10 * np.log10(per_channel.sum(axis=1).mean(axis=1))
        shape[sl] = mixed - mixed.mean(axis=1, keepdims=True)
        if c > 1:
            total = 10 * np.log10(per_channel.sum(axis=1))
            # a microphone that hears the onset far below the loudest hears only what
            # else sounds there: its level is counted down to `BAND_RANGE`, as a band's
            total = np.maximum(total, total.max(axis=1, keepdims=True) - BAND_RANGE)
            channel[sl] = total - total.mean(axis=1, keepdims=True)
    return Features(shape, level, channel)



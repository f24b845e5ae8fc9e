"""Click-track recordings: short clicks at known times, for tests of the detector.

The simplest synthetic recording, where the truth is exact by construction:

- ``metronome_train(bpm, duration, *, phase, asymmetry, jitter, rng)``: tick times (s)
  of one metronome, beats alternating (1 ± asymmetry/2)·T, with optional white jitter;
- ``render(trains, duration, *, rate, gains, pitches, pans)``: (S, C) samples, one
  click (`metrosync.synthetic.ticks.click_waveform`: a 6 ms decaying cosine burst)
  at the nearest sample to each time, mono or panned in stereo;
- ``add_noise``, ``add_reverb``: white noise at an SNR measured while the clicks sound,
  and an exponentially decaying noise tail (a room);
- ``write(path, samples)``: a 16-bit WAV.

Recordings as a phone hears real metronomes are `metrosync.synthetic.recording`'s.
"""

from __future__ import annotations

import numpy as np
import soundfile as sf
from scipy import signal

from .ticks import click_waveform

RATE = 44100


def render(trains, duration, *, rate=RATE, gains=None, pitches=None, pans=None):
    """(S, C) clicks at the onset times of each train (list of arrays, s); mono when
    ``pans`` is None, else stereo with a constant-power pan per train in [-1, 1]."""
    n = len(trains)
    gains = [0.9 / n] * n if gains is None else gains
    pitches = np.linspace(1800, 2600, n) if pitches is None else pitches
    channels = 1 if pans is None else 2
    out = np.zeros((int(round(duration * rate)), channels))
    for i, times in enumerate(trains):
        click = gains[i] * click_waveform(pitches[i], rate)
        if pans is None:
            weights = [1.0]
        else:
            angle = (pans[i] + 1) * np.pi / 4
            weights = [np.cos(angle), np.sin(angle)]
        onset = np.round(np.asarray(times) * rate).astype(np.int64)
        index = onset[:, None] + np.arange(click.size)[None, :]
        inside = index < out.shape[0]
        for c, w in enumerate(weights):
            np.add.at(out[:, c], index[inside], np.broadcast_to(w * click, index.shape)[inside])
    return out


def metronome_train(bpm, duration, *, phase=0.0, asymmetry=0.0, jitter=0.0, rng=None):
    """Tick times of one metronome: beats alternate (1 ± asymmetry/2)·T, where
    asymmetry is the fraction of a beat by which the long beat exceeds the short one;
    white period jitter (s) optional."""
    period = 60.0 / bpm
    count = int(duration / period) + 2
    beats = np.where(np.arange(count) % 2 == 0, 1 + asymmetry / 2, 1 - asymmetry / 2) * period
    if jitter:
        beats = beats + rng.normal(0, jitter, count)
    times = phase * period + np.concatenate([[0.0], np.cumsum(beats)])
    return times[(times >= 0) & (times < duration - 0.01)]


def click_power(samples, trains, rate=RATE, length=0.006):
    """Mean power of the samples while the clicks sound (the first ``length`` s of each)."""
    onsets = np.round(np.concatenate(trains) * rate).astype(np.int64)
    index = (onsets[:, None] + np.arange(int(length * rate))[None, :]).ravel()
    index = index[index < samples.shape[0]]
    return float(np.mean(samples[index] ** 2))


def add_noise(samples, snr_db, trains, rng, rate=RATE):
    """White noise whose power is ``snr_db`` below the clicks' power while they sound."""
    power = click_power(samples, trains, rate) / 10 ** (snr_db / 10)
    noisy = samples + rng.normal(0.0, np.sqrt(power), samples.shape)
    return noisy / max(1.0, np.abs(noisy).max() / 0.95)  # scaled, never clipped


def add_reverb(samples, rng, rate=RATE, rt60=0.5, drr_db=0.0):
    """The direct sound plus an exponentially decaying noise tail (reverberation time
    ``rt60``, s) with ``drr_db`` dB less energy than the direct sound."""
    n = int(rt60 * rate)
    t = np.arange(n) / rate
    tail = rng.normal(0, 1, n) * 10 ** (-3 * t / rt60)
    tail[: int(0.002 * rate)] = 0.0  # the first reflections arrive after 2 ms
    tail *= np.sqrt(10 ** (-drr_db / 10) / np.sum(tail**2))
    ir = np.concatenate([[1.0], tail[1:]])
    wet = signal.oaconvolve(samples, ir[:, None], axes=0)[: samples.shape[0]]
    return wet / max(1.0, np.abs(wet).max() / 0.95)


def write(path, samples, rate=RATE, subtype="PCM_16"):
    sf.write(str(path), samples, rate, subtype=subtype)
    return path

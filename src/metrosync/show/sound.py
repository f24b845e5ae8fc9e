"""Hear a run: a stereo WAV with one click per metronome at each zero crossing of θ.

A real metronome ticks when its escapement releases, i.e. when the pendulum passes
through the vertical, in both directions. So every zero crossing of θ_i, up or down,
becomes one short click of metronome i, and the ticks audibly come together as r
rises.

Crossing times come from the recorded trajectory. When every integration step was
recorded they are found exactly as the integrator finds them: the sign of θ changes
between two steps, and the time is interpolated linearly between them. With sparser
records the crossing is the root of the cubic Hermite interpolant built from θ and θ̇.

Each click starts at sample round(τ·rate), τ = (t − start)/speedup being its time in
the audio, so it is within half a sample of the crossing. Metronome i is panned by
its x position R cos(α_i + φ) on the disk seen from above (constant-power pan), and
has a pitch of its own so that the ear can tell them apart. Each click has the gain
0.9/N, so the file never clips and a synchronized ensemble sounds louder, as it does
in the room.
"""

from __future__ import annotations

import math
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..errors import ParameterError
from .recording import RecordedRun

#: Click length and decay time, s.
CLICK_LENGTH = 0.006
CLICK_DECAY = 0.001
#: Pitches (Hz) of the clicks span this range across the metronomes.
PITCH_RANGE = (1800.0, 2600.0)


@dataclass(frozen=True)
class ClickTrack:
    """A rendered click track.

    samples : (S, 2) float in [−1, 1], left and right channels.
    sample_rate : samples per second.
    click_times : N arrays of click onsets in audio time, s (the crossing times
        mapped through (t − start)/speedup).
    start, end, speedup : the simulated window [start, end] (s) and the speed-up.
    """

    samples: np.ndarray
    sample_rate: int
    click_times: list[np.ndarray]
    start: float
    end: float
    speedup: float

    @property
    def duration(self) -> float:
        """Length of the audio, s."""
        return self.samples.shape[0] / self.sample_rate

    def write(self, path: Path | str) -> Path:
        """Write a 16-bit PCM stereo WAV atomically; returns the path."""
        path = Path(path)
        pcm = np.round(np.clip(self.samples, -1.0, 1.0) * 32767).astype("<i2")
        with atomic_path(path) as tmp, wave.open(str(tmp), "wb") as out:
            out.setnchannels(2)
            out.setsampwidth(2)
            out.setframerate(self.sample_rate)
            out.writeframes(pcm.tobytes())
        return path


def crossing_times(run: RecordedRun) -> list[np.ndarray]:
    """Times (s) of every zero crossing of each θ_i, both directions.

    Returns N increasing arrays. A crossing is a sign change from strictly negative
    to strictly positive or back between consecutive records, as in the integrator.
    """
    t = run.time
    out = []
    for i in range(run.n):
        y = run.theta[:, i]
        k = np.flatnonzero(((y[:-1] < 0) & (y[1:] > 0)) | ((y[:-1] > 0) & (y[1:] < 0)))
        h = t[k + 1] - t[k]
        if run.every_step:
            s = y[k] / (y[k] - y[k + 1])
        else:
            s = _hermite_root(y[k], run.theta_dot[k, i] * h, y[k + 1], run.theta_dot[k + 1, i] * h)
        out.append(t[k] + s * h)
    return out


def _hermite_root(y0, d0, y1, d1, iterations: int = 52) -> np.ndarray:
    """Root in [0, 1] of the cubic Hermite polynomial with y(0)=y0, y(1)=y1,
    y'(0)=d0, y'(1)=d1, where y0 and y1 have opposite signs (bisection: robust even
    when the cubic is not monotone)."""

    def value(s):
        s2, s3 = s * s, s * s * s
        return (
            (2 * s3 - 3 * s2 + 1) * y0
            + (s3 - 2 * s2 + s) * d0
            + (-2 * s3 + 3 * s2) * y1
            + (s3 - s2) * d1
        )

    lo = np.zeros_like(y0)
    hi = np.ones_like(y0)
    sign0 = np.sign(y0)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        same = np.sign(value(mid)) == sign0
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


def click_waveform(pitch: float, sample_rate: int) -> np.ndarray:
    """(L,) one click: a decaying cosine burst whose first sample is its peak, 1."""
    u = np.arange(int(round(CLICK_LENGTH * sample_rate))) / sample_rate
    taper = np.cos(0.5 * np.pi * u / CLICK_LENGTH) ** 2
    return np.exp(-u / CLICK_DECAY) * np.cos(2 * np.pi * pitch * u) * taper


def pan_gains(pan) -> tuple[np.ndarray, np.ndarray]:
    """Constant-power gains (left, right) for pan in [−1 (left), 1 (right)]."""
    angle = (np.clip(pan, -1.0, 1.0) + 1.0) * np.pi / 4
    return np.cos(angle), np.sin(angle)


def click_track(
    run: RecordedRun,
    *,
    speedup: float = 1.0,
    start: float | None = None,
    end: float | None = None,
    sample_rate: int = 44100,
) -> ClickTrack:
    """Render the clicks of a recorded run between ``start`` and ``end`` (s).

    The audio lasts round((end − start)/speedup · sample_rate) samples.
    """
    if not (isinstance(speedup, int | float) and math.isfinite(speedup) and speedup > 0):
        raise ParameterError(f"`speedup` must be a number > 0, got {speedup!r}.")
    if (
        isinstance(sample_rate, bool)
        or not isinstance(sample_rate, int | np.integer)
        or not (8000 <= sample_rate <= 192000)
    ):
        raise ParameterError(
            f"`sample_rate` must be an integer in [8000, 192000] Hz, got {sample_rate!r}."
        )
    start, end = run.window(start, end)
    n_samples = int(round((end - start) / speedup * sample_rate))
    samples = np.zeros((n_samples, 2))
    gain = 0.9 / run.n
    pitches = np.linspace(*PITCH_RANGE, run.n) if run.n > 1 else [PITCH_RANGE[0]]
    audio_times = []
    for i, times in enumerate(crossing_times(run)):
        times = times[(times >= start) & (times < end)]
        tau = (times - start) / speedup
        audio_times.append(tau)
        onset = np.round(tau * sample_rate).astype(np.int64)
        click = click_waveform(pitches[i], sample_rate)
        left, right = pan_gains(np.cos(run.rim_angles[i] + run.phi_at(times)))
        index = onset[:, None] + np.arange(click.size)[None, :]
        inside = index < n_samples
        np.add.at(samples[:, 0], index[inside], (gain * left[:, None] * click)[inside])
        np.add.at(samples[:, 1], index[inside], (gain * right[:, None] * click)[inside])
    return ClickTrack(samples, int(sample_rate), audio_times, start, end, float(speedup))


def write_wav(ds, path: Path | str, *, run: int = 0, **options) -> ClickTrack:
    """Write the click track of run ``run`` of ``ds`` to a WAV file.

    ``options`` are those of `click_track` (speedup, start, end, sample_rate).
    Returns the track, whose ``click_times`` say when each click sounds.
    """
    track = click_track(RecordedRun.from_dataset(ds, run), **options)
    track.write(path)
    return track

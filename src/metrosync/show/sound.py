"""Hear a run: a stereo WAV with one click per metronome each time θ passes the angle
where its escapement acts.

A real metronome ticks when its escapement releases, i.e. when the pendulum passes
through the vertical, in both directions, or through the angle δ_i of a metronome out
of beat (the model's ``escapement_offset``; tick and tock then come unevenly). So every
crossing of θ_i through δ_i, up or down, becomes one short click of metronome i, and
the ticks audibly come together as r rises.

Crossing times come from the recorded trajectory. When every integration step was
recorded they are found exactly as the integrator finds them: the sign of θ changes
between two steps, and the time is interpolated linearly between them. With sparser
records the crossing is the root of the cubic Hermite interpolant built from θ and θ̇.

Each click starts at sample round(τ·rate), τ = (t − start)/speedup being its time in
the audio, so it is within half a sample of the crossing. Metronome i is panned by
its x position R cos(α_i + φ) on the disk seen from above, or by its place in the row
on a board, left to right (constant-power pan, `RecordedRun.stereo_position`), and
has a pitch of its own so that the ear can tell them apart. Each click has the gain
0.9/N, so the file never clips and a synchronized ensemble sounds louder, as it does
in the room.

Two tick sounds (``tick_sound``, see `TICK_SOUNDS`), both from
`metrosync.synthetic.ticks`: ``"click"``, a 6 ms decaying cosine burst
(`click_waveform`), and ``"realistic"``, the tick of a real metronome (a `Voice`): a
main impact, secondary impacts 15–35 ms later and a ring of about 80 ms through
resonances of its own (metronome i gets voice i of ``voices(N)``). A realistic tick
starts at the crossing; an upward crossing sounds a tick, a downward one the tock,
which sounds different and softer. Its gain is 0.9/N over a bound on one metronome's
loudest sum (its ticks overlap when sped up: the k-th latest began at least k times the
shortest interval ago and adds at most its waveform's largest value from then on), so
the file never clips either.

The audio is rendered and written in blocks of `BLOCK_SAMPLES`, so memory does not
depend on its length. Refused before any sample is made: a speed-up that brings a
metronome's ticks closer together than one click (they would merge into a tone), a
window shorter than one tick, and audio longer than an hour.
"""

from __future__ import annotations

import math
import wave
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import interrupts
from .._files import atomic_path
from ..budget import Budget, format_seconds
from ..errors import ParameterError
from ..synthetic.ticks import CLICK_LENGTH, check_sample_rate, click_waveform, voices
from .recording import RecordedRun

#: Pitches (Hz) of the clicks span this range across the metronomes.
PITCH_RANGE = (1800.0, 2600.0)
#: Samples rendered and written at a time: memory does not grow with the length.
BLOCK_SAMPLES = 1 << 16
#: Longest audio written, s.
MAX_AUDIO_SECONDS = 3600.0
#: The tick sounds `click_track` knows.
TICK_SOUNDS = ("click", "realistic")


@dataclass(frozen=True)
class ClickTrack:
    """A click track: where each click sounds, rendered to samples block by block.

    sample_rate : samples per second.   n_samples : length of the audio.
    click_times : N arrays of click onsets in audio time, s (the crossing times
        mapped through (t − start)/speedup).
    onsets : N arrays of the clicks' first samples, round(click_time · sample_rate).
    gains : N arrays (K_i, 2) of each click's left and right gain.
    waveforms : N arrays, the click of each metronome.
    start, end, speedup : the simulated window [start, end] (s) and the speed-up.
    tock_waveforms : N arrays, the tock of each metronome, or None when tick and tock
        sound alike (then ``waveforms`` sounds at every crossing).
    is_tock : N (K_i,) bool arrays, which clicks are tocks (downward crossings), or
        None when ``tock_waveforms`` is.
    """

    sample_rate: int
    n_samples: int
    click_times: list[np.ndarray]
    onsets: list[np.ndarray]
    gains: list[np.ndarray]
    waveforms: list[np.ndarray]
    start: float
    end: float
    speedup: float
    tock_waveforms: list[np.ndarray] | None = None
    is_tock: list[np.ndarray] | None = None

    @property
    def duration(self) -> float:
        """Length of the audio, s."""
        return self.n_samples / self.sample_rate

    def blocks(self, size: int = BLOCK_SAMPLES) -> Iterator[np.ndarray]:
        """The audio as consecutive (≤ size, 2) float blocks in [−1, 1] (left, right)."""
        for first in range(0, self.n_samples, size):
            interrupts.check()
            yield self._render(first, min(first + size, self.n_samples))

    @property
    def samples(self) -> np.ndarray:
        """(S, 2) the whole audio in memory (for inspection; `write` streams it)."""
        parts = list(self.blocks())
        return np.concatenate(parts) if parts else np.zeros((0, 2))

    def _render(self, first: int, stop: int) -> np.ndarray:
        block = np.zeros((stop - first, 2))
        for i, (onset, gain) in enumerate(zip(self.onsets, self.gains, strict=True)):
            if self.tock_waveforms is None:
                _add_clicks(block, first, onset, gain, self.waveforms[i])
                continue
            tock = self.is_tock[i]
            _add_clicks(block, first, onset[~tock], gain[~tock], self.waveforms[i])
            _add_clicks(block, first, onset[tock], gain[tock], self.tock_waveforms[i])
        return block

    def write(self, path: Path | str) -> Path:
        """Write a 16-bit PCM stereo WAV atomically, block by block; returns the path."""
        path = Path(path)
        with atomic_path(path) as tmp, wave.open(str(tmp), "wb") as out:
            out.setnchannels(2)
            out.setsampwidth(2)
            out.setframerate(self.sample_rate)
            for block in self.blocks():
                pcm = np.round(np.clip(block, -1.0, 1.0) * 32767).astype("<i2")
                out.writeframes(pcm.tobytes())
        return path


def _add_clicks(block, first: int, onset, gain, click) -> None:
    """Add to ``block`` (audio from sample ``first`` on) the clicks that start at
    ``onset`` (K,) with gains ``gain`` (K, 2) and sound in it."""
    stop = first + block.shape[0]
    # The clicks that sound in [first, stop): onsets from first − len + 1 on.
    lo, hi = np.searchsorted(onset, [first - click.size + 1, stop])
    if lo == hi:
        return
    index = onset[lo:hi, None] + np.arange(click.size)[None, :] - first
    inside = (index >= 0) & (index < stop - first)
    for channel in (0, 1):
        values = gain[lo:hi, channel, None] * click
        np.add.at(block[:, channel], index[inside], values[inside])


def crossing_times(run: RecordedRun) -> list[np.ndarray]:
    """Times (s) at which each θ_i crosses its tick angle δ_i (`RecordedRun.tick_angles`,
    0 unless the metronome is out of beat), both directions.

    Returns N increasing arrays. A crossing is a sign change of θ_i − δ_i from strictly
    negative to strictly positive or back between consecutive records, as in the
    integrator.
    """
    t = run.time
    out = []
    for i, angle in enumerate(run.tick_angles):
        y = run.theta[:, i] - angle
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
    tick_sound: str = "click",
) -> ClickTrack:
    """The clicks of a recorded run between ``start`` and ``end`` (s).

    The audio lasts round((end − start)/speedup · sample_rate) samples. ``tick_sound``
    is one of `TICK_SOUNDS` (see the module docstring). Refused: a ``speedup`` that
    brings a metronome's ticks closer than one click (they would merge into a tone), a
    window shorter than one tick of the slowest metronome, and audio longer than
    `MAX_AUDIO_SECONDS`.
    """
    if tick_sound not in TICK_SOUNDS:
        raise ParameterError(
            f"`tick_sound` must be one of {', '.join(map(repr, TICK_SOUNDS))}, got {tick_sound!r}."
        )
    check_sound(speedup, sample_rate)
    start, end = run.window(start, end)
    bpm = 60.0 * np.asarray(run.omega) / np.pi
    check_length(speedup, start, end, fastest_bpm=float(bpm.max()), slowest_bpm=float(bpm.min()))
    n_samples = int(round((end - start) / speedup * sample_rate))
    budget = Budget(
        "the sound",
        {"one block of samples": 16.0 * BLOCK_SAMPLES, "click onsets": 48.0 * run.theta.size},
        seconds=n_samples * 5e-8 + run.theta.size * 1e-7,
    )
    budget.check()
    gain = 0.9 / run.n
    pitches = np.linspace(*PITCH_RANGE, run.n) if run.n > 1 else [PITCH_RANGE[0]]
    audio_times, onsets, gains, waveforms, is_tock = [], [], [], [], []
    for i, times in enumerate(crossing_times(run)):
        times = times[(times >= start) & (times < end)]
        tau = (times - start) / speedup
        audio_times.append(tau)
        onsets.append(np.round(tau * sample_rate).astype(np.int64))
        left, right = pan_gains(run.stereo_position(i, times))
        gains.append(gain * np.column_stack([left, right]))
        waveforms.append(click_waveform(pitches[i], sample_rate))
        if tick_sound == "realistic":
            is_tock.append(run.theta_dot_at(times)[:, i] < 0)
    tock_waveforms = None
    if tick_sound == "realistic":
        sounds = voices(run.n)
        waveforms = [v.waveform(sample_rate) for v in sounds]
        tock_waveforms = [v.waveform(sample_rate, tock=True) for v in sounds]
        # When sped up, a tick still rings as the next ones start.
        shortest = min((np.diff(k).min() for k in onsets if k.size > 1), default=np.inf)
        loudest = max(_overlap_peak(w, shortest) for w in waveforms + tock_waveforms)
        gains = [g / loudest for g in gains]
    return ClickTrack(
        int(sample_rate), n_samples, audio_times, onsets, gains, waveforms, start, end,
        float(speedup), tock_waveforms, is_tock or None,
    )  # fmt: skip


def _overlap_peak(wave: np.ndarray, spacing: float) -> float:
    """A bound on |sum of copies of ``wave``| when they start at least ``spacing``
    samples apart: the k-th latest copy began ≥ k·spacing samples ago, so it adds at
    most the largest |wave| from there on."""
    tail = np.maximum.accumulate(np.abs(wave)[::-1])[::-1]
    if not np.isfinite(spacing):
        return float(tail[0])
    step = max(int(spacing), 1)
    return float(tail[::step].sum())


def check_sound(speedup: float, sample_rate: int) -> None:
    """Refuse a ``speedup`` or ``sample_rate`` no click track can have (made before
    simulating, too)."""
    if not (isinstance(speedup, int | float) and math.isfinite(speedup) and speedup > 0):
        raise ParameterError(f"`speedup` must be a number > 0, got {speedup!r}.")
    check_sample_rate(sample_rate)


def _milliseconds(seconds: float) -> str:
    return f"{seconds * 1e3:.3g} ms" if seconds >= 1e-3 else f"{seconds * 1e6:.3g} µs"


def check_length(
    speedup: float, start: float, end: float, *, fastest_bpm: float, slowest_bpm: float
) -> None:
    """Refuse audio whose ticks merge, that holds no tick, or that lasts for hours.

    speedup : the speed-up.   start, end : the simulated window, s.
    fastest_bpm, slowest_bpm : the metronomes' extreme natural frequencies, BPM.
    """
    tick_fast = 60.0 / fastest_bpm  # ω = π·BPM/60 and two ticks a period
    tick_slow = 60.0 / slowest_bpm
    fastest = tick_fast / CLICK_LENGTH
    if speedup > fastest:
        raise ParameterError(
            f"`speedup` = {speedup:g} brings a metronome's ticks "
            f"{_milliseconds(tick_fast / speedup)} apart in the audio, closer than one click "
            f"({CLICK_LENGTH * 1e3:g} ms): they "
            f"would merge into a tone. Use a `speedup` of at most {math.floor(fastest)}."
        )
    if end - start < tick_slow:
        raise ParameterError(
            f"the window [{start:g}, {end:g}] s is shorter than one tick period "
            f"({tick_slow:.3g} s): the audio would hold at most one click per metronome. "
            f"Widen it (`start`, `end`) or simulate a longer `duration`."
        )
    seconds = (end - start) / speedup
    if seconds > MAX_AUDIO_SECONDS:
        raise ParameterError(
            f"`speedup` = {speedup:g} makes {end - start:g} s of simulation last "
            f"{format_seconds(seconds)} of audio, more than {MAX_AUDIO_SECONDS / 3600:g} h; "
            f"use a `speedup` of at least {(end - start) / MAX_AUDIO_SECONDS:.3g}, or a "
            f"shorter window (`start`, `end`)."
        )


def write_wav(ds, path: Path | str, *, run: int = 0, **options) -> ClickTrack:
    """Write the click track of run ``run`` of ``ds`` to a WAV file.

    ``options`` are those of `click_track` (speedup, start, end, sample_rate,
    tick_sound).
    Returns the track, whose ``click_times`` say when each click sounds.
    """
    track = click_track(RecordedRun.from_dataset(ds, run), **options)
    track.write(path)
    return track

"""Picture and sound together: the video's audio track timed against its rods.

Contract: `sound_check(path, passes)` decodes the audio track of the video at ``path``
(PyAV), writes it to a temporary WAV, analyses it with `metrosync.audio`'s tick
detector (`analyze_audio`), puts the ticks on the picture's clock (the audio stream's
start time against the first frame's), and compares them with the rods' passes
through the vertical (both directions: a metronome ticks at each). It returns a
`SoundCheck`: the ticks heard, the offset of each from the nearest pass, the median
offset that puts most ticks on a pass (the sound's latency plus where in the swing the
escapement ticks; searched within ±`MAX_LATENCY`), and whether
picture and sound agree: most ticks fall within `TOLERANCE` of that offset.
"""

from __future__ import annotations

import contextlib
import tempfile
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._words import plural
from ..errors import MetrosyncError

#: Largest spread of a tick about the median offset for it to agree with a pass, s.
TOLERANCE = 0.015
#: Largest delay of the sound behind the picture (either way) that is looked for, s.
MAX_LATENCY = 0.2
#: Fraction of the ticks that must agree for picture and sound to agree.
AGREEMENT = 0.8


@dataclass(frozen=True)
class SoundCheck:
    """The audio track against the picture.

    tick_time : (K,) ticks heard, s on the picture's clock.
    offset : (K,) each tick minus its nearest pass, s.
    latency : median offset, s (positive: the tick is heard after the pass).
    agreeing : fraction of ticks within `TOLERANCE` of the latency.
    passes_heard : fraction of the passes with a tick within `TOLERANCE` of latency.
    """

    tick_time: np.ndarray
    offset: np.ndarray
    latency: float
    agreeing: float
    passes_heard: float

    @property
    def agree(self) -> bool:
        return self.agreeing >= AGREEMENT

    def sentence(self) -> str:
        verdict = "agree" if self.agree else "DISAGREE"
        return (
            f"{plural(self.tick_time.size, 'tick')} heard; picture and sound {verdict}: "
            f"{self.agreeing * 100:.0f}% of the ticks fall within {TOLERANCE * 1e3:.0f} ms "
            f"of a pass, {self.passes_heard * 100:.0f}% of the passes are heard; the ticks "
            f"come {self.latency * 1e3:+.1f} ms after the passes (sound latency and "
            f"escapement)"
        )


def _extract(path: Path, wav: Path) -> float:
    """Write the first audio track of ``path`` to ``wav`` (mono float); returns its start
    on the picture's clock (audio start − first video frame's time), s."""
    import av
    import soundfile

    with av.open(str(path)) as container:
        video, audio = container.streams.video[0], container.streams.audio[0]
        rate = audio.codec_context.sample_rate or audio.rate
        resampler = av.AudioResampler(format="flt", layout="mono", rate=rate)
        start = None
        with soundfile.SoundFile(wav, "w", samplerate=rate, channels=1,
                                 subtype="FLOAT") as out:  # fmt: skip
            for frame in container.decode(audio):
                if start is None and frame.pts is not None:
                    start = float(frame.pts * frame.time_base)
                for piece in resampler.resample(frame):
                    out.write(piece.to_ndarray().reshape(-1))
            for piece in resampler.resample(None):
                out.write(piece.to_ndarray().reshape(-1))
        container.seek(0)
        first = next(container.decode(video), None)
        v0 = float(first.pts * first.time_base) if first is not None and first.pts else 0.0
    return (start or 0.0) - v0


def sound_check(path: str | Path, passes: list[np.ndarray]) -> SoundCheck:
    """The video's audio track against the passes (each metronome's, both directions).

    Raises `MetrosyncError` when the track cannot be decoded or gives no ticks; it, and
    every warning of the analysis, names the video's sound track, not the temporary WAV
    it was analysed from.
    """
    from ..audio import analyze_audio

    every = np.sort(np.concatenate([np.asarray(p, dtype=float) for p in passes]))
    name = f"the sound track of {Path(path).name}"
    with tempfile.TemporaryDirectory() as folder:
        wav = Path(folder) / "track.wav"
        import av

        try:
            shift = _extract(Path(path), wav)
        except (av.error.FFmpegError, RuntimeError, ValueError) as error:
            raise MetrosyncError(f"{name} cannot be decoded ({error}).") from None
        with _speaking_of(wav, name):
            heard = analyze_audio(wav)
    ticks = heard.tick_time.values + shift
    if ticks.size == 0 or every.size == 0:
        return SoundCheck(ticks, np.full(ticks.size, np.nan), float("nan"), 0.0, 0.0)
    latency = _latency(ticks, every)
    offset = ticks - _nearest(every, ticks - latency)
    agreeing = float(np.mean(np.abs(offset - latency) <= TOLERANCE))
    gap = np.abs(every - _nearest(ticks - latency, every))
    return SoundCheck(ticks, offset, latency, agreeing, float(np.mean(gap <= TOLERANCE)))


@contextlib.contextmanager
def _speaking_of(wav: Path, name: str) -> Iterator[None]:
    """Say ``name`` wherever the audio analysis inside names the file ``wav`` (its
    errors and warnings): the user gave a video, and the WAV is gone once it returns."""

    def renamed(text: str) -> str:
        for said in (f"recording {str(wav)!r}", repr(str(wav)), str(wav)):
            text = text.replace(said, name)
        return text

    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield
    except MetrosyncError as error:
        raise MetrosyncError(renamed(str(error))) from None
    finally:
        for warning in caught:
            warnings.warn(renamed(str(warning.message)), warning.category, stacklevel=3)


def _nearest(sorted_times: np.ndarray, times: np.ndarray) -> np.ndarray:
    """For each of ``times``, the nearest of ``sorted_times``."""
    k = np.clip(np.searchsorted(sorted_times, times), 1, max(sorted_times.size - 1, 1))
    before, after = sorted_times[k - 1], sorted_times[np.minimum(k, sorted_times.size - 1)]
    return np.where(np.abs(times - before) <= np.abs(times - after), before, after)


def _latency(ticks: np.ndarray, passes: np.ndarray) -> float:
    """The delay that puts most ticks on a pass: with several metronomes a tick's nearest
    pass may be another's, so every delay in ±`MAX_LATENCY` is tried (1 ms steps), and
    the best refined as the median offset of the ticks it matches."""
    trials = np.arange(-MAX_LATENCY, MAX_LATENCY + 1e-9, 1e-3)
    hits = [np.sum(np.abs(ticks - d - _nearest(passes, ticks - d)) <= 0.25 * TOLERANCE)
            for d in trials]  # fmt: skip
    best = float(trials[int(np.argmax(hits))])
    offset = ticks - _nearest(passes, ticks - best)
    close = np.abs(offset - best) <= 0.5 * TOLERANCE
    return float(np.median(offset[close])) if close.any() else best

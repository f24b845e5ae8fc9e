"""Several recordings made together (one phone per microphone), aligned into one.

Contract: `record_together(paths)` opens each file (`reader.open_recording`), finds
how much later each one started than the first, and returns a `Together`: a recording
with the files' channels side by side on the first file's time line, read like any
`reader.Recording` (`blocks`, `segment`), so that the analysis sees one multichannel
recording and tells the metronomes apart by their level at each microphone as well as
by their sound.

Alignment. Each file's detection curve (`detection.scan`: the rise of its band power,
every 0.5 ms) is clipped at 0 dB and cross-correlated with the first file's (FFT);
the lag of the highest peak within `MAX_OFFSET` is the coarse offset. It is refined to
a sample by cross-correlating the band-passed waveforms over `REFINE_SPAN` around the
loudest stretch, within ±2 hops of it. Files whose curves correlate less than
`MIN_LIKENESS` at the best offset draw a warning: they hardly sound recorded together.
The files must share a sample rate. Frames of a file before its start or after its
end read as silence.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import fft, signal

from . import detection as det
from .reader import BLOCK_FRAMES, AudioFileError, Recording, open_recording

#: Largest start difference searched, s.
MAX_OFFSET = 60.0
#: Below this correlation of the detection curves at the best offset, the files are
#: said not to match.
MIN_LIKENESS = 0.2
#: Stretch of waveform used to refine the offset to a sample, s.
REFINE_SPAN = 10.0


@dataclass(frozen=True)
class Together:
    """Recordings aligned on the first one's time line; reads like a `Recording`.

    parts : the files. offsets : (F,) frames by which each started later than the first
    (negative: earlier). path, sample_rate, channels, frames, format, subtype: as a
    `Recording` (``path`` is the first file; ``channels`` counts every file's).
    """

    parts: tuple
    offsets: np.ndarray
    path: Path
    sample_rate: int
    channels: int
    frames: int
    format: str
    subtype: str
    names: tuple = field(default=())

    @property
    def duration(self) -> float:
        return self.frames / self.sample_rate

    def segment(self, start: int, stop: int) -> np.ndarray:
        """Frames [start, stop) of every channel, zeros outside each file."""
        pairs = zip(self.parts, self.offsets, strict=True)
        out = [p.segment(start - int(o), stop - int(o)) for p, o in pairs]
        return np.concatenate(out, axis=1)

    def segments(self, starts: np.ndarray, length: int) -> np.ndarray:
        """(n, length, channels): `segment` at each of ``starts``, each file opened once."""
        pairs = zip(self.parts, self.offsets, strict=True)
        out = [p.segments(np.asarray(starts) - int(o), length) for p, o in pairs]
        return np.concatenate(out, axis=2)

    def blocks(self, block_frames: int = BLOCK_FRAMES) -> Iterator[tuple[int, np.ndarray]]:
        for start in range(0, self.frames, block_frames):
            yield start, self.segment(start, min(self.frames, start + block_frames))


def record_together(paths: Sequence[str | Path], *, band=det.DEFAULT_BAND) -> Together:
    """Open ``paths`` and align them (see the module docstring)."""
    parts = [open_recording(p) for p in paths]
    rate = parts[0].sample_rate
    for p in parts[1:]:
        if p.sample_rate != rate:
            raise AudioFileError(
                f"recordings made together must share a sample rate: {str(parts[0].path)!r} "
                f"is {rate} Hz, {str(p.path)!r} {p.sample_rate} Hz. Convert one first, e.g. "
                f"`ffmpeg -i {p.path.name} -ar {rate} {p.path.stem}_{rate}.wav`."
            )
    scans = [det.scan(p, band=band) for p in parts]
    rest = zip(parts[1:], scans[1:], strict=True)
    offsets = [0] + [_offset(parts[0], scans[0], p, s) for p, s in rest]
    offsets = np.array(offsets, dtype=np.int64)
    frames = int(max(p.frames + o for p, o in zip(parts, offsets, strict=True)))
    first = parts[0]
    return Together(
        tuple(parts), offsets, first.path, rate, sum(p.channels for p in parts), frames,
        first.format, f"{first.subtype}, {len(parts)} files together",
        tuple(str(p.path) for p in parts),
    )  # fmt: skip


def _offset(first: Recording, scan0, other: Recording, scan1) -> int:
    """Frames by which ``other`` started later than ``first``."""
    hop = scan0.hop
    a = np.maximum(scan0.curve, 0).astype(float)
    b = np.maximum(scan1.curve, 0).astype(float)
    n = fft.next_fast_len(a.size + b.size)
    corr = fft.irfft(fft.rfft(a, n) * np.conj(fft.rfft(b, n)), n)
    lags = np.concatenate([np.arange(0, a.size), np.arange(-b.size + 1, 0)])
    values = np.concatenate([corr[: a.size], corr[n - b.size + 1 :]])
    most = round(MAX_OFFSET / (hop / first.sample_rate))
    values[np.abs(lags) > most] = -np.inf
    best = int(np.argmax(values))
    coarse = int(lags[best]) * hop  # first's frame = other's frame + coarse
    likeness = float(values[best] / np.sqrt(np.sum(a * a) * np.sum(b * b)))
    if likeness < MIN_LIKENESS:
        warnings.warn(
            f"{str(other.path)!r} and {str(first.path)!r} hardly match at any offset "
            f"(correlation {likeness:.2f} at best): were they recorded at the same time, "
            f"of the same metronomes? The analysis goes on with the best offset, "
            f"{coarse / first.sample_rate:.3f} s.",
            UserWarning,
            stacklevel=3,
        )
    # refine on the waveforms around the first file's loudest stretch
    span = round(REFINE_SPAN * first.sample_rate)
    centre = int(np.argmax(scan0.level)) * hop
    lo = max(0, centre - span // 2)
    x = first.segment(lo, lo + span).mean(axis=1)
    y = other.segment(lo - coarse - 2 * hop, lo - coarse + span + 2 * hop).mean(axis=1)
    x = signal.sosfilt(scan0.sos, x)
    y = signal.sosfilt(scan0.sos, y)
    best = signal.correlate(y, x, mode="valid", method="fft")  # lag k: y[k:k+span] ~ x
    k = int(np.argmax(best))
    return coarse + 2 * hop - k

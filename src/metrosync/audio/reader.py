"""Reading a sound recording: checks, blocks and short segments, never the whole file.

Contract: `open_recording(path)` checks that ``path`` is an audio file that libsndfile
(through `soundfile`) can decode, with at least one frame and a usable sample rate,
and returns a `Recording`. Its `blocks` yield the samples in order as float32 arrays
of shape (frames, channels), a bounded number at a time, and `segment` reads any
short stretch, so that a recording of hours is analysed in bounded memory.

Every problem is an `AudioFileError` naming the file and what to do: a missing file,
a format libsndfile does not read (phones' ``.m4a``: convert it first), a damaged
or empty file. Formats read: WAV (PCM 8–32 bit, float), FLAC, Ogg Vorbis and Opus,
MP3, AIFF, W64, RF64 and CAF, mono or with any number of channels.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MetrosyncError

#: Suffixes of the formats read (lower case).
AUDIO_SUFFIXES = (
    ".wav", ".flac", ".ogg", ".oga", ".opus", ".mp3", ".aif", ".aiff", ".w64", ".rf64", ".caf",
)  # fmt: skip
#: Audio formats phones write that libsndfile does not decode.
UNSUPPORTED_AUDIO = (".m4a", ".aac", ".mp4", ".3gp", ".amr", ".wma", ".webm", ".mov")
#: Sample rates outside this range (Hz) are refused: too coarse for millisecond timing,
#: or not a recording.
MIN_RATE, MAX_RATE = 8000, 768000
#: Frames per block of `Recording.blocks` (about 24 s at 44.1 kHz).
BLOCK_FRAMES = 1 << 20


class AudioFileError(MetrosyncError, ValueError):
    """A recording cannot be read: missing, not audio, damaged, empty or silent."""


def is_audio_path(path: str | Path) -> bool:
    """True when ``path``'s suffix names a sound recording (read or not)."""
    suffix = Path(path).suffix.lower()
    return suffix in AUDIO_SUFFIXES or suffix in UNSUPPORTED_AUDIO


@dataclass(frozen=True)
class Recording:
    """A sound file that has been opened once and checked.

    path : the file.
    sample_rate : frames per second, Hz.
    channels : number of channels.
    frames : number of frames (samples per channel).
    format, subtype : libsndfile's names, e.g. ``"WAV"``, ``"PCM_16"``.
    """

    path: Path
    sample_rate: int
    channels: int
    frames: int
    format: str
    subtype: str

    @property
    def duration(self) -> float:
        """Length of the recording, s."""
        return self.frames / self.sample_rate

    def blocks(self, block_frames: int = BLOCK_FRAMES) -> Iterator[tuple[int, np.ndarray]]:
        """Yield (first frame, samples (n, channels) float32) through the whole file."""
        with _open(self.path) as f:
            start = 0
            while True:
                data = f.read(block_frames, dtype="float32", always_2d=True)
                if data.shape[0] == 0:
                    return
                yield start, data
                start += data.shape[0]

    def segment(self, start: int, stop: int) -> np.ndarray:
        """Frames [start, stop) as (stop − start, channels) float32, zeros outside the file."""
        out = np.zeros((stop - start, self.channels), dtype=np.float32)
        lo, hi = max(start, 0), min(stop, self.frames)
        if hi > lo:
            with _open(self.path) as f:
                f.seek(lo)
                data = f.read(hi - lo, dtype="float32", always_2d=True)
            out[lo - start : lo - start + data.shape[0]] = data
        return out


def _open(path: Path):
    import soundfile as sf

    try:
        return sf.SoundFile(str(path))
    except sf.LibsndfileError as error:
        raise AudioFileError(
            f"cannot read {str(path)!r} as audio ({error.error_string}); is it a sound "
            f"recording? Formats read: {', '.join(AUDIO_SUFFIXES)}."
        ) from None


def open_recording(path: str | Path) -> Recording:
    """Check ``path`` and return its `Recording` (nothing is decoded yet).

    Raises
    ------
    AudioFileError
        The file is missing, a directory, in a format not read, damaged, or empty.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if not path.exists():
        raise AudioFileError(f"cannot read recording {str(path)!r}: the file does not exist.")
    if path.is_dir():
        raise AudioFileError(f"recording {str(path)!r} is a directory; give a sound file.")
    if suffix in UNSUPPORTED_AUDIO:
        raise AudioFileError(
            f"cannot read {str(path)!r}: {suffix} (compressed AAC/video audio) is not read; "
            f"convert it first, e.g. `ffmpeg -i {path.name} {path.stem}.wav`."
        )
    if path.stat().st_size == 0:
        raise AudioFileError(f"recording {str(path)!r} is empty (0 bytes).")
    with _open(path) as f:
        rate, channels, frames = int(f.samplerate), int(f.channels), int(f.frames)
        fmt, subtype = str(f.format), str(f.subtype)
    if frames <= 0:
        raise AudioFileError(
            f"recording {str(path)!r} holds no sound: 0 frames after its {fmt} header."
        )
    if not MIN_RATE <= rate <= MAX_RATE:
        raise AudioFileError(
            f"recording {str(path)!r} has a sample rate of {rate} Hz; tick timing needs "
            f"{MIN_RATE}..{MAX_RATE} Hz (record at 44.1 or 48 kHz)."
        )
    return Recording(path, rate, channels, frames, fmt, subtype)

"""Reading a sound recording: checks, blocks and short segments.

Contract: `open_recording(path)` checks that ``path`` is a sound file, or a video
with a sound track, with at least one frame and a usable sample rate, and returns a
`Recording`. Its `blocks` yield the samples in order as float32 arrays of shape
(frames, channels), a bounded number at a time, and `segment` reads any short stretch.

Two decoders. Uncompressed and libsndfile's formats (WAV (PCM 8–32 bit, float), FLAC,
Ogg Vorbis and Opus, MP3, AIFF, W64, RF64, CAF) are read through `soundfile` from
the file, a block at a time, so that a recording of hours is analysed in bounded
memory. What phones and cameras write (``.m4a``, ``.aac``, ``.mp4``, ``.mov``, ``.3gp``,
``.amr``, ``.webm``, ``.mkv``, ...), and an Ogg or MP3 that libsndfile fails on, is
decoded once through FFmpeg (`decode`: the first audio stream, at its own rate and
channels, the encoder's priming cut where the container records it) into memory.

Every problem is an `AudioFileError` naming the file and what to do: a missing file,
a directory, a damaged, empty or cut-short file, a video without a sound track.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._input_files import check_input_file
from ..errors import MetrosyncError

#: Suffixes of the formats libsndfile reads (lower case); FFmpeg reads them when it fails.
SNDFILE_SUFFIXES = (
    ".wav", ".flac", ".ogg", ".oga", ".opus", ".mp3", ".aif", ".aiff", ".w64", ".rf64", ".caf",
)  # fmt: skip
#: Suffixes of what phones and cameras write, decoded through FFmpeg: compressed sound
#: (AAC, AMR, WMA) and the sound tracks of videos.
FFMPEG_SUFFIXES = (
    ".m4a", ".aac", ".mp4", ".m4v", ".mov", ".3gp", ".3g2", ".amr", ".wma", ".webm", ".mkv",
    ".mka", ".avi",
)  # fmt: skip
#: Suffixes of every format read (lower case).
AUDIO_SUFFIXES = SNDFILE_SUFFIXES + FFMPEG_SUFFIXES
#: Sample rates outside this range (Hz) are refused: too coarse for millisecond timing,
#: or not a recording.
MIN_RATE, MAX_RATE = 8000, 768000
#: Frames per block of `Recording.blocks` (about 24 s at 44.1 kHz).
BLOCK_FRAMES = 1 << 20


class AudioFileError(MetrosyncError, ValueError):
    """A recording cannot be read: missing, not audio, damaged, empty or silent."""


def is_audio_path(path: str | Path) -> bool:
    """True when ``path``'s suffix names a sound recording or a video (its sound is read)."""
    return Path(path).suffix.lower() in AUDIO_SUFFIXES


@dataclass(frozen=True)
class Recording:
    """A sound file that has been opened once and checked.

    path : the file.
    sample_rate : frames per second, Hz.
    channels : number of channels.
    frames : number of frames (samples per channel).
    format, subtype : libsndfile's names, e.g. ``"WAV"``, ``"PCM_16"``; for a file
        decoded through FFmpeg its suffix and codec, e.g. ``"M4A"``, ``"AAC"``.
    samples : (frames, channels) float32, read-only, for a file decoded through FFmpeg
        (held in memory); None for one read from the file a block at a time.
    """

    path: Path
    sample_rate: int
    channels: int
    frames: int
    format: str
    subtype: str
    samples: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def duration(self) -> float:
        """Length of the recording, s."""
        return self.frames / self.sample_rate

    def blocks(self, block_frames: int = BLOCK_FRAMES) -> Iterator[tuple[int, np.ndarray]]:
        """Yield (first frame, samples (n, channels) float32) through the whole file."""
        if self.samples is not None:
            for start in range(0, self.frames, block_frames):
                yield start, self.samples[start : start + block_frames]
            return
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
        if hi > lo and self.samples is not None:
            out[lo - start : hi - start] = self.samples[lo:hi]
        elif hi > lo:
            with _open(self.path) as f:
                f.seek(lo)
                data = f.read(hi - lo, dtype="float32", always_2d=True)
            out[lo - start : lo - start + data.shape[0]] = data
        return out


    def segments(self, starts: np.ndarray, length: int) -> np.ndarray:
        """(n, length, channels) float32: frames [s, s + length) for each of ``starts``,
        zeros outside the file, the file opened once for them all."""
        out = np.zeros((len(starts), length, self.channels), dtype=np.float32)
        if self.samples is not None:
            for i, start in enumerate(starts):
                out[i] = self.segment(int(start), int(start) + length)
            return out
        with _open(self.path) as f:
            for i, start in enumerate(starts):
                lo, hi = max(int(start), 0), min(int(start) + length, self.frames)
                if hi > lo:
                    f.seek(lo)
                    data = f.read(hi - lo, dtype="float32", always_2d=True)
                    out[i, lo - start : lo - start + data.shape[0]] = data
        return out


def _open(path: Path):
    import soundfile as sf

    try:
        return sf.SoundFile(str(path))
    except sf.LibsndfileError as error:
        raise AudioFileError(_unreadable(path, error.error_string)) from None


def _unreadable(path: Path, why: str) -> str:
    return (
        f"cannot read {str(path)!r} as audio ({why}); is it a sound recording or a video? "
        f"Formats read: {', '.join(AUDIO_SUFFIXES)}. A file cut short (a recording stopped "
        f"by a crash, a copy broken off) cannot be read; if a player still plays it, "
        f"convert it, e.g. `ffmpeg -i {path.name} {path.stem}.wav`."
    )


def open_recording(path: str | Path) -> Recording:
    """Check ``path`` and return its `Recording`.

    A libsndfile format is only opened here (its samples are read later, a block at a
    time); anything else is decoded here, through FFmpeg.

    Raises
    ------
    AudioFileError
        The file is missing, a directory, not a recording, damaged, empty, without a
        sound track, or at a sample rate outside 8–768 kHz.
    """
    path = check_input_file(path, "recording", error=AudioFileError)
    if path.suffix.lower() in FFMPEG_SUFFIXES:
        return _checked(_decoded(path, None))
    import soundfile as sf

    try:
        with sf.SoundFile(str(path)) as f:
            rate, channels, frames = int(f.samplerate), int(f.channels), int(f.frames)
            fmt, subtype = str(f.format), str(f.subtype)
    except sf.LibsndfileError as error:
        # An older libsndfile lacks MP3 and Opus, and FFmpeg reads more of WAV's codecs.
        return _checked(_decoded(path, error.error_string))
    return _checked(Recording(path, rate, channels, frames, fmt, subtype))


def _decoded(path: Path, sndfile_error: str | None) -> Recording:
    """The `Recording` of ``path`` decoded through FFmpeg; ``sndfile_error`` is why
    libsndfile could not read it, if it was tried (and the error shown if FFmpeg fails)."""
    from .decode import DecodeError, NoSoundTrack, decode_sound

    try:
        sound = decode_sound(path)
    except NoSoundTrack as error:
        raise AudioFileError(
            f"{str(path)!r} has no sound to analyse: {error}. Record with sound on, or give "
            f"the sound recording itself."
        ) from None
    except DecodeError as error:
        if sndfile_error is not None:
            raise AudioFileError(_unreadable(path, sndfile_error)) from None
        raise AudioFileError(_unreadable(path, f"FFmpeg: {error}")) from None
    frames, channels = sound.samples.shape
    fmt = path.suffix.lstrip(".").upper() or sound.container
    return Recording(path, sound.sample_rate, channels, frames, fmt, sound.codec.upper(),
                     sound.samples)  # fmt: skip


def _checked(recording: Recording) -> Recording:
    path, rate = recording.path, recording.sample_rate
    if recording.frames <= 0:
        raise AudioFileError(
            f"recording {str(path)!r} holds no sound: 0 frames after its header "
            f"({recording.format})."
        )
    if not MIN_RATE <= rate <= MAX_RATE:
        raise AudioFileError(
            f"recording {str(path)!r} has a sample rate of {rate} Hz; tick timing needs "
            f"{MIN_RATE}..{MAX_RATE} Hz (record at 44.1 or 48 kHz)."
        )
    return recording

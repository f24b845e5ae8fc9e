"""Decoding compressed sound through FFmpeg (PyAV): phones' AAC, and the sound of a video.

Contract: `decode_sound(path)` decodes the first audio stream of any file FFmpeg
opens (``.m4a``, ``.aac``, ``.mp4``, ``.mov``, ``.3gp``, ``.amr``, ``.webm``, ``.mkv``,
Ogg and MP3 where libsndfile fails, ...) into one float32 array of shape
(frames, channels) at the stream's own sample rate, with the stream's own channels:
nothing is resampled or mixed down. It returns a `Decoded`, or raises `AudioFileError`
naming the file: one FFmpeg cannot open (damaged, cut short, not media), one with no
audio stream (a silent video), one whose codec this FFmpeg lacks.

Timing. Sample k of the array is heard at k / rate seconds after the first sample
of the sound track. Each decoded frame is placed at its presentation time, so that

* the encoder's priming samples are dropped where the container records them: MP4,
  M4A, MOV and 3GP hold them in an edit list, Ogg Opus as its pre-skip, and FFmpeg
  gives those samples negative times or removes them; anything before time 0 is left
  out. A raw ADTS ``.aac`` stream records no delay at all: its ticks come one
  encoder delay late (1024 samples for FFmpeg's encoder, 2112 for Apple's, 21–48 ms),
  the same for every tick;
* a packet FFmpeg cannot decode (a damaged stretch) leaves silence of its length in
  place and the rest keeps its time; one warning counts such packets.

Memory. The frames are written into one array, preallocated from the stream's stated
length and doubled when it runs out (so the copying stays proportional to the
length, never quadratic), then cut to what was decoded: 4 bytes per sample and
channel, about 0.7 GB per hour and channel at 48 kHz.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._words import plural
from ..errors import MetrosyncError

#: Frames preallocated when a stream states no length (one minute at 48 kHz).
_FIRST_GUESS = 48000 * 60
#: Full scale of FFmpeg's integer sample formats, to float in [-1, 1).
_SCALE = {"u8": 128.0, "s16": 32768.0, "s32": 2147483648.0, "s64": 9223372036854775808.0}


class DecodeError(MetrosyncError, ValueError):
    """FFmpeg cannot decode a file's sound; `reader` turns it into an `AudioFileError`."""


class NoSoundTrack(DecodeError):
    """The file opens but holds no audio stream (a silent video, a picture)."""


@dataclass(frozen=True)
class Decoded:
    """The sound track of a file, decoded.

    samples : (frames, channels) float32, read-only.
    sample_rate : Hz, the stream's own.
    container : FFmpeg's name of the file format, e.g. ``"mov,mp4,m4a,3gp,3g2,mj2"``.
    codec : FFmpeg's name of the codec, e.g. ``"aac"``.
    damaged_packets : packets that could not be decoded (silence in their place).
    """

    samples: np.ndarray
    sample_rate: int
    container: str
    codec: str
    damaged_packets: int = 0


def decode_sound(path: Path) -> Decoded:
    """Decode the first audio stream of ``path``; see the module docstring.

    Raises
    ------
    NoSoundTrack
        The file has no audio stream.
    DecodeError
        FFmpeg cannot open the file, its codec is missing, or
        its channels or sample rate change within the stream.
    """
    import av

    name = str(path)
    try:
        container = av.open(name, metadata_errors="ignore")
    except av.error.FFmpegError as error:
        raise DecodeError(str(error.strerror or error)) from None
    with container:
        audio = [s for s in container.streams.audio if s.codec_context is not None]
        if not audio and any(s.codec_context is None for s in container.streams):
            # What an MP4 cut before its index was written looks like to FFmpeg.
            raise DecodeError("its streams cannot be decoded: its index is damaged or missing")
        if not audio:
            kinds = ", ".join(sorted({str(s.type) for s in container.streams})) or "none"
            raise NoSoundTrack(f"it holds no sound track (its streams: {kinds})")
        stream = audio[0]
        rate = int(stream.codec_context.sample_rate or stream.rate or 0)
        writer = _Writer(_stated_frames(stream, container, rate))
        origin = _origin(stream, rate)
        damaged = 0
        channels = None
        for packet in container.demux(stream):
            try:
                frames = packet.decode()
            except av.error.FFmpegError:
                damaged += 1
                continue
            for frame in frames:
                data = _as_float(frame)
                if channels is None:
                    channels = data.shape[1]
                    rate = int(frame.sample_rate) or rate
                elif data.shape[1] != channels or int(frame.sample_rate) != rate:
                    raise DecodeError(
                        f"its sound track changes from {plural(channels, 'channel')} at "
                        f"{rate} Hz to {plural(data.shape[1], 'channel')} at "
                        f"{frame.sample_rate} Hz partway through; cut it where it changes"
                    )
                start = _first_frame(frame, rate)
                if origin is None:
                    origin = max(start or 0, 0)
                writer.put(None if start is None else start - origin, data)
        codec = stream.codec_context.name
        fmt = container.format.name
    if channels is None:
        raise DecodeError(f"its {codec} sound track holds no decodable sound")
    if damaged:
        warnings.warn(
            f"{name!r}: {plural(damaged, 'damaged packet')} of its {codec} sound could not "
            f"be decoded; silence stands in their place and the rest keeps its time.",
            UserWarning,
            stacklevel=3,
        )
    return Decoded(writer.result(channels), rate, fmt, codec, damaged)


def _stated_frames(stream, container, rate: int) -> int:
    """The stream's length in frames as the file states it, for preallocation only."""
    if stream.duration is not None and stream.time_base is not None:
        return int(stream.duration * stream.time_base * rate) + 1
    if container.duration is not None:  # microseconds
        return int(container.duration * rate / 1_000_000) + 1
    return _FIRST_GUESS


def _origin(stream, rate: int) -> int | None:
    """Index of time 0 on the stream's time line: its start, or None (its first frame's).

    A negative start is priming that FFmpeg times before 0; the sound begins at 0.
    """
    if stream.start_time is None or stream.time_base is None:
        return None
    return max(int(round(stream.start_time * stream.time_base * rate)), 0)


def _first_frame(frame, rate: int) -> int | None:
    """Index of ``frame``'s first sample on the track's time line, or None if unstated."""
    if frame.pts is None or frame.time_base is None:
        return None
    return int(round(frame.pts * frame.time_base * rate))


def _as_float(frame) -> np.ndarray:
    """(samples, channels) float32 of one decoded frame, whatever its sample format."""
    layout = frame.format
    data = frame.to_ndarray()
    channels = frame.layout.nb_channels
    # Planar frames come as (channels, samples), packed ones as (1, samples·channels).
    data = data.T if layout.is_planar else data.reshape(-1, channels)
    base = layout.name.rstrip("p")
    if base in ("flt", "dbl"):
        return data.astype(np.float32, copy=False)
    scale = _SCALE[base]
    offset = scale if base == "u8" else 0.0
    return ((data.astype(np.float64) - offset) / scale).astype(np.float32)


class _Writer:
    """Frames written at their place in one growing (frames, channels) array."""

    def __init__(self, frames: int) -> None:
        self._capacity = max(int(frames), 1024)
        self._out: np.ndarray | None = None
        self._end = 0  # frames written so far (silence in any gaps included)

    def put(self, start: int | None, data: np.ndarray) -> None:
        if self._out is None:
            self._out = np.zeros((self._capacity, data.shape[1]), dtype=np.float32)
        # A frame is placed where its time says when that differs from where the last
        # one ended: a gap (a damaged packet) stays silent, priming (time < 0) is cut.
        at = self._end if start is None or abs(start - self._end) <= 1 else start
        if at < 0:
            data, at = data[-at:], 0
        stop = at + data.shape[0]
        if stop > self._out.shape[0]:
            grown = np.zeros((max(stop, 2 * self._out.shape[0]), data.shape[1]), np.float32)
            grown[: self._end] = self._out[: self._end]
            self._out = grown
        self._out[at:stop] = data
        self._end = max(self._end, stop)

    def result(self, channels: int) -> np.ndarray:
        if self._out is None:
            return np.zeros((0, channels), np.float32)
        out = self._out
        self._out = None
        # In place, without a second copy of an hour of sound; nothing else refers to it.
        out.resize((self._end, out.shape[1]), refcheck=False)
        out.flags.writeable = False
        return out

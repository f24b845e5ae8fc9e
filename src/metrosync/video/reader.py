"""Reading a video: checks, then grey frames streamed with the container's own times.

Contract: `open_video(path)` opens a file with PyAV (FFmpeg's demuxers and decoders in
a wheel: MP4, MOV, MKV, AVI, WebM and the codecs phones write), checks that it holds
a video stream, and returns a `Video` that knows its size, rotation, nominal rate,
length and audio track. `Video.frames` yields ``(time, picture)`` one frame at a time:

* ``time`` is the frame's presentation timestamp (PTS × time base) in seconds from the
  first frame, never an index divided by a nominal rate: phones record at a variable
  rate, and a "30 fps" file may hold frames 31 and 36 ms apart, or drop some;
* ``picture`` is a uint8 (height, width) grey image at a reduced size (the
  longer side at most ``max_side`` pixels), turned upright by the rotation the file
  asks for (a phone held upright stores a landscape picture and a rotation of ±90°).

Decoding uses FFmpeg's frame and slice threads. Memory does not grow with the length.
A file that ends early (a copy cut short) yields what could be decoded and says so in
`Video.loss`; every problem before the first frame is a `VideoFileError` naming the
file and what to do.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._input_files import check_input_file
from .._words import plural
from ..budget import format_bytes
from ..errors import MetrosyncError

#: Default longest side of the pictures analysed, pixels.
DEFAULT_MAX_SIDE = 640
#: Fewest bytes in which a container can store a video frame: its entry in the index
#: (an MP4's 4-byte sample size, an AVI's 16-byte idx1 entry, a Matroska block's header)
#: beside a coded picture of a few bytes at least. A header that counts more frames
#: than its file's bytes can hold this way is damaged.
MIN_FRAME_BYTES = 4
#: Most the stated frame count and the one the length × average rate make may differ by,
#: as a ratio, before the header is taken as contradicting itself.
FRAME_COUNT_RATIO = 2.0


class VideoFileError(MetrosyncError, ValueError):
    """A video cannot be read: missing, not a video, audio only, damaged or too short."""


@dataclass
class Video:
    """A video file opened once and checked.

    path : the file.
    width, height : the decoded picture's size before rotation, pixels.
    rotation : degrees counter-clockwise (0, 90, 180, 270) that the picture is turned to
        be shown upright.
    nominal_fps : the rate the container states (may differ from the real times).
    duration : the container's stated length, s (NaN if unknown).
    frames_estimate : frames expected from the stated length and rate (0 if unknown).
    codec : the video codec's name.
    has_audio : whether the file holds an audio stream.
    loss : after `frames` ends, a sentence about what could not be read ("" if none).
    """

    path: Path
    width: int
    height: int
    rotation: int
    nominal_fps: float
    duration: float
    frames_estimate: int
    codec: str
    has_audio: bool
    loss: str = field(default="")
    decoded: int = field(default=0)

    @property
    def upright_size(self) -> tuple[int, int]:
        """(width, height) as shown, after the rotation."""
        if self.rotation % 180:
            return self.height, self.width
        return self.width, self.height

    def stored_row(self, x: float, y: float, shape: tuple[int, int]) -> float:
        """Where the upright picture's point (x, y), in a picture of ``shape`` (H, W),
        lies among the stored picture's rows, as a fraction from the top (0..1): a
        rolling shutter exposes the stored rows in turn."""
        h, w = shape
        k = int(round(self.rotation / 90.0)) % 4
        # np.rot90 by k quarter turns counter-clockwise made the upright picture
        return [y / h, x / w, 1.0 - y / h, 1.0 - x / w][k]

    def scaled_size(self, max_side: int) -> tuple[int, int]:
        """(width, height) of the decoded picture with its longer side at most ``max_side``
        (even sizes, for the scaler); before rotation."""
        scale = min(1.0, max_side / max(self.width, self.height))
        w = max(2, int(round(self.width * scale / 2)) * 2)
        h = max(2, int(round(self.height * scale / 2)) * 2)
        return w, h

    def frames(
        self, *, max_side: int = DEFAULT_MAX_SIDE, stop: float | None = None
    ) -> Iterator[tuple[float, np.ndarray]]:
        """Yield ``(time, grey picture)`` for each frame, in presentation order.

        max_side : longest side of the pictures, pixels (the file's own size if larger).
        stop : stop after this time (s from the first frame); default the whole file.
        """
        import av

        width, height = self.scaled_size(max_side)
        k = int(round(self.rotation / 90.0)) % 4
        self.loss, self.decoded = "", 0
        t0, last = None, -np.inf
        dropped_times = 0
        with _open(self.path) as container:
            stream = container.streams.video[0]
            stream.thread_type = "AUTO"
            base = stream.time_base
            try:
                for frame in container.decode(stream):
                    if frame.pts is None:
                        dropped_times += 1
                        continue
                    t = float(frame.pts * base)
                    if t0 is None:
                        t0 = t
                    t -= t0
                    if t <= last:  # a repeated or out-of-order timestamp: not a new picture
                        dropped_times += 1
                        continue
                    if stop is not None and t > stop:
                        break
                    last = t
                    picture = frame.reformat(width=width, height=height, format="gray",
                                             interpolation="AREA").to_ndarray()  # fmt: skip
                    if k:
                        picture = np.rot90(picture, k)
                    self.decoded += 1
                    yield t, picture
            except av.error.FFmpegError as error:
                self.loss = (
                    f"decoding stopped at {max(last, 0.0):.2f} s after "
                    f"{plural(self.decoded, 'frame')} ({error.strerror or error}); "
                    f"the rest of the file is lost"
                )
            if stop is None and not self.loss and np.isfinite(self.duration):
                expected = self.duration - 2.0 / max(self.nominal_fps, 1.0)
                if last < expected - 1.0:
                    self.loss = (
                        f"the file states {self.duration:.1f} s but frames end at {last:.1f} s: "
                        f"it was cut short, and {self.duration - last:.1f} s are lost"
                    )
        if dropped_times:
            note = f"{plural(dropped_times, 'frame')} without a new timestamp skipped"
            self.loss = f"{self.loss}; {note}" if self.loss else note


def _frame_count(path: Path, stated: int, duration: float, fps: float, average: float) -> int:
    """The frames to expect: the count the header states, else its length × rate (0:
    unknown); a `VideoFileError` when the header cannot be right.

    A damaged header can state billions of frames for a clip of seconds, and every
    size and time planned from it would be as wrong. Two counts are checked against the
    file: the stated one and the one its length and average rate make (the same frames
    counted twice, so they agree whatever the timestamps do; the rate FFmpeg guesses
    for a variable-rate file need not, and is not compared). Neither may exceed what
    the file's bytes can hold at `MIN_FRAME_BYTES` a frame.
    """
    size = path.stat().st_size
    room = size // MIN_FRAME_BYTES
    implied = duration * average if np.isfinite(duration * average) and duration > 0 else None
    by_rate = duration * fps if np.isfinite(duration * fps) and duration > 0 else None
    contradicted = (
        stated > 0
        and implied is not None
        and abs(stated - implied) > 2
        and max(stated, implied) > FRAME_COUNT_RATIO * min(stated, implied)
    )
    too_many = max(stated, by_rate or 0) > room
    if contradicted or too_many:
        said = f"states {plural(stated, 'frame')}" if stated > 0 else "states no frame count"
        if by_rate is not None:
            rate = average if implied is not None else fps
            said += f", but {duration:.4g} s at {rate:.4g} fps make about {round(duration * rate)}"
        said += f", and its {format_bytes(size)} can hold at most {plural(room, 'frame')}"
        raise VideoFileError(
            f"{str(path)!r} has a damaged header: it {said}. Copy its streams into "
            f"a new file, which writes the header again from the frames themselves (`ffmpeg "
            f"-i {path.name} -c copy fixed{path.suffix}`), and track that."
        )
    if stated > 0:
        return stated
    return int(by_rate) if by_rate is not None else 0


def _open(path: Path):
    import av

    try:
        return av.open(str(path), metadata_errors="ignore")
    except av.error.FFmpegError as error:
        cut = ""
        if path.suffix.lower() in (".mp4", ".mov", ".m4v", ".3gp"):
            cut = (
                " An MP4 or MOV cut short before its index was written (a recording stopped "
                "by a crash, a copy broken off) cannot be read at all: copy it again."
            )
        raise VideoFileError(
            f"cannot read {str(path)!r} as a video ({error.strerror or error}); give an MP4, "
            f"MOV, MKV or AVI file from a camera or phone.{cut}"
        ) from None


def open_video(path: str | Path) -> Video:
    """Open and check a video file; see the module docstring.

    Raises `VideoFileError` for a missing file, a file FFmpeg cannot read, a file with
    no video stream (an audio recording: use ``metrosync analyze``), or no frame.
    """
    import av

    path = check_input_file(path, "video", error=VideoFileError)
    with _open(path) as container:
        if not container.streams.video:
            kinds = sorted({s.type for s in container.streams})
            hint = (
                " It is a sound recording: analyse it with `metrosync analyze FILE` (WAV, "
                "FLAC, MP3 or a phone's .m4a)."
                if "audio" in kinds
                else ""
            )
            raise VideoFileError(
                f"{str(path)!r} holds no video stream (streams: {', '.join(kinds) or 'none'})."
                f"{hint}"
            )
        stream = container.streams.video[0]
        stream.thread_type = "AUTO"
        rate = stream.average_rate or stream.guessed_rate or stream.base_rate
        fps = float(rate) if rate else float("nan")
        if stream.duration is not None and stream.time_base is not None:
            duration = float(stream.duration * stream.time_base)
        elif container.duration is not None:
            duration = container.duration / av.time_base
        else:
            duration = float("nan")
        average = float(stream.average_rate) if stream.average_rate else float("nan")
        estimate = _frame_count(path, int(stream.frames or 0), duration, fps, average)
        try:
            first = next(container.decode(stream), None)
        except av.error.FFmpegError as error:
            raise VideoFileError(
                f"cannot decode the first frame of {str(path)!r} ({error.strerror or error}): "
                f"the file is damaged or its codec is not supported."
            ) from None
        if first is None:
            raise VideoFileError(f"{str(path)!r} holds a video stream but no frame.")
        return Video(
            path=path,
            width=first.width,
            height=first.height,
            rotation=int(round(first.rotation or 0)) % 360,
            nominal_fps=fps,
            duration=duration,
            frames_estimate=int(estimate),
            codec=stream.codec_context.name,
            has_audio=bool(container.streams.audio),
        )

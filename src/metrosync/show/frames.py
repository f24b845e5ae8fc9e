"""Frame sinks: animated GIF and MP4 files written one frame at a time.

Contract: `open_sink(path, fps, width, height)` yields a sink whose ``add(image)``
takes one RGB frame (a Pillow image) and writes it out at once, so memory holds
one frame whatever the length of the animation (matplotlib's `PillowWriter` keeps
every frame until the end). On any error or Ctrl-C the sink stops its encoder and
the caller's temporary file is discarded (`metrosync._files.atomic_path`).

``.gif``: each frame is reduced to its own 256-colour palette (Pillow's fast octree,
no dithering) and LZW-encoded by Pillow's GIF encoder, with a local colour table.
GIF counts time in hundredths of a second; frame k lasts
round((k + 1)·100/fps) − round(k·100/fps) of them, so the average rate is ``fps``
exactly. The file loops forever.

``.mp4``: raw frames are piped to ffmpeg (H.264, yuv420p, padded to even sizes),
which must be on PATH.
"""

from __future__ import annotations

import contextlib
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from PIL import GifImagePlugin, Image

from ..errors import ParameterError

#: Highest frame rate a GIF can play: browsers stretch frames shorter than 2/100 s.
GIF_MAX_FPS = 50.0


class GifSink:
    """Appends frames to an animated GIF being written to ``file``."""

    def __init__(self, file: BinaryIO, fps: float):
        self.file = file
        self.fps = float(fps)
        self.count = 0

    def duration_ms(self, k: int) -> int:
        """How long frame ``k`` shows, ms (a multiple of 10, see the module docstring)."""
        cs = round((k + 1) * 100 / self.fps) - round(k * 100 / self.fps)
        return 10 * max(2, cs)

    def add(self, image: Image.Image) -> None:
        frame = image.quantize(
            colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE
        )
        if self.count == 0:
            header, _ = GifImagePlugin.getheader(frame, info={"loop": 0})
            self.file.write(b"".join(header))
        duration = self.duration_ms(self.count)
        for chunk in GifImagePlugin.getdata(frame, duration=duration, include_color_table=True):
            self.file.write(chunk)
        self.count += 1

    def close(self) -> None:
        self.file.write(b";")  # the GIF trailer


class FFmpegSink:
    """Pipes raw RGB frames into an ffmpeg process that writes an MP4."""

    def __init__(self, path: Path, fps: float, width: int, height: int):
        command = [
            ffmpeg_path(path), "-y", "-loglevel", "error",
            "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}", "-r", f"{fps:g}",
            "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-c:v", "h264", "-pix_fmt", "yuv420p", str(path),
        ]  # fmt: skip
        # A session of its own: a Ctrl-C at the terminal reaches us, and we stop it.
        self.process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
        )

    def add(self, image: Image.Image) -> None:
        try:
            self.process.stdin.write(image.tobytes())
        except BrokenPipeError:
            self.close()  # ffmpeg stopped: report why
            raise

    def close(self) -> None:
        with contextlib.suppress(BrokenPipeError):
            self.process.stdin.close()
        with self.process.stderr:
            errors = self.process.stderr.read().decode(errors="replace").strip()
        if self.process.wait() != 0:
            raise OSError(f"ffmpeg failed (exit {self.process.returncode}): {errors[-500:]}")

    def abort(self) -> None:
        self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stderr):
            with contextlib.suppress(OSError):
                stream.close()


def ffmpeg_path(path: Path) -> str:
    """ffmpeg on PATH, or a `ParameterError` that says how to get it."""
    found = shutil.which("ffmpeg")
    if found is None:
        raise ParameterError(
            f"writing {path.name!r} needs ffmpeg on PATH; install it "
            f"(e.g. `apt-get install ffmpeg`) or write a .gif instead."
        )
    return found


def check_format(path: Path, fps: float) -> None:
    """Refuse a suffix other than .gif/.mp4, a GIF faster than it can play, and an MP4
    without ffmpeg; before any frame is drawn."""
    suffix = path.suffix.lower()
    if suffix == ".gif":
        if fps > GIF_MAX_FPS:
            raise ParameterError(
                f"`fps` = {fps:g} is faster than a GIF can play (at most {GIF_MAX_FPS:g} frames "
                f"per second); lower it, or write an .mp4."
            )
    elif suffix == ".mp4":
        ffmpeg_path(path)
    else:
        raise ParameterError(f"the animation file must end in .gif or .mp4, got {str(path)!r}.")


@contextlib.contextmanager
def open_sink(path: Path, fps: float, width: int, height: int) -> Iterator[GifSink | FFmpegSink]:
    """A sink writing ``path`` (its suffix picks the format); finished on success,
    stopped on any error (the partial file is then the caller's to discard)."""
    path = Path(path)
    check_format(path, fps)
    if path.suffix.lower() == ".gif":
        with open(path, "wb") as file:
            sink = GifSink(file, fps)
            yield sink
            sink.close()
        return
    sink = FFmpegSink(path, fps, width, height)
    try:
        yield sink
    except BaseException:
        sink.abort()
        raise
    sink.close()

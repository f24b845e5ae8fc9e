"""The animation: frame count, frames that move, formats and guards."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from PIL import Image

import metrosync
from metrosync.errors import ParameterError
from metrosync.show import animation, frames
from metrosync.show.animation import animate, frame_times
from metrosync.show.recording import NoTrajectoriesError


def gif_frames(path):
    with Image.open(path) as im:
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB")))
    return frames


def test_frame_times_follow_fps_and_speedup():
    times = frame_times(2.0, 14.0, fps=8.0, speedup=4.0)
    assert times.size == 25
    np.testing.assert_allclose(np.diff(times), 0.5)
    assert times[0] == 2.0 and times[-1] == pytest.approx(14.0)


def test_gif_has_the_expected_frames_and_they_move(recorded_ds, tmp_path):
    path = tmp_path / "sync.gif"
    count = animate(recorded_ds, path, fps=8.0, speedup=4.0, start=2.0, end=14.0, dpi=40)
    frames = gif_frames(path)
    assert count == len(frames) == 25  # floor(12 s × 8 fps / 4) + 1
    assert frames[0].shape == (160, 320, 3)  # 8 × 4 in at 40 dpi
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).sum() > 0
    assert not list(tmp_path.glob("*.partial*"))


def test_mp4_needs_ffmpeg(recorded_ds, tmp_path, monkeypatch):
    monkeypatch.setattr(frames.shutil, "which", lambda name: None)
    with pytest.raises(ParameterError, match="ffmpeg"):
        animate(recorded_ds, tmp_path / "a.mp4")


@pytest.mark.parametrize(
    ("options", "match"),
    [({"fps": 0}, "`fps`"), ({"speedup": -1.0}, "`speedup`"), ({"end": 99.0}, "`end`"),
     ({"fps": 40.0, "speedup": 0.001}, "frames exceed"),
     ({"fps": 1000.0}, "`fps` = 1000 is faster than a GIF can play"),
     ({"dpi": 1e6}, r"`dpi` = 1e\+06 makes 8 x 4 in frames of 8000000 x 4000000 pixels; frames "
                    r"must be 100 to 4096 pixels a side: use a `dpi` between 25 and 512"),
     ({"dpi": 10}, r"frames of 80 x 40 pixels"),
     ({"size": (80.0, 4.0)}, r"`dpi` = 80 makes 80 x 4 in frames of 6400 x 320 pixels"),
     ({"size": (8.0, -4.0)}, r"`size` must be a number > 0")],
)  # fmt: skip
def test_bad_options_are_refused(recorded_ds, tmp_path, options, match):
    with pytest.raises(ParameterError, match=match):
        animate(recorded_ds, tmp_path / "a.gif", **options)
    with pytest.raises(ParameterError, match=r"\.gif or \.mp4"):
        animate(recorded_ds, tmp_path / "a.png")


def test_a_dataset_without_trajectories_is_refused(tmp_path):
    ds = metrosync.simulate(3, 192.0, duration=2.0)
    with pytest.raises(NoTrajectoriesError, match="--save-every"):
        animate(ds, tmp_path / "a.gif")


# -- streaming, defaults and sizes ------------------------------------------------------


def test_frames_go_to_the_file_as_they_are_drawn(recorded_ds, tmp_path, monkeypatch):
    written = []
    add = frames.GifSink.add

    def add_and_measure(self, image):
        add(self, image)
        written.append(self.file.tell())

    monkeypatch.setattr(frames.GifSink, "add", add_and_measure)
    count = animate(recorded_ds, tmp_path / "a.gif", fps=10.0, speedup=1.0, end=6.0, dpi=40)
    assert count == len(written) == 61
    # Every frame reaches the file before the next is drawn: nothing is held back.
    assert all(b > a for a, b in zip(written, written[1:], strict=False))
    assert len(gif_frames(tmp_path / "a.gif")) == 61


def test_gif_timing_averages_the_frame_rate_and_loops(recorded_ds, tmp_path):
    path = tmp_path / "a.gif"
    count = animate(recorded_ds, path, fps=15.0, speedup=1.0, end=4.0, dpi=40)
    with Image.open(path) as im:
        assert im.info["loop"] == 0
        durations = []
        for k in range(im.n_frames):
            im.seek(k)
            durations.append(im.info["duration"])
    assert set(durations) == {60, 70}  # hundredths of a second: 7, 7, 6, 7, 7, 6, ...
    assert sum(durations) == pytest.approx(1000 * count / 15.0, abs=10)


@pytest.mark.parametrize(
    ("span", "speedup"), [(20.0, 1.0), (90.0, 4.0), (120.0, 4.0), (600.0, 20.0), (1000.0, 40.0)]
)
def test_default_speedup_fits_the_window_in_30_seconds(span, speedup):
    assert animation.auto_speedup(span) == speedup
    assert span / speedup <= 30.0 or speedup == 1.0


def test_default_animation_of_a_long_run_is_watchable(recorded_ds, tmp_path):
    count = animate(recorded_ds, tmp_path / "a.gif", dpi=30)  # 20 s shown at 1x, 15 fps
    assert count == 301


def test_mp4_frames_are_piped_to_ffmpeg(recorded_ds, tmp_path, monkeypatch):
    fake = tmp_path / "bin" / "ffmpeg"
    fake.parent.mkdir()
    # Stands in for ffmpeg: reads the raw frames and writes what it got to the output.
    fake.write_text(
        "#!" + sys.executable + "\n"
        "import sys\n"
        "data = sys.stdin.buffer.read()\n"
        "open(sys.argv[-1], 'w').write(' '.join(sys.argv[1:-1]) + f' bytes={len(data)}')\n"
    )
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{fake.parent}:{os.environ['PATH']}")
    path = tmp_path / "a.mp4"
    count = animate(recorded_ds, path, fps=10.0, speedup=2.0, end=4.0, dpi=40)
    text = path.read_text()
    assert "-f rawvideo -pix_fmt rgb24 -s 320x160 -r 10 -i -" in text
    assert f"bytes={count * 320 * 160 * 3}" in text


@pytest.mark.slow
def test_memory_does_not_grow_with_the_number_of_frames(tmp_path):
    child = textwrap.dedent(
        """
        import resource, sys
        import metrosync
        from metrosync.show.animation import animate
        ds = metrosync.simulate(7, 192.0, duration=100.0, record_every=5, trajectories=True)
        animate(ds, sys.argv[1], fps=10.0, speedup=float(sys.argv[2]), dpi=80)
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
        """
    )
    peaks = {}
    for speedup in (10.0, 1.0):  # 101 and 1001 frames of 640 x 320 pixels
        out = subprocess.run([sys.executable, "-c", child, str(tmp_path / "a.gif"), str(speedup)],
                             capture_output=True, text=True, check=True)  # fmt: skip
        peaks[speedup] = int(out.stdout.split()[-1]) * 1024
    held = 900 * 640 * 320 * 4  # the 900 extra frames, were they kept: 737 MB
    assert peaks[1.0] - peaks[10.0] < 0.05 * held


def test_a_board_run_is_drawn_as_a_board(board_ds, recorded_ds, tmp_path):
    """A board run: the board from the side on two cans (its colours), no disk; the
    pendulums and the board move from frame to frame."""

    def pixels(frame, rgb):
        return int(np.count_nonzero(np.abs(frame.astype(int) - rgb).sum(axis=2) < 12))

    wood, can, disk = (0xE8, 0xD9, 0xBF), (0xD9, 0xDD, 0xE3), (237, 237, 237)
    for name, ds in (("board", board_ds), ("disk", recorded_ds)):
        assert animate(ds, tmp_path / f"{name}.gif", fps=4.0, speedup=4.0, end=8.0, dpi=40) == 9
    board, on_disk = gif_frames(tmp_path / "board.gif"), gif_frames(tmp_path / "disk.gif")
    assert pixels(board[0], wood) > 100 and pixels(board[0], can) > 50
    assert pixels(board[0], disk) < 20 < pixels(on_disk[0], disk)
    assert pixels(on_disk[0], wood) == 0
    moved = [
        np.abs(a.astype(int) - b.astype(int)).sum()
        for a, b in zip(board[:-1], board[1:], strict=True)
    ]
    assert min(moved) > 0
    view = animation.BoardView(animation.RecordedRun.from_dataset(board_ds), 0.0, 8.0)
    view.draw(5.0)
    assert " cm" in view.clock.get_text() and "rad" not in view.clock.get_text()

"""The animation: frame count, frames that move, formats and guards."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import metrosync
from metrosync.errors import ParameterError
from metrosync.show import animation
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
    monkeypatch.setattr(animation.shutil, "which", lambda name: None)
    with pytest.raises(ParameterError, match="ffmpeg"):
        animate(recorded_ds, tmp_path / "a.mp4")


@pytest.mark.parametrize(
    ("options", "match"),
    [({"fps": 0}, "`fps`"), ({"speedup": -1.0}, "`speedup`"), ({"end": 99.0}, "`end`"),
     ({"fps": 1000.0, "speedup": 0.001}, "frames exceed")],
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

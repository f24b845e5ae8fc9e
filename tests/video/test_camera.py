"""The camera model: what is rendered is where the projection says, timestamps read back
are the truth, and each impairment is there when asked and absent when not."""

from __future__ import annotations

from pathlib import Path

import av
import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.video.camera import Camera, Metronome, Scene, film

BPM_FREQUENCY = 1.6  # Hz, a metronome at 192 BPM


def swing(duration: float, n: int, *, amplitude=0.45, frequency=BPM_FREQUENCY, dt=5e-4):
    """A closed-form run: (times, theta (T, n)), metronome i shifted in phase."""
    t = np.arange(0.0, duration, dt)
    phases = np.arange(n) * 0.9
    return t, amplitude * np.sin(2 * np.pi * frequency * t[:, None] + phases[None, :])


def plain_scene(n: int = 1) -> Scene:
    """Contrasting colours on a plain background: a white rod and yellow bob on black."""
    ms = tuple(
        Metronome(
            x=0.3 * i,
            z=0.0,
            body_colour=(0.08, 0.08, 0.08),
            rod_colour=(0.95, 0.95, 0.95),
            bob_colour=(0.95, 0.85, 0.2),
        )  # fmt: skip
        for i in range(n)
    )
    return Scene(ms, wall_colour=(0.15, 0.15, 0.18), clutter=0, texture=0.0, disk=False)


def clean(**options) -> Camera:
    """A camera with no impairment, at a small size."""
    base = dict(width=320, height=240, fps=30.0)
    base.update(options)
    return Camera.ideal(**base)


def luma_frames(path: Path) -> tuple[np.ndarray, list[np.ndarray], list[int]]:
    """Decoded presentation times (s), luma planes (turned upright) and rotations."""
    times, planes, rotations = [], [], []
    with av.open(str(path)) as container:
        for frame in container.decode(video=0):
            times.append(float(frame.pts * frame.time_base))
            y = frame.to_ndarray()[: frame.height].astype(np.float32)
            planes.append(np.rot90(y, frame.rotation // 90))
            rotations.append(frame.rotation)
    return np.array(times), planes, rotations


def covered(mask: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Whether each point (K, 2) lies on a masked pixel or next to one."""
    grown = mask.copy()
    grown[1:] |= mask[:-1]
    grown[:-1] |= mask[1:]
    grown[:, 1:] |= mask[:, :-1]
    grown[:, :-1] |= mask[:, 1:]
    x = np.clip(np.round(points[:, 0]).astype(int), 0, mask.shape[1] - 1)
    y = np.clip(np.round(points[:, 1]).astype(int), 0, mask.shape[0] - 1)
    return grown[y, x]


def rod_end(mask, pivot, tip) -> float:
    """Farthest masked pixel from the pivot within 2 px of the line pivot → tip, in rod
    lengths along it."""
    ys, xs = np.nonzero(mask)
    d = tip - pivot
    length = np.hypot(*d)
    u = d / length
    rel = np.column_stack([xs, ys]) - pivot
    along = rel @ u
    across = np.abs(rel @ np.array([-u[1], u[0]]))
    near = (across < 2.0) & (along > 0)
    return float(along[near].max() / length)


def mirrored_pair(tmp_path, suffix, camera, theta_fn, duration=1.6):
    """The same scene filmed with θ and with −θ: their difference shows both rods only."""
    t, theta = theta_fn(duration)
    scene = plain_scene(theta.shape[1])
    a = film(tmp_path / f"a{suffix}", t, theta, scene=scene, camera=camera)
    b = film(tmp_path / f"b{suffix}", t, -theta, scene=scene, camera=camera)
    return a, b


@pytest.mark.parametrize("suffix, rotation", [(".mp4", 0), (".mov", 90)])
def test_rod_tip_is_where_the_projection_says(tmp_path, suffix, rotation):
    camera = clean(yaw_deg=30.0, pitch_deg=15.0, rotation=rotation)
    a, b = mirrored_pair(tmp_path, suffix, camera, lambda d: swing(d, 2))
    times_a, frames_a, rotations = luma_frames(a.path)
    _, frames_b, _ = luma_frames(b.path)
    assert set(rotations) == {rotation}
    assert frames_a[0].shape == (a.height, a.width)
    checked = 0
    for k in np.flatnonzero(np.abs(a.theta).min(axis=1) > 0.25)[::7][:6]:
        mask = np.abs(frames_a[k] - frames_b[k]) > 40
        tips = a.tip_at(a.theta[k])
        for i in range(a.n):
            pivot, tip = a.pivot_px[i], tips[i]
            along = np.linspace(0.3, 0.95, 40)[:, None]
            on_rod = pivot + along * (tip - pivot)
            assert covered(mask, on_rod).mean() > 0.9, (k, i)
            assert rod_end(mask, pivot, tip) == pytest.approx(1.0, abs=2.5 / a.rod_length_px[i])
            checked += 1
    assert checked >= 6


def test_rod_at_rest_lies_between_pivot_and_tip(tmp_path):
    camera = clean(yaw_deg=-25.0, pitch_deg=20.0)
    t = np.arange(0.0, 0.5, 1e-3)
    theta = np.zeros((t.size, 1))
    truth = film(tmp_path / "rest.mp4", t, theta, scene=plain_scene(1), camera=camera)
    _, frames, _ = luma_frames(truth.path)
    background = np.median(frames[0])
    rod = frames[0] > background + 80  # the white rod and yellow bob on a dark scene
    points = truth.pivot_px[0] + np.linspace(0.05, 0.97, 30)[:, None] * (
        truth.tip_px[0] - truth.pivot_px[0]
    )
    assert covered(rod, points).all()
    beyond = truth.pivot_px[0] + 1.15 * (truth.tip_px[0] - truth.pivot_px[0])
    assert not covered(rod, beyond[None])[0]
    assert np.allclose(truth.tip_at(np.zeros(1))[0], truth.tip_px[0])


@pytest.mark.parametrize("suffix", [".mp4", ".mov", ".mkv"])
def test_timestamps_read_back_equal_the_truth_with_jitter_and_drops(tmp_path, suffix):
    camera = Camera(fps=60, width=160, height=120, vfr_jitter_s=2e-3, drop_fraction=0.1)
    t, theta = swing(3.0, 2)
    truth = film(tmp_path / f"vfr{suffix}", t, theta, scene=Scene.random(2, 4), camera=camera)
    times, _, _ = luma_frames(truth.path)
    assert truth.dropped > 5
    assert times.size == truth.frame_times.size
    tick = 1e-3 if suffix == ".mkv" else 1 / 90000
    assert np.abs(times - truth.frame_times).max() < 1e-9
    steps = np.diff(times)
    assert steps.std() > 1e-3  # really variable
    assert steps.max() > 1.7 / 60  # drops show as gaps
    assert steps.min() > 0
    assert times[0] == 0.0
    assert np.allclose(times / tick, np.round(times / tick))


def test_file_says_30_fps_while_its_timestamps_vary(tmp_path):
    camera = Camera(fps=30, real_fps=24.0, vfr_jitter_s=3e-3, width=160, height=120)
    t, theta = swing(3.0, 1)
    truth = film(tmp_path / "nominal30.mkv", t, theta, scene=Scene.random(1, 2), camera=camera)
    with av.open(str(truth.path)) as container:
        stream = container.streams.video[0]
        assert stream.average_rate == 30
        assert stream.guessed_rate == 30
    times, _, _ = luma_frames(truth.path)
    assert np.abs(times - truth.frame_times).max() < 1e-9
    assert np.mean(np.diff(times)) == pytest.approx(1 / 24, rel=0.02)
    assert times.size == pytest.approx(24 * times[-1] + 1, abs=1)


@pytest.mark.parametrize("fps", [30, 60, 240])
def test_frame_rates(tmp_path, fps):
    camera = Camera(fps=fps, width=160, height=120, vfr_jitter_s=0.0)
    t, theta = swing(1.0, 1)
    truth = film(tmp_path / f"r{fps}.mp4", t, theta, scene=Scene.random(1, fps), camera=camera)
    times, _, _ = luma_frames(truth.path)
    assert np.allclose(np.diff(times), 1 / fps, atol=1 / 90000)
    assert times.size == truth.frame_times.size
    assert times.size >= 0.9 * fps
    with av.open(str(truth.path)) as container:
        assert container.streams.video[0].codec_context.name == "h264"


def test_avi_at_a_constant_rate(tmp_path):
    t, theta = swing(1.0, 1)
    truth = film(tmp_path / "c.avi", t, theta, scene=Scene.random(1, 5), camera=clean())
    with av.open(str(truth.path)) as container:
        dts = [float(p.dts * p.time_base) for p in container.demux(video=0) if p.dts is not None]
    assert np.allclose(dts, truth.frame_times)
    with pytest.raises(ParameterError, match="avi"):
        film(tmp_path / "v.avi", t, theta, scene=Scene.random(1, 5), camera=Camera())

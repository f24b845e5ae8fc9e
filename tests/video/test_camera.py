"""The camera model: what is rendered is where the projection says, timestamps read back
are the truth, and each impairment is there when asked and absent when not."""

from __future__ import annotations

from pathlib import Path

import av
import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.video import _scene_filming
from metrosync.video.camera import Camera, Metronome, Microphone, Scene, film, visibility

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


@pytest.mark.parametrize(
    "suffix, rotation", [(".mp4", 0), (".mov", 90), (".mkv", 270), (".mp4", 180)]
)
def test_rod_tip_is_where_the_projection_says(tmp_path, suffix, rotation):
    camera = clean(yaw_deg=30.0, pitch_deg=15.0, rotation=rotation)
    a, b = mirrored_pair(tmp_path, suffix, camera, lambda d: swing(d, 2))
    times_a, frames_a, rotations = luma_frames(a.path)
    _, frames_b, _ = luma_frames(b.path)
    assert {r % 360 for r in rotations} == {rotation}  # PyAV reports it in [-180, 180]
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


def test_truth_crossings_and_angles_are_the_trajectory_s(tmp_path):
    frequency, phases = BPM_FREQUENCY, np.arange(2) * 0.9
    t, theta = swing(6.0, 2)
    camera = Camera(fps=30, width=160, height=120, vfr_jitter_s=2e-3, drop_fraction=0.1)
    truth = film(tmp_path / "c.mp4", t, theta, scene=Scene.random(2, 1), camera=camera)
    sim = truth.frame_times + truth.start_s
    exact = 0.45 * np.sin(2 * np.pi * frequency * sim[:, None] + phases)
    assert np.abs(truth.theta - exact).max() < 1e-5
    for i in range(2):
        k = np.arange(20)
        ups = (k - phases[i] / (2 * np.pi)) / frequency - truth.start_s
        ups = ups[(ups >= 0) & (ups <= truth.frame_times[-1])]
        assert np.abs(truth.crossings[i] - ups).max() < 1e-7
        assert truth.ticks[i].size in (2 * ups.size - 1, 2 * ups.size, 2 * ups.size + 1)


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


def frame_means(path: Path) -> np.ndarray:
    _, frames, _ = luma_frames(path)
    return np.array([f.mean() for f in frames])


def still(duration=2.0, angle=0.2):
    t = np.arange(0.0, duration, 1e-3)
    return t, np.full((t.size, 1), angle)


def test_sensor_noise_only_when_asked(tmp_path):
    t, theta = still(1.0)
    stds = {}
    for noise in (0.0, 6.0):
        truth = film(
            tmp_path / f"n{noise}.mp4", t, theta, scene=plain_scene(), camera=clean(noise=noise)
        )
        _, frames, _ = luma_frames(truth.path)
        stds[noise] = float(np.median(np.std(np.array(frames[2:]), axis=0)))
    assert stds[0.0] < 0.5
    assert 3.0 < stds[6.0] < 8.0


def test_flicker_aliases_at_the_frame_rate_and_vanishes_over_a_full_cycle(tmp_path):
    t, theta = still(2.2)
    means = {}
    for name, options in {
        "off": {},
        "on": dict(flicker_hz=100.0, flicker_depth=0.3, exposure_s=1e-3),
        "cycle": dict(flicker_hz=100.0, flicker_depth=0.3, exposure_s=0.01),
    }.items():
        camera = clean(**options)
        means[name] = frame_means(film(tmp_path / f"{name}.mp4", t, theta, scene=plain_scene(),
                                       camera=camera).path)  # fmt: skip
    assert means["off"].std() < 0.3
    assert means["cycle"].std() < 0.3  # an exposure of one light cycle averages it out
    assert means["on"].std() > 2.0
    spectrum = np.abs(np.fft.rfft(means["on"] - means["on"].mean()))
    frequencies = np.fft.rfftfreq(means["on"].size, 1 / 30)
    assert frequencies[np.argmax(spectrum)] == pytest.approx(10.0, abs=0.6)  # |100 − 3·30|


def test_light_drifts_slowly_only_when_asked(tmp_path):
    t, theta = still(4.0)
    means = {}
    for drift in (0.0, 0.3):
        camera = clean(light_drift=drift)
        truth = film(tmp_path / f"d{drift}.mp4", t, theta, scene=plain_scene(), camera=camera)
        means[drift] = frame_means(truth.path)
    assert np.ptp(means[0.0]) < 0.5
    assert np.ptp(means[0.3]) > 3.0
    steps = np.abs(np.diff(means[0.3]))
    assert steps.max() < 0.1 * np.ptp(means[0.3])  # slow: no jumps between frames


def test_rolling_shutter_bands_the_flicker(tmp_path):
    t, theta = still(1.0)
    camera = clean(flicker_hz=100.0, flicker_depth=0.3, exposure_s=1e-3, rolling_shutter_s=0.03)
    truth = film(tmp_path / "bands.mp4", t, theta, scene=plain_scene(), camera=camera)
    _, frames, _ = luma_frames(truth.path)
    frames = np.array(frames)
    rows = (frames / frames.mean(axis=0)).mean(axis=2)[5]  # one frame's row profile
    spectrum = np.abs(np.fft.rfft(rows - rows.mean()))
    # 100 Hz seen over a 30 ms readout: 3 bright bands down the frame.
    assert np.argmax(spectrum) == 3
    assert truth.row_delay_s == pytest.approx(0.03 / 240)


def nearest_masked(mask: np.ndarray, point) -> float:
    ys, xs = np.nonzero(mask)
    return float(np.min(np.hypot(xs - point[0], ys - point[1])))


def test_rolling_shutter_films_each_row_at_its_own_time(tmp_path):
    amplitude, frequency = 0.6, 2.0

    def run(duration):
        return swing(duration, 1, amplitude=amplitude, frequency=frequency)

    camera = clean(rolling_shutter_s=1 / 30)
    a, b = mirrored_pair(tmp_path, ".mp4", camera, run)
    _, frames_a, _ = luma_frames(a.path)
    _, frames_b, _ = luma_frames(b.path)
    checked = 0
    for k in np.flatnonzero((np.abs(a.theta[:, 0]) > 0.15) & (np.abs(a.theta[:, 0]) < 0.35)):
        t = a.frame_times[k] + a.start_s
        tip = a.tip_at(a.theta[k])[0]
        for _ in range(6):  # the tip's row sets its time, its time sets its row
            angle = amplitude * np.sin(2 * np.pi * frequency * (t + a.row_delay_s * tip[1]))
            tip = a.tip_at(np.array([angle]))[0]
        mask = np.abs(frames_a[k] - frames_b[k]) > 40
        assert nearest_masked(mask, tip) < 1.5
        assert nearest_masked(mask, a.tip_at(a.theta[k])[0]) > 3.0
        checked += 1
    assert checked >= 4


def footprint(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: pixels that differ from the median picture, and those that differ by
    less than half the rod's full contrast."""
    _, frames, _ = luma_frames(path)
    frames = np.array(frames)
    diff = np.abs(frames - np.median(frames, axis=0))
    return (diff > 12).sum(axis=(1, 2)), ((diff > 12) & (diff < 80)).sum(axis=(1, 2))


def test_motion_blur_spreads_a_fast_rod(tmp_path):
    t, theta = swing(2.0, 1, amplitude=0.6, frequency=2.0)
    sharp = film(tmp_path / "s.mp4", t, theta, scene=plain_scene(), camera=clean())
    blurred = film(tmp_path / "b.mp4", t, theta, scene=plain_scene(),
                   camera=clean(exposure_s=1 / 60))  # fmt: skip
    assert blurred.exposure_s == pytest.approx(1 / 60)
    area_s, half_s = footprint(sharp.path)
    area_b, half_b = footprint(blurred.path)
    fast_s = np.abs(sharp.theta[:, 0]) < 0.2  # the fastest part of a swing
    fast_b = np.abs(blurred.theta[:, 0]) < 0.2
    assert fast_s.sum() >= 5 and fast_b.sum() >= 5
    assert np.median(area_b[fast_b]) > 2.0 * np.median(area_s[fast_s])
    # Smeared: many more pixels only partly covered (the pivot's end barely moves).
    assert np.median(half_b[fast_b]) > 3.0 * np.median(half_s[fast_s])


def test_bit_rate_is_the_one_asked(tmp_path):
    t, theta = swing(4.0, 2)
    sizes = {}
    for bitrate in (2e5, 1.6e6):
        camera = Camera(fps=30, width=320, height=240, bitrate=bitrate, noise=4.0)
        truth = film(tmp_path / f"{bitrate:g}.mp4", t, theta, scene=Scene.random(2, 9),
                     camera=camera)  # fmt: skip
        sizes[bitrate] = truth.path.stat().st_size * 8 / truth.frame_times[-1]
    assert sizes[1.6e6] == pytest.approx(1.6e6, rel=0.35)
    assert sizes[2e5] == pytest.approx(2e5, rel=0.5)


def audio_samples(path: Path) -> tuple[float, int, np.ndarray]:
    """Time of the first sample, sample rate, and the mono samples of the sound track."""
    blocks, start, rate = [], None, None
    with av.open(str(path)) as container:
        for frame in container.decode(audio=0):
            if start is None:
                start, rate = float(frame.pts * frame.time_base), frame.sample_rate
            data = frame.to_ndarray().reshape(-1).astype(np.float64)
            blocks.append(data / 32768.0 if frame.format.name == "s16" else data)
    return start, rate, np.concatenate(blocks)


@pytest.mark.parametrize("suffix, codec", [(".mp4", "aac"), (".mkv", "pcm_s16le")])
def test_sound_ticks_when_the_rod_passes_the_vertical(tmp_path, suffix, codec):
    t, theta = swing(4.0, 1)
    mic = Microphone(codec=codec, delay_s=0.03)
    truth = film(tmp_path / f"s{suffix}", t, theta, scene=Scene.random(1, 3), camera=clean(),
                 audio=mic)  # fmt: skip
    assert truth.audio and truth.audio_delay_s == 0.03
    start, rate, samples = audio_samples(truth.path)
    loud = np.flatnonzero(np.abs(samples) > 0.3)
    onsets = loud[np.concatenate([[True], np.diff(loud) > 0.05 * rate])]
    heard = start + onsets / rate
    expected = truth.ticks[0] + truth.audio_delay_s
    expected = expected[expected < start + samples.size / rate - 0.01]
    assert heard.size == expected.size
    assert np.abs(heard - expected).max() < 1.5e-3
    # Two ticks per period: the upward crossings are every other one.
    assert np.allclose(
        truth.crossings[0], truth.ticks[0][np.isin(truth.ticks[0], truth.crossings[0])]
    )
    assert truth.crossings[0].size in (truth.ticks[0].size // 2, (truth.ticks[0].size + 1) // 2)


@pytest.mark.parametrize(
    "change, argument",
    [
        (dict(theta=np.zeros((10, 3))), "theta"),
        (dict(theta=np.full((2000, 1), 2.0)), "theta"),
        (dict(theta=np.full((2000, 1), np.nan)), "theta"),
        (dict(times=np.zeros(2000)), "times"),
        (dict(path="clip.gif"), "path"),
        (dict(scene="three metronomes"), "scene"),
        (dict(camera=30), "camera"),
        (dict(audio="yes"), "audio"),
        (dict(path="clip.mp4", audio=Microphone(codec="pcm_s16le")), "codec"),
        (dict(times=np.arange(2000) * 1e-5), "too short"),
    ],
)
def test_bad_input_is_refused_naming_the_argument(tmp_path, change, argument):
    t, theta = swing(1.0, 1, dt=5e-4)
    args = dict(path="clip.mp4", times=t, theta=theta, scene=plain_scene(), camera=clean(),
                audio=None)  # fmt: skip
    args.update(change)
    path = tmp_path / args.pop("path")
    with pytest.raises(ParameterError, match=argument):
        film(path, args.pop("times"), args.pop("theta"), **args)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "options, argument",
    [
        (dict(fps=0), "fps"), (dict(width=321), "width"), (dict(height=250), "height"),
        (dict(yaw_deg=float("nan")), "yaw_deg"), (dict(rotation=45), "rotation"),
        (dict(exposure_s=0.1), "exposure_s"), (dict(drop_fraction=0.9), "drop_fraction"),
        (dict(noise=-1), "noise"), (dict(vfr_jitter_s=0.05), "vfr_jitter_s"),
        (dict(bitrate=True), "bitrate"),
    ],
)  # fmt: skip
def test_camera_checks_itself(options, argument):
    with pytest.raises(ParameterError, match=f"`{argument}`"):
        Camera(**options)


def test_interrupted_filming_leaves_no_file(tmp_path, monkeypatch):
    calls = []
    render = _scene_filming.Filming.render

    def interrupted(self, t):
        calls.append(t)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return render(self, t)

    monkeypatch.setattr(_scene_filming.Filming, "render", interrupted)
    t, theta = swing(1.0, 1)
    with pytest.raises(KeyboardInterrupt):
        film(tmp_path / "cut.mp4", t, theta, scene=plain_scene(), camera=clean(), audio=True)
    assert len(calls) == 4
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("n", range(1, 9))
def test_random_scenes_of_one_to_eight_metronomes_stay_in_the_picture(tmp_path, n):
    scene = Scene.random(n, seed=100 + n, overlap=0.5)
    assert scene.n == n
    t, theta = swing(0.4, n)
    camera = Camera(width=256, height=144, yaw_deg=-30.0 if n % 2 else 35.0)
    truth = film(tmp_path / "s.mp4", t, theta, scene=scene, camera=camera)
    extremes = truth.tip_at(np.full((2, n), 0.45) * np.array([[1.0], [-1.0]]))
    for points in (truth.pivot_px, truth.tip_px, *extremes):
        assert np.all((points >= 0) & (points <= [truth.width - 1, truth.height - 1]))
    if n > 1:
        gaps = np.hypot(*(truth.pivot_px[:, None] - truth.pivot_px[None]).transpose(2, 0, 1))
        assert np.min(gaps + 1e3 * np.eye(n)) > 2.0
    assert np.allclose(truth.visible, visibility(scene, camera))
    json = truth.to_json()
    assert f'"n": {n}' in json and '"frame_times"' in json


def test_random_scenes_vary_widely():
    scenes = [Scene.random(int(n), seed=s) for s, n in enumerate(np.arange(40) % 8 + 1)]
    metronomes = [m for scene in scenes for m in scene.metronomes]
    heights = np.array([m.body_height for m in metronomes])
    assert heights.max() > 1.6 * heights.min()
    assert len({m.body_colour for m in metronomes}) > 20
    assert len({scene.wall_colour for scene in scenes}) == len(scenes)
    assert np.ptp([scene.clutter for scene in scenes]) > 30
    overlapping = 0
    for scene in scenes:
        for a, b in zip(scene.metronomes, scene.metronomes[1:], strict=False):
            overlapping += abs(b.x - a.x) < 0.5 * (a.base_width + b.base_width)
    assert overlapping >= 5
    assert Scene.random(3, seed=1) == Scene.random(3, seed=1)
    assert Scene.random(3, seed=1) != Scene.random(3, seed=2)


def test_visibility_says_when_one_metronome_hides_another():
    front = Metronome(x=0.0, z=0.0, body_height=0.3, rod_length=0.2, bob_position=0.1)
    behind = Metronome(x=0.01, z=0.15, body_height=0.15, rod_length=0.12, bob_position=0.06)
    aside = Metronome(x=0.4, z=0.0)
    scene = Scene((front, behind, aside), clutter=0)
    square = visibility(scene, Camera.ideal(width=320, height=240))
    assert square[0] == pytest.approx(1.0) and square[2] == pytest.approx(1.0)
    assert square[1] < 0.3
    # From 40° to the right of the axis the one behind shows beside the one in front.
    aside_view = visibility(scene, Camera.ideal(width=320, height=240, yaw_deg=40.0))
    assert aside_view[1] > 0.8


def test_random_cameras_film_within_a_phones_range(tmp_path):
    cameras = [Camera.random(seed) for seed in range(40)]
    yaws = np.array([c.yaw_deg for c in cameras])
    assert np.all((np.abs(yaws) >= 20) & (np.abs(yaws) <= 40))
    assert (yaws > 0).any() and (yaws < 0).any()
    assert {c.fps for c in cameras} == {30.0, 60.0, 240.0}
    assert {c.flicker_hz for c in cameras} == {100.0, 120.0}
    assert Camera.random(3, fps=60.0, width=320, height=240).fps == 60.0
    t, theta = swing(1.0, 2)
    camera = Camera.random(7, width=320, height=240)
    truth = film(tmp_path / "r.mov", t, theta, scene=Scene.random(2, 7), camera=camera)
    times, _, _ = luma_frames(truth.path)
    assert np.abs(times - truth.frame_times).max() < 1e-9


def test_an_unwritable_path_is_named(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    t, theta = swing(1.0, 1)
    with pytest.raises(OSError, match="`path` = .*file/clip.mp4"):
        film(blocker / "clip.mp4", t, theta, scene=plain_scene(), camera=clean())
    assert [p.name for p in tmp_path.iterdir()] == ["file"]

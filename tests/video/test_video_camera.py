"""`track` on videos filmed by the camera model with every impairment on: perspective,
clutter, motion blur, rolling shutter, flicker, noise, H.264 at a phone's bit rate,
jittered timestamps and dropped frames, and a sound track late by 30 ms."""

import numpy as np
import pytest

from metrosync.observables import crossings as ph
from metrosync.video import track
from metrosync.video.camera import Camera, Microphone, Scene, film


def run(t_end, n, seed):
    """A closed-form run of ``n`` metronomes near 192 BPM drifting into step."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, t_end, 1e-3)
    freq = 1.6 + rng.normal(0, 0.015, n)
    phase = rng.uniform(0, 2 * np.pi, n) * np.exp(-t[:, None] / 6.0)  # phases converge
    amplitude = rng.uniform(0.3, 0.45, n)
    return t, amplitude * np.sin(2 * np.pi * freq * t[:, None] + phase)


def filmed(folder, fps, seed, n=3):
    t, theta = run(12.0, n, seed)
    camera = Camera(fps=fps, width=640, height=360, drop_fraction=0.03, vfr_jitter_s=0.001,
                    yaw_deg=30.0, flicker_hz=100.0)  # fmt: skip
    truth = film(folder / f"run{fps:g}.mp4", t, theta, camera=camera, seed=seed,
                 scene=Scene.random(n, seed=seed, overlap=0.0),
                 audio=Microphone(delay_s=0.03))  # fmt: skip
    return truth, track(truth.path)  # the readout estimated from the rods


@pytest.fixture(scope="module")
def at_60(tmp_path_factory):
    return filmed(tmp_path_factory.mktemp("camera"), 60.0, seed=2)


@pytest.fixture(scope="module")
def at_30(tmp_path_factory):
    return filmed(tmp_path_factory.mktemp("camera"), 30.0, seed=3)


def errors(truth, ds):
    """Per metronome (by the nearest pivot): crossing errors (s), and passes missed."""
    out = []
    for j in range(ds.sizes["metronome"]):
        i = int(np.argmin(np.hypot(truth.pivot_px[:, 0] - float(ds.pivot_x[j]),
                                   truth.pivot_px[:, 1] - float(ds.pivot_y[j]))))  # fmt: skip
        true, got = truth.crossings[i], ds.crossing_time.values[j]
        got = got[np.isfinite(got)]
        k = np.clip(np.searchsorted(got, true), 1, got.size - 1)
        near = np.where(np.abs(got[k - 1] - true) < np.abs(got[k] - true), got[k - 1], got[k])
        err = near - true
        out.append((i, err[np.abs(err) < 0.1], int(np.sum(np.abs(err) >= 0.1))))
    return out


@pytest.mark.parametrize("which, bound", [("at_60", 2e-3), ("at_30", 4e-3)])
def test_passes_are_timed_within_the_bound_with_every_impairment(which, bound, request):
    truth, ds = request.getfixturevalue(which)
    assert ds.sizes["metronome"] == truth.n
    found = errors(truth, ds)
    assert sorted(i for i, _, _ in found) == list(range(truth.n))  # one each, no swap
    for _, err, missed in found:
        assert missed <= 1  # the first, before a swing is seen
        assert np.sqrt(np.mean(err**2)) < bound


@pytest.mark.parametrize("which", ["at_60", "at_30"])
def test_r_follows_the_truth(which, request):
    truth, ds = request.getfixturevalue(which)
    passes = [ph.passes_on_period_grid(c) for c in truth.crossings]
    order = [i for i, _, _ in errors(truth, ds)]
    expected = ph.order_on_grid([passes[i] for i in order], ds.time.values)
    assert np.nanmax(np.abs(ds.r.values - expected)) < 0.02


def test_the_sound_is_heard_30_ms_after_the_passes(at_60):
    truth, ds = at_60
    assert ds.attrs["sound_agrees"] == 1
    # within 5 ms: the tick detector dates a click by its rise, a few ms into it
    assert ds.attrs["sound_latency"] == pytest.approx(truth.audio_delay_s, abs=0.005)


@pytest.mark.slow
@pytest.mark.parametrize("seeds", [0, 1000], ids=["scenes", "second-scenes"])
def test_the_number_of_metronomes_is_found_in_95_percent_of_scenes(seeds, tmp_path):
    # two sets of 24 scenes, N = 1 to 8: measured 23 of 24 in each (2026-11-27), never
    # too many; the rods missed have their body's shade and a bob that hardly shows either
    from metrosync.video.detection import DetectionError, find_metronomes
    from metrosync.video.reader import open_video
    from metrosync.video.tracking import _learning_pictures

    found = []
    for n in range(1, 9):
        for seed in range(3):
            rng = np.random.default_rng(100 * n + seed + seeds)
            t, theta = run(7.0, n, 100 * n + seed + seeds)
            camera = Camera(fps=30, width=640, height=360, vfr_jitter_s=0.002,
                            drop_fraction=0.02,
                            yaw_deg=float(rng.uniform(20, 40) * rng.choice([-1, 1])))  # fmt: skip
            scene = Scene.random(n, seed=100 * n + seed + seeds, overlap=0.0)
            film(tmp_path / "scene.mp4", t, theta, scene=scene, camera=camera, seed=seed + seeds)
            pictures = _learning_pictures(open_video(tmp_path / "scene.mp4"), 640, 6.0)
            try:
                found.append(len(find_metronomes(pictures)) - n)
            except DetectionError:
                found.append(-n)
    right = sum(extra == 0 for extra in found)
    assert right >= 0.95 * len(found), f"found the right number in {right} of {len(found)}"
    assert max(found) <= 0, f"found too many in {sum(extra > 0 for extra in found)} scenes"


def test_the_rolling_shutter_is_estimated_from_the_rods(at_60, at_30):
    for truth, ds in (at_60, at_30):
        readout = truth.row_delay_s * truth.height
        assert ds.attrs["readout"] == pytest.approx(readout, rel=0.3)


def test_a_phone_held_upright_is_turned_and_its_shutter_dated(tmp_path):
    # portrait: the picture is stored on its side, so the shutter's rows run across it
    t, theta = run(12.0, 2, 5)
    camera = Camera(fps=60, width=640, height=360, rotation=90, drop_fraction=0.02,
                    vfr_jitter_s=0.001)  # fmt: skip
    truth = film(tmp_path / "portrait.mp4", t, theta, camera=camera, seed=5,
                 scene=Scene.random(2, seed=5, overlap=0.0))  # fmt: skip
    ds = track(truth.path, sound=False)
    assert ds.attrs["video_size"] == "360x640"
    found = errors(truth, ds)
    assert sorted(i for i, _, _ in found) == [0, 1]
    for _, err, missed in found:
        assert missed <= 1 and np.sqrt(np.mean(err**2)) < 2e-3

"""`track` on drawn videos: passes, r, identity, perspective, sound, and the dataset."""

import numpy as np
import pytest
import synth_video

from metrosync.observables import crossings as ph
from metrosync.video import track
from metrosync.video.detection import DetectionError, find_metronomes
from metrosync.video.reader import open_video
from metrosync.video.tracking import _learning_pictures


def matched(true, got):
    """(errors of the passes found, passes missed): each true pass against the nearest."""
    got = got[np.isfinite(got)]
    k = np.clip(np.searchsorted(got, true), 1, max(got.size - 1, 1))
    nearest = np.where(np.abs(got[k - 1] - true) < np.abs(got[k] - true), got[k - 1], got[k])
    err = nearest - true
    found = np.abs(err) < 0.1
    return err[found], int((~found).sum())


def true_r(times, theta, grid):
    passes = [ph.passes_on_period_grid(ph.zero_crossings(times, th)) for th in theta.T]
    return ph.order_on_grid(passes, grid)


@pytest.fixture(scope="module")
def tracked(three_rods):
    path, times, theta, pivots = three_rods
    return track(path), times, theta, pivots


def test_passes_are_timed_well_inside_a_frame_at_30_fps(tracked):
    ds, times, theta, pivots = tracked
    assert ds.sizes["metronome"] == 3
    for j in range(3):
        # identity: metronome j is the rod drawn about pivot j, and its passes are its own
        assert np.hypot(ds.pivot_x[j] - pivots[j, 0], ds.pivot_y[j] - pivots[j, 1]) < 3
        err, missed = matched(ph.zero_crossings(times, theta[:, j]), ds.crossing_time.values[j])
        assert missed <= 1  # the first pass may fall before a swing is seen
        assert np.sqrt(np.mean(err**2)) < 1.5e-3


def test_r_and_frequencies_follow_the_truth(tracked):
    ds, times, theta, _ = tracked
    truth = true_r(times, theta, ds.time.values)
    assert np.nanmax(np.abs(ds.r.values - truth)) < 0.02
    freq_true = [ph.mean_frequency_bpm(*ph.passes_on_period_grid(ph.zero_crossings(times, th)))
                 for th in theta.T]  # fmt: skip
    assert np.allclose(ds.frequency_bpm.values, freq_true, atol=0.1)
    assert np.allclose(np.nanmedian(ds.amplitude.values, axis=1), 0.45, atol=0.01)
    assert np.all(np.abs(ds.asymmetry.values) < 0.5)  # drawn symmetric


def test_the_dataset_reads_like_the_light_gates(tracked, tmp_path):
    from metrosync.lightgate.plots import plot_analysis

    ds = tracked[0]
    for name in ("r", "r_runs", "frequency_bpm", "frequency_bpm_runs", "period_jitter",
                 "passes_kept", "passes_bridged"):  # fmt: skip
        assert name in ds
    assert ds.r_runs.dims == ("log", "time") and ds.frequency_bpm.dims == ("metronome",)
    for name in ("r_eq", "sigma_bpm", "equilibrium_window"):
        assert np.isfinite(ds.attrs[name])
    plot_analysis(ds, tmp_path / "r.png")
    assert (tmp_path / "r.png").stat().st_size > 0
    quality = ds.angle_quality.values
    assert set(np.unique(quality)) <= {0, 1, 2}
    assert np.all((ds.angle_confidence.values >= 0) & (ds.angle_confidence.values <= 1))


@pytest.mark.parametrize("n", [1, 4, 8])
def test_metronomes_are_found_and_counted(tmp_path, n):
    # eight in 480 pixels: each swing overlaps its neighbours' in the picture
    synth_video.scene(tmp_path / "n.mp4", n=n, seconds=6, seed=n)
    pictures = _learning_pictures(open_video(tmp_path / "n.mp4"), 640, 6.0)
    assert len(find_metronomes(pictures)) == n
    assert len(find_metronomes(pictures, count=n)) == n
    with pytest.raises(DetectionError, match=f"not the {n + 2} asked for"):
        find_metronomes(pictures, count=n + 2)


def test_overlapping_rods_keep_their_identity(tmp_path):
    # two pivots 40 px apart with 75 px rods swinging ±26°: the rods cross each other
    path = tmp_path / "close.mp4"
    rng = np.random.default_rng(1)
    times = np.arange(0, 12, 1 / 30)
    theta = synth_video.angles_sine(times, [1.4, 1.47], 0.45, [0.0, 2.0])
    pivots = [(220, 220), (260, 220)]
    pictures = (synth_video.draw(th, pivots, length=75, noise=3, rng=rng) for th in theta)
    synth_video.write_video(path, times, pictures)
    ds = track(path)
    assert ds.sizes["metronome"] == 2
    for j in range(2):
        err, missed = matched(ph.zero_crossings(times, theta[:, j]), ds.crossing_time.values[j])
        assert missed <= 1 and np.sqrt(np.mean(err**2)) < 3e-3
        seen = ds.angle_quality.values[:, j] == 0
        assert np.max(np.abs(ds.angle.values[seen, j] - theta[seen, j])) < 0.05


def test_a_camera_off_square_is_corrected_by_view_angle(tmp_path):
    # seen 35° off square, the horizontal shrinks by cos 35°: tan(seen) = tan(θ) cos 35°
    path = tmp_path / "oblique.mp4"
    times = np.arange(0, 10, 1 / 30)
    theta = synth_video.angles_sine(times, [1.4], 0.45, [0.3])
    seen = np.arctan(np.tan(theta) * np.cos(np.radians(35)))
    pictures = (synth_video.draw(th, [(240, 220)], length=75) for th in seen)
    synth_video.write_video(path, times, pictures)
    square = track(path)
    corrected = track(path, view_angle=35)
    amp = [np.nanmedian(ds.amplitude.values) for ds in (square, corrected)]
    assert amp[0] == pytest.approx(np.arctan(np.tan(0.45) * np.cos(np.radians(35))), abs=0.01)
    assert amp[1] == pytest.approx(0.45, abs=0.01)


def test_the_sound_track_is_timed_against_the_passes(two_with_sound):
    path = two_with_sound[0]
    ds = track(path)
    assert ds.attrs["sound_agrees"] == 1
    assert abs(ds.attrs["sound_latency"]) < 0.005  # the clicks were placed at the passes
    assert "agree" in ds.attrs["sound"]
    assert track(path, sound=False).attrs["sound_agrees"] == -1


def test_options_are_checked_with_their_names():
    with pytest.raises(ValueError, match="`count`"):
        track("x.mp4", count=0)
    with pytest.raises(ValueError, match="`view_angle`"):
        track("x.mp4", view_angle=85)
    with pytest.raises(ValueError, match="`vertical`"):
        track("x.mp4", vertical="up")
    with pytest.raises(ValueError, match="`regions`"):
        track("x.mp4", regions=[])


@pytest.mark.parametrize("lag, z", [(0.0, 1.0), (np.pi, -1.0)])
def test_z_of_two_metronomes_in_and_out_of_phase(tmp_path, lag, z):
    path = tmp_path / "two.mp4"
    times = np.arange(0, 10, 1 / 30)
    theta = synth_video.angles_sine(times, [1.5, 1.5], 0.4, [0.3, 0.3 + lag])
    pictures = (synth_video.draw(th, [(110, 150), (210, 150)], size=(320, 180), length=60)
                for th in theta)  # fmt: skip
    synth_video.write_video(path, times, pictures)
    ds = track(path)
    assert ds.attrs["z"] == pytest.approx(z, abs=0.1)
    assert ds.attrs["r_eq"] == pytest.approx(1.0 if lag == 0 else 0.0, abs=0.02)


def test_a_box_given_by_hand_finds_the_pivot_inside(three_rods):
    path, _, _, pivots = three_rods
    x, y = pivots[1]
    ds = track(path, regions=[(x - 60, y - 90, x + 60, y + 10)])
    assert ds.sizes["metronome"] == 1
    assert float(ds.pivot_x[0]) == pytest.approx(x, abs=3)
    assert float(ds.pivot_y[0]) == pytest.approx(y, abs=3)

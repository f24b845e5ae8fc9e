"""The checks `track` makes before its work, and the measurements it may not make:
the header's frame count, the budget, regions against the picture, z over lost frames,
and a rolling shutter the rods cannot measure."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
import synth_video

from metrosync.budget import ResourceError
from metrosync.errors import ParameterError
from metrosync.observables.zorder import z_order
from metrosync.video import dataset, shutter
from metrosync.video.budget import tracking_budget
from metrosync.video.reader import VideoFileError, open_video
from metrosync.video.regions import OUTSIDE_REACH, check_in_frame, read_regions
from metrosync.video.tracking import LEARN_PICTURES, track


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    path = tmp_path_factory.mktemp("hardening") / "clip.mp4"
    synth_video.scene(path, n=2, seconds=4, size=(160, 90), seed=2)
    return path


def stated(healthy, path, frames):
    data = bytearray(healthy.read_bytes())
    at = data.find(b"stts") + 12
    data[at : at + 4] = struct.pack(">I", frames)
    path.write_bytes(bytes(data))
    return path


def test_a_healthy_header_gives_its_frame_count(clip):
    assert open_video(clip).frames_estimate == 120


@pytest.mark.parametrize("frames", [2399143057, 1000])
def test_a_frame_count_the_header_contradicts_is_refused(clip, tmp_path, frames):
    # 1000 frames would fit in the file's bytes, but 4 s at 30 fps make 120
    with pytest.raises(VideoFileError, match="has a damaged header: it states"):
        open_video(stated(clip, tmp_path / "bad.mp4", frames))


def test_a_count_near_the_one_length_and_rate_make_is_kept(clip, tmp_path):
    # the same frames counted twice agree to a frame or two, whatever the timestamps do
    assert open_video(stated(clip, tmp_path / "near.mp4", 122)).frames_estimate == 122


def test_the_budget_counts_the_grid_the_frames_and_the_pictures(clip):
    video = open_video(clip)
    options = dict(max_side=640, learn=6.0, most_pictures=LEARN_PICTURES)
    plain = tracking_budget(video, metronomes=2, grid_dt=0.1, **options)
    fine = tracking_budget(video, metronomes=2, grid_dt=1e-6, **options)
    assert plain.nbytes < 50e6 and plain.seconds == 0.0  # no time is guessed
    assert fine.arrays["the r(t) grid"] == pytest.approx(4.0 / 1e-6 * (64 + 48 * 2), rel=0.01)
    assert "a larger `grid_dt` (now 1e-06 s" in fine.fixes
    with pytest.raises(ResourceError, match="tracking clip.mp4 would need about"):
        fine.check(available=5e8)
    timed = tracking_budget(video, metronomes=2, grid_dt=0.1, seconds_per_frame=0.01,
                            frames_done=20, **options)  # fmt: skip
    assert timed.seconds == pytest.approx(100 * 0.01)
    assert "a smaller `max_side` (now 640)" in timed.fixes


def test_the_library_refuses_before_decoding(clip, monkeypatch):
    from metrosync.video import reader

    def frames(self, **_):
        raise AssertionError("decoded")

    monkeypatch.setattr(reader.Video, "frames", frames)
    for options, argument in [
        (dict(equilibrium_window=0.0), "`equilibrium_window` must be a time > 0 s"),
        (dict(equilibrium_window=math.nan), "`equilibrium_window` must be a time > 0 s"),
        (dict(grid_dt=2.5), "`grid_dt` 2.5 s is longer than half of clip.mp4 (4.0 s)"),
        (dict(regions=[(80, 45), (700, 45)]), "`regions` 2 of 2, the pivot (700, 45)"),
    ]:
        with pytest.raises(ParameterError) as refused:
            track(clip, **options)
        assert argument in str(refused.value)
    with pytest.raises(ResourceError, match="the r\\(t\\) grid"):
        track(clip, grid_dt=1e-12)


def test_regions_may_lie_outside_the_picture_within_reach():
    check_in_frame([(160, -100), (-60, 90), (400, 200)], (320, 180))
    check_in_frame([(-50, -50, 10, 10)], (320, 180))  # overlaps the picture by 10 px
    reach = OUTSIDE_REACH * 320
    with pytest.raises(ParameterError, match=f"lies {reach + 1:.0f} px above"):
        check_in_frame([(160, -reach - 1)], (320, 180))
    with pytest.raises(ParameterError, match="shows less than 8 px"):
        check_in_frame([(-50, -50, 5, 5)], (320, 180))


def test_a_regions_file_may_give_a_pivot_above_the_picture(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text("320 -900\n-5.5, 10\n")
    assert read_regions(path) == [(320.0, -900.0), (-5.5, 10.0)]


def two_rods(seconds=10.0, fps=30.0):
    t = np.arange(0, seconds, 1 / fps)
    return t, synth_video.angles_sine(t, [1.4, 1.43], 0.45, [0.0, 2.0])


def test_z_is_measured_across_lost_frames():
    # was NaN as soon as one frame of the final window was lost
    t, theta = two_rods()
    start = 7.0
    whole, _ = dataset._z(t, theta, start)
    assert whole == pytest.approx(z_order(t, theta[:, 0], theta[:, 1], start=start), abs=0.02)
    for rod, lost in [(1, slice(250, 258)), (0, slice(230, 236)), (1, slice(211, 212))]:
        gappy = theta.copy()
        gappy[lost, rod] = np.nan
        z, note = dataset._z(t, gappy, start)
        assert note == "" and z == pytest.approx(whole, abs=0.05), (rod, lost)


def test_z_says_why_it_is_not_measured():
    t, theta = two_rods()
    theta[::5, 1] = np.nan  # no stretch of 7 frames seen
    z, note = dataset._z(t, theta, 7.0)
    assert math.isnan(z)
    assert note.startswith("z not measured: both rods are seen together in 0 frames of the last")


@pytest.mark.parametrize(
    "readout, error, interval, kept",
    [(0.016, 0.0039, 1 / 30, True), (0.035, 0.021, 1 / 30, False),
     (0.05, 0.283, 1 / 30, False), (0.004, 0.0009, 1 / 240, True),
     (0.004, 0.002, 1 / 240, False), (0.0, math.nan, 1 / 30, False)],
)  # fmt: skip
def test_a_readout_is_kept_only_when_its_error_is_small_against_its_range(
    readout, error, interval, kept
):
    value, err, how = shutter.readout_verdict(readout, error, interval)
    if kept:
        assert (value, err) == (readout, error) and how.startswith("estimated from the rods' skew")
    else:
        assert value == 0.0 and math.isnan(err) and how.startswith("not measurable")


def test_the_longest_readout_is_the_frame_interval_when_shorter():
    assert shutter.longest_readout(1 / 240) == pytest.approx(1 / 240)
    assert shutter.longest_readout(1 / 10) == shutter.MAX_READOUT


@pytest.mark.parametrize("grid_dt", [0.1, 5e-6], ids=["pictures", "grid"])
def test_the_budget_covers_what_tracking_allocates_and_not_far_more(two_rods_clip, grid_dt):
    import tracemalloc

    tracemalloc.start()
    try:
        track(two_rods_clip, grid_dt=grid_dt, sound=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    budget = tracking_budget(open_video(two_rods_clip), metronomes=2, max_side=640, learn=6.0,
                             grid_dt=grid_dt, most_pictures=LEARN_PICTURES)  # fmt: skip
    assert peak <= budget.nbytes <= 3 * peak, (peak, budget.arrays)


@pytest.fixture(scope="module")
def two_rods_clip(tmp_path_factory):
    path = tmp_path_factory.mktemp("hardening") / "two.mp4"
    synth_video.scene(path, n=2, seconds=6, size=(320, 180), seed=2)
    return path

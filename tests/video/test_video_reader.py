"""Reading videos: the container's times, rotation, streaming, and every bad file."""

from fractions import Fraction

import av
import numpy as np
import pytest
import synth_video

from metrosync.video.reader import VideoFileError, open_video


def test_a_nominal_30_fps_file_with_varying_times_is_read_at_its_real_times(tmp_path, rng):
    # what phones write: a "30 fps" file whose frames come 25..45 ms apart, some dropped
    steps = rng.uniform(0.025, 0.045, 150)
    steps[40] = 0.1  # two frames dropped
    times = np.concatenate([[0.0], np.cumsum(steps)])
    pictures = [synth_video.draw([0.3 * np.sin(t * 9)], [(80, 100)], size=(160, 120))
                for t in times]  # fmt: skip
    path = synth_video.write_video(tmp_path / "vfr.mp4", times, pictures, rate=30,
                                   time_base=Fraction(1, 600))  # fmt: skip
    video = open_video(path)
    got = np.array([t for t, _ in video.frames()])
    assert got.size == times.size
    # PTS in a 1/600 s time base: within half a tick of the times written
    assert np.max(np.abs(got - times)) <= 1 / 1200 + 1e-9
    # a nominal-rate clock would be off by far more than a frame by the end
    assert abs(got[-1] - (times.size - 1) / 30) > 0.2


@pytest.mark.parametrize("rotation", [90, -90, 180])
def test_the_rotation_a_phone_stores_is_undone(tmp_path, rotation):
    picture = np.zeros((64, 128), np.uint8)
    picture[:16, :16] = 255  # a mark in the stored picture's top-left corner
    path = synth_video.write_video(tmp_path / "rot.mp4", np.arange(3) / 30, [picture] * 3,
                                   rotation=rotation)  # fmt: skip
    video = open_video(path)
    assert video.rotation == rotation % 360
    _, shown = next(video.frames())
    expected = np.rot90(picture, rotation // 90)  # counter-clockwise by the stored angle
    assert shown.shape == expected.shape == video.upright_size[::-1]
    assert np.mean(np.abs(shown.astype(float) - expected)) < 8


def test_pictures_are_reduced_and_streamed_one_at_a_time(three_rods):
    path, times, _, _ = three_rods
    video = open_video(path)
    frames = video.frames(max_side=240)
    t, picture = next(frames)
    assert picture.shape == (136, 240) and picture.dtype == np.uint8
    assert not isinstance(frames, list | tuple)
    assert sum(1 for _ in frames) == times.size - 1


def test_not_a_video_is_refused_with_what_to_give(tmp_path):
    path = tmp_path / "notes.mp4"
    path.write_text("not a video")
    with pytest.raises(VideoFileError, match="cannot read .* as a video.*MP4, MOV, MKV"):
        open_video(path)
    with pytest.raises(VideoFileError, match="does not exist"):
        open_video(tmp_path / "missing.mov")
    (tmp_path / "empty.mkv").write_bytes(b"")
    with pytest.raises(VideoFileError, match="empty"):
        open_video(tmp_path / "empty.mkv")


def test_an_audio_only_file_points_to_the_sound_analysis(tmp_path):
    path = tmp_path / "voice.m4a"
    with av.open(str(path), "w") as out:
        stream = out.add_stream("aac", rate=44100)
        stream.layout = "mono"
        for i in range(10):
            frame = av.AudioFrame.from_ndarray(np.zeros((1, 1024), np.float32), format="fltp",
                                               layout="mono")  # fmt: skip
            frame.sample_rate, frame.pts = 44100, i * 1024
            for packet in stream.encode(frame):
                out.mux(packet)
        for packet in stream.encode():
            out.mux(packet)
    with pytest.raises(VideoFileError, match="no video stream.*sound recording.*analyze"):
        open_video(path)


def test_an_mp4_cut_before_its_index_says_so(three_rods, tmp_path):
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(three_rods[0].read_bytes()[:100_000])
    with pytest.raises(VideoFileError, match="cut short before its index"):
        open_video(cut)


def test_a_truncated_mkv_yields_what_was_readable_and_says_the_loss(tmp_path):
    path = tmp_path / "whole.mkv"
    times, _, _ = synth_video.scene(path, n=1, seconds=8, size=(160, 90), noise=0)
    cut = tmp_path / "cut.mkv"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    video = open_video(cut)
    got = [t for t, _ in video.frames()]
    assert 0.2 * times.size < len(got) < 0.8 * times.size
    assert "cut short" in video.loss and "s are lost" in video.loss

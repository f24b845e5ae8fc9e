"""``metrosync track`` refuses what cannot work before it decodes the video, measures how
long the rest will take, and never prints a temporary path or a NaN as a measurement."""

from __future__ import annotations

import re
import struct
import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "video"))

import synth_video  # noqa: E402

from metrosync.cli import main  # noqa: E402
from metrosync.video import angles, reader  # noqa: E402

SIZE = (320, 180)


def run(capsys, *argv):
    code = main(["track", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def two_rods(tmp_path_factory):
    """Two upright rods, 8 s of 320x180 at 30 fps."""
    path = tmp_path_factory.mktemp("track") / "two.mp4"
    synth_video.scene(path, n=2, seconds=8, size=SIZE, seed=1)
    return path


@pytest.fixture
def no_decoding(monkeypatch):
    """Fail the test if any frame is decoded past the one `open_video` checks."""

    def frames(self, **_):
        raise AssertionError("a frame was decoded before the request was refused")

    monkeypatch.setattr(reader.Video, "frames", frames)


def test_a_grid_too_fine_for_memory_is_refused_before_a_frame(two_rods, capsys, no_decoding):
    # was: 12.8 s of tracking, then "Unable to allocate 139. TiB"
    code, _, err = run(capsys, two_rods, "--grid-dt", "1e-12")
    assert code == 2, err
    line = err.strip().splitlines()[-1]
    assert "of memory" in line and "the r(t) grid" in line
    assert "a larger `grid_dt` (--grid-dt) (now 1e-12 s" in line


def test_a_grid_longer_than_the_video_is_refused_before_a_frame(two_rods, capsys, no_decoding):
    code, _, err = run(capsys, two_rods, "--grid-dt", "1e12")
    assert code == 2, err
    assert "`grid_dt` (--grid-dt) 1e+12 s is longer than half of two.mp4 (8.0 s)" in err


def test_a_window_longer_than_the_video_is_refused_before_a_frame(two_rods, capsys, no_decoding):
    code, _, err = run(capsys, two_rods, "--window", "30")
    assert code == 2, err
    assert "`equilibrium_window` (--window) 30 s is not shorter than two.mp4" in err


@pytest.mark.parametrize("option", ["--window", "--grid-dt"])
@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "soon"])
def test_a_time_no_video_could_use_is_refused_while_parsing(
    two_rods, capsys, no_decoding, option, value
):
    with pytest.raises(SystemExit) as stop:
        main(["track", str(two_rods), option, value])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}: expected a time in seconds, finite and > 0" in err
    assert repr(value) in err


def damaged(healthy: Path, path: Path, frames: int = 2399143057) -> Path:
    """A copy of ``healthy`` whose header states ``frames`` frames (its stts box)."""
    data = bytearray(healthy.read_bytes())
    at = data.find(b"stts") + 12  # version and flags, entry count, then the first count
    data[at : at + 4] = struct.pack(">I", frames)
    path.write_bytes(bytes(data))
    return path


def test_a_damaged_header_is_refused_before_a_frame(two_rods, tmp_path, capsys, no_decoding):
    # was: "about 2399143057 frames ... about 6151.7 h of work", then it tracked 240
    bad = damaged(two_rods, tmp_path / "bad.mp4")
    code, _, err = run(capsys, bad, "--no-sound")
    assert code == 2, err
    line = err.strip().splitlines()[-1]
    assert "has a damaged header: it states 2399143057 frames, but 8 s at 30 fps make " in line
    assert "can hold at most" in line and "`ffmpeg -i bad.mp4 -c copy fixed.mp4`" in line


def test_the_time_left_is_measured_on_the_frames_tracked(two_rods, capsys, monkeypatch):
    # was: a guess from decoding alone ("expect about 3 s" for 23.7 s); measuring a rod
    # here costs 4 ms more than it did, which only a measured rate can know
    measure = angles.RodGauge.measure
    ends = []

    def slow(self, *args):
        time.sleep(0.004)
        ends.append(time.perf_counter())
        return measure(self, *args)

    monkeypatch.setattr(angles.RodGauge, "measure", slow)
    said = []
    from metrosync.video import track

    track(two_rods, sound=False, report=lambda line: said.append((time.perf_counter(), line)))
    when, line = said[-1]
    found = re.search(r"at ([\d.]+) ms a frame, .* expect about ([\d.]+) s more", line)
    assert found, line
    assert float(found[1]) >= 2 * 4.0  # two rods a frame
    took = ends[-1] - when
    assert 0.5 * took <= float(found[2]) <= 2.0 * took, (line, took)


@pytest.fixture
def slow_rods(monkeypatch):
    """Each rod measured 3 ms slower, so that the rate is measured (after
    CALIBRATION_SECONDS of tracking) on any machine, and a few seconds are "long"."""
    measure = angles.RodGauge.measure

    def slow(self, *args):
        time.sleep(0.003)
        return measure(self, *args)

    monkeypatch.setattr(angles.RodGauge, "measure", slow)


def test_long_work_is_warned_of_from_the_measured_rate(two_rods, capsys, monkeypatch, slow_rods):
    import metrosync.budget

    monkeypatch.setattr(metrosync.budget, "WARN_SECONDS", 0.5)  # a few minutes, scaled down
    code, _, err = run(capsys, two_rods, "--no-sound")
    assert code == 0, err
    warned = [line for line in err.splitlines() if "warning:" in line]
    assert len(warned) == 1, err
    assert re.search(r"tracking two.mp4 is estimated to take about \d+ s \(\d+ frames left, 2 "
                     r"metronomes, measured at [\d.]+ ms a frame\); Ctrl-C stops it, or a smaller "
                     r"`max_side` \(--resolution\) \(now 640\)", warned[0]), warned[0]  # fmt: skip


def test_the_line_before_the_work_states_the_header_only(two_rods, capsys, slow_rods):
    # the rate is measured only after CALIBRATION_SECONDS of tracking: on a fast machine
    # these 240 small frames are all tracked sooner, and the line is rightly not given
    code, _, err = run(capsys, two_rods, "--no-sound")
    assert code == 0, err
    first, second = err.strip().splitlines()[:2]
    assert first.startswith("two.mp4: 320x180 h264, 8.0 s, about 240 frames at 30 fps")
    assert "expect" not in first  # nothing was measured yet
    assert re.search(r"tracking 2 metronomes at [\d.]+ ms a frame, measured on the first", second)


def regions_file(tmp_path, text):
    path = tmp_path / "regions.txt"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "text, said",
    [("99999 5\n", "lies 99680 px right of the video's 320x180 picture"),
     ("160 90\n320 -900\n", "`regions` (--regions) 2 of 2, the pivot (320, -900), lies 900 px "
                            "above the video's 320x180 picture"),
     ("5000 5000 6000 6000\n", "shows less than 8 px of the video's 320x180 picture")],
)  # fmt: skip
def test_regions_the_picture_cannot_show_are_refused_before_a_frame(
    two_rods, tmp_path, capsys, no_decoding, text, said
):
    # was: '99999 5' accepted, then "passes the vertical 0 times" after the tracking
    code, _, err = run(capsys, two_rods, "--regions", regions_file(tmp_path, text))
    assert code == 2, err
    assert said in err and "x 0..319, y 0..179" in err


@pytest.fixture(scope="module")
def hanging(tmp_path_factory):
    """Two pendulums hung from 40 px above a 320x180 picture, swinging at 1.3 and 1.45 Hz."""
    path = tmp_path_factory.mktemp("track") / "hanging.mp4"
    t = np.arange(0, 8, 1 / 30)
    theta = np.pi + synth_video.angles_sine(t, [1.3, 1.45], 0.3, [0.0, 1.0])
    pivots = [(110, -40), (220, -40)]
    rng = np.random.default_rng(0)
    pictures = (synth_video.draw(th, pivots, size=SIZE, length=200, noise=3, rng=rng)
                for th in theta)  # fmt: skip
    synth_video.write_video(path, t, pictures)
    return path


def test_a_pivot_above_the_picture_is_tracked(hanging, tmp_path, capsys):
    # was: "'110 -40' is not each line 'x y'": a hanging pendulum's pivot is out of view
    code, out, err = run(capsys, hanging, "--regions", regions_file(tmp_path, "110 -40\n220 -40"))
    assert code == 0, err
    rows = [line.split() for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert [r[2] for r in rows] == ["-40", "-40"]
    # a tick at each pass: 2 x 60 x 1.3 and 2 x 60 x 1.45 a minute
    assert [float(r[3]) for r in rows] == pytest.approx([156.0, 174.0], abs=0.5)


def test_a_pivot_outside_with_no_rod_in_view_is_refused(hanging, tmp_path, capsys):
    code, _, err = run(capsys, hanging, "--regions", regions_file(tmp_path, "-100 90\n"))
    assert code == 2, err
    assert "no rod is seen swinging about the pivot (-100, 90), outside the video's picture" in err


def test_a_silent_sound_track_is_named_as_the_video_s(tmp_path, capsys):
    # was: "recording '/tmp/tmpab12/track.wav' is silent"
    path = tmp_path / "mute.mp4"
    t = np.arange(0, 8, 1 / 30)
    theta = synth_video.angles_sine(t, [1.4, 1.5], 0.45, [0.0, 2.0])
    pivots = [(107, 144), (213, 144)]
    pictures = (synth_video.draw(th, pivots, size=SIZE, length=50) for th in theta)
    synth_video.write_video(path, t, pictures, audio=np.zeros(44100 * 8))
    code, out, err = run(capsys, path)
    assert code == 0, err
    assert "warning: the sound track of mute.mp4 is silent: every sample is 0." in err
    assert "the sound was not used" in err
    assert "track.wav" not in err and "/tmp" not in err and "sound:" not in out


def test_the_summary_says_why_z_and_the_shutter_are_not_measured(two_rods, capsys):
    from metrosync.cli.track import summary
    from metrosync.video import track

    ds = track(two_rods, sound=False)
    ds.attrs.update(z=float("nan"), z_note="z not measured: no whole swing of both rods seen",
                    readout=0.0, readout_error=float("nan"),
                    readout_source="not measurable from the rods' skew: ± 283 ms")  # fmt: skip
    text = summary(ds)
    assert "nan" not in text.lower()
    assert "  z not measured: no whole swing of both rods seen" in text
    assert "rolling shutter: not measurable from the rods' skew: ± 283 ms; taken as 0" in text

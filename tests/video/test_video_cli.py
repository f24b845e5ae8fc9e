"""``metrosync track`` as a user meets it: outputs, every bad input, Ctrl-C."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import synth_video

from metrosync.cli import main


def run(capsys, *argv):
    code = main(["track", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def test_track_writes_the_dataset_plot_and_preview(three_rods, tmp_path, capsys):
    path = three_rods[0]
    files = [tmp_path / "t.nc", tmp_path / "r.png", tmp_path / "p.png"]
    code, out, err = run(capsys, path, "--out", files[0], "--plot", files[1], "--preview",
                         files[2])  # fmt: skip
    assert code == 0, err
    assert "3 metronomes" in out and "equilibrium r" in out
    assert "about 590 frames" in err and "expect about" in err  # before the work
    assert all(f.stat().st_size > 0 for f in files)


def test_pivots_given_by_hand_are_used(three_rods, tmp_path, capsys):
    path, _, _, pivots = three_rods
    regions = tmp_path / "pivots.txt"
    regions.write_text("# x y\n" + "\n".join(f"{x:.0f}, {y:.0f}" for x, y in pivots[::-1]))
    code, out, err = run(capsys, path, "--regions", regions)
    assert code == 0, err
    rows = [line.split() for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert [float(r[1].rstrip(",")) for r in rows] == pytest.approx(pivots[::-1, 0], abs=3)


@pytest.mark.parametrize(
    "content, message",
    [("1 2 3\n", "line 1: '1 2 3' is not each line 'x y'"),
     ("10 10 5 5\n", "top-left corner"), ("# nothing\n", "holds no region")],
)  # fmt: skip
def test_a_bad_regions_file_names_the_line(three_rods, tmp_path, capsys, content, message):
    regions = tmp_path / "r.txt"
    regions.write_text(content)
    code, _, err = run(capsys, three_rods[0], "--regions", regions)
    assert code == 2 and message in err and "--regions" in err
    assert len(err.strip().splitlines()) == 1


def test_count_insists(three_rods, capsys):
    code, _, err = run(capsys, three_rods[0], "--count", "5")
    assert code == 2 and "not the 5 asked for" in err and "--count" in err


def test_bad_files_get_one_line_and_no_traceback(tmp_path, capsys):
    text = tmp_path / "notes.mp4"
    text.write_text("hello")
    still = tmp_path / "still.mp4"
    picture = synth_video.draw([0.1, 0.2], [(100, 200), (300, 200)])
    synth_video.write_video(still, np.arange(90) / 30, [picture] * 90)
    one = tmp_path / "one.mp4"
    synth_video.write_video(one, [0.0], [picture])
    cases = [(text, "as a video"), (tmp_path / "gone.mp4", "does not exist"),
             (still, "nothing swings"), (one, "holds 1 frame in")]  # fmt: skip
    for path, message in cases:
        code, out, err = run(capsys, path)
        assert code == 2, (path, err)
        assert message in err and "Traceback" not in err
        assert err.strip().splitlines()[-1].startswith("metrosync track: error:")


def test_a_truncated_file_is_used_and_the_loss_said(tmp_path, capsys):
    whole = tmp_path / "whole.mkv"
    synth_video.scene(whole, n=2, seconds=12, size=(320, 180))
    cut = tmp_path / "cut.mkv"
    cut.write_bytes(whole.read_bytes()[: int(whole.stat().st_size * 0.6)])
    code, out, err = run(capsys, cut)
    assert code == 0, err
    assert "cut short" in err and "s are lost" in err and "lost:" in out


CHILD = """
import signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
from metrosync.video import angles
measure = angles.RodGauge.measure
def marked(self, *args):
    open(sys.argv[1], "a").close()
    return measure(self, *args)
angles.RodGauge.measure = marked
from metrosync.cli import main
sys.exit(main(sys.argv[2:]))
"""


def test_ctrl_c_gives_one_line_exit_130_and_no_partial_file(three_rods, tmp_path):
    marker, out = tmp_path / "measuring", tmp_path / "out" / "t.nc"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(marker), "track", str(three_rods[0]), "--out", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=dict(os.environ),
    )  # fmt: skip
    deadline = time.monotonic() + 120
    while not marker.exists():
        assert child.poll() is None, child.stderr.read()
        assert time.monotonic() < deadline
        time.sleep(0.02)
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=60)
    assert child.returncode == 130
    assert err.splitlines()[-1] == "metrosync track: interrupted: nothing was written"
    assert "Traceback" not in err
    assert not out.parent.exists() or list(out.parent.iterdir()) == []

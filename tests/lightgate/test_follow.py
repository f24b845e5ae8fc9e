"""Following a growing capture gives what reading the finished file gives; `analyze --follow`."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from metrosync.lightgate import analyze, parse_log, read_log
from metrosync.lightgate.analyze import analyze_logs
from metrosync.lightgate.follow import LogFollower
from metrosync.lightgate.messages import format_gap
from ptyfeed import Command, wait_until

DATA = Path(__file__).parent.parent / "data"
MESSY = (DATA / "messy.log").read_text()
HEADER = "# metrosync gate-logger 1.0 channels=3 tick_us=64 counter_bits=16\r\n"
# The messy capture, with the logger's header and a restart after a marked gap.
LIVE = HEADER + MESSY[: MESSY.rindex("\n") + 1] + format_gap(1.5, "x") + "\n" + HEADER + "1-1-1 7\n"


def same_log(a, b) -> None:
    for name in ("levels", "ticks", "line_numbers", "interrupted_level"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for name in ("tick", "counter_bits", "wraps", "skipped", "n_lines", "header",
                 "records_lost", "restarts"):  # fmt: skip
        assert getattr(a, name) == getattr(b, name), name


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, len(LIVE) - 1), max_size=12, unique=True))
def test_followed_text_reads_as_the_text_so_far(cuts):
    follower = LogFollower()
    edges = [0, *sorted(cuts), len(LIVE)]
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        follower.feed(LIVE[lo:hi])
        try:
            expected = parse_log(LIVE[:hi])
        except Exception as error:  # the text so far may not be a readable log yet
            try:
                follower.log()
            except type(error):
                continue
            raise AssertionError(f"the follower read what parse_log refused: {error}") from None
        same_log(follower.log(), expected)


def test_a_window_of_the_last_lines_keeps_the_header():
    follower = LogFollower()
    follower.feed(LIVE)
    window = follower.log(last=40)
    assert window.header is not None and window.n_lines == 41
    assert np.array_equal(window.levels, parse_log(LIVE).levels[-len(window.ticks) :])


def test_following_a_file_that_grows_equals_analysing_the_finished_file(tmp_path):
    path = tmp_path / "run.log"
    data = (DATA / "clean.log").read_bytes()
    follower = LogFollower(path)
    assert follower.poll() == 0  # not there yet: waits for it
    with open(path, "wb") as f:
        for lo in range(0, len(data), 997):  # cut anywhere, mid-line included
            f.write(data[lo : lo + 997])
            f.flush()
            follower.poll()
    follower.poll(final=True)
    followed = analyze_logs([follower.log()])
    xr.testing.assert_identical(followed, analyze([path]))


def test_analyze_follow_writes_at_ctrl_c_what_analyze_writes(tmp_path):
    path, out, out_finished = tmp_path / "run.log", tmp_path / "live.nc", tmp_path / "done.nc"
    lines = (DATA / "clean.log").read_text().splitlines(keepends=True)
    command = Command("analyze", path, "--follow", "--out", out, "--grid-dt", "0.05")

    def write():  # a capture growing for about a second and a half
        with open(path, "w") as f:
            for k, line in enumerate(lines):
                f.write(line)
                f.flush()
                if k % 25 == 0:
                    time.sleep(0.1)

    writer = threading.Thread(target=write)
    writer.start()
    writer.join()
    wait_until(lambda: f"lines={len(lines)} r=" in command.text, timeout=20)
    code, err = command.interrupt()
    assert code == 130, err
    assert err.splitlines()[-1] == (
        f"metrosync analyze: interrupted: analysed {path} as it stood; wrote {out} (complete)"
    )
    assert f"wrote {out}" in command.text and "equilibrium r" in command.text
    from metrosync.cli import main

    assert main(["analyze", str(path), "--out", str(out_finished), "--grid-dt", "0.05"]) == 0
    with (xr.open_dataset(out, engine="h5netcdf") as live,
          xr.open_dataset(out_finished, engine="h5netcdf") as done):  # fmt: skip
        xr.testing.assert_identical(live.load(), done.load())
    assert read_log(path).n_lines == len(lines)


def test_analyze_follow_refuses_several_logs(capsys):
    from metrosync.cli import main

    clean = str(DATA / "clean.log")
    assert main(["analyze", clean, clean, "--follow"]) == 2
    assert "`--follow` follows one LOG, got 2" in capsys.readouterr().err


def test_a_follower_that_keeps_recent_lines_only_reads_them_with_the_header():
    follower = LogFollower(keep=30)
    for line in LIVE.splitlines(keepends=True):
        follower.feed(line)
    assert len(follower.lines) <= 60 and follower.n_lines == LIVE.count("\n")
    window = follower.log(last=30)
    assert window.header is not None and window.n_lines == 31
    assert np.array_equal(window.levels, parse_log(LIVE).levels[-len(window.ticks) :])

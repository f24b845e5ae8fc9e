"""Choosing gates: one check for `analyze` and the live panel, and gates that never change."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest

from metrosync.cli import main
from metrosync.cli._live import LivePanel
from metrosync.errors import AnalysisError, ParameterError
from metrosync.lightgate import analyze, parse_log
from metrosync.lightgate.channels import check_channels, never_changed
from metrosync.lightgate.follow import LogFollower
from metrosync.lightgate.live import live_status

DATA = Path(__file__).parent.parent / "data"
CLEAN = (DATA / "clean.log").read_text()
HEADER = "# metrosync gate-logger 1.1 channels=4 tick_us=64 counter_bits=16\n"


def with_unwired_gate(text: str, level: str = "1") -> str:
    """The capture with a fourth gate that reads a steady ``level`` (an unwired input)."""
    return re.sub(r"^([01](?:-[01])*) ", rf"\1-{level} ", text, flags=re.M)


UNWIRED = with_unwired_gate(CLEAN)


def test_check_channels_gives_the_valid_range_and_the_source():
    assert check_channels(None, 3) == [0, 1, 2]
    assert check_channels([2, 0], 3) == [2, 0]
    for bad in ([0, 3], [-1], [], [1, 1]):
        with pytest.raises(ParameterError, match=r"in \[0, 2\] \(x: 3 gates\), got"):
            check_channels(bad, 3, where=" (x: 3 gates)")


def test_never_changed_finds_the_steady_columns():
    levels = np.array([[0, 1, 1, 0], [1, 1, 0, 0], [0, 1, 1, 0]])
    assert never_changed(levels) == [1, 3]
    assert never_changed(levels[:1]) == [0, 1, 2, 3]


@pytest.mark.parametrize("level", ["0", "1"])
def test_analyze_leaves_out_a_gate_that_never_changed_and_names_it(tmp_path, level):
    path = tmp_path / "unwired.log"
    path.write_text(with_unwired_gate(CLEAN, level))
    plain = tmp_path / "clean.log"
    plain.write_text(CLEAN)
    with pytest.warns(UserWarning, match=r"unwired.log: gate 3 never changed .*uses gates 0, 1, 2"):
        ds = analyze(path)
    assert ds.metronome.values.tolist() == [0, 1, 2] and ds.attrs["gates_never_changed"] == "3"
    ref = analyze(plain)
    assert ref.attrs["gates_never_changed"] == ""
    np.testing.assert_array_equal(ds.r.values, ref.r.values)
    # Chosen by name, it is left out too; alone, there is nothing to analyse.
    with pytest.warns(UserWarning, match="gate 3 never changed"):
        assert analyze(path, channels=[0, 3, 2]).metronome.values.tolist() == [0, 2]
    with pytest.raises(AnalysisError, match=r"every gate chosen \(3\) never changed"):
        analyze(path, channels=[3])


def test_analyze_cli_warns_once_and_goes_on(tmp_path, capsys):
    path = tmp_path / "unwired.log"
    path.write_text(UNWIRED)
    assert main(["analyze", str(path)]) == 0
    out, err = capsys.readouterr()
    assert err.count("warning:") == 1 and "gate 3 never changed" in err
    assert "`channels` (--channels)" in err and "3 metronomes" in out
    assert main(["analyze", str(path), "--channels", "0,4"]) == 2
    assert "`channels` (--channels) must be distinct gate indices in [0, 3]" in (
        capsys.readouterr().err
    )


def test_live_status_marks_the_gate_and_leaves_it_out_of_r():
    log = parse_log(UNWIRED)
    status = live_status(log)
    assert [g.never_changed for g in status.gates] == [False, False, False, True]
    assert status.never_changed == (3,) and status.r_gates == (0, 1, 2)
    # Over the whole capture (a live view analyses only its recent part): a gate that
    # changed long ago is silent, not "never changed".
    recent = live_status(log, changes=[5, 5, 5, 2])
    assert recent.never_changed == () and recent.gates[3].silent
    with pytest.raises(ParameterError, match=r"\[0, 3\]"):
        live_status(log, channels=[0, 4])


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_the_panel_says_never_changed_and_warns():
    follower = LogFollower()
    follower.feed(UNWIRED)
    stream, plain = _Terminal(), io.StringIO()
    for out in (stream, plain):
        with LivePanel(follower, "recording", stream=out) as panel:
            panel.tick(force=True)
    shown = stream.getvalue()
    assert "never changed" in shown and "SILENT for - s" not in shown
    flat = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]|[│\s]", "", shown)  # the panel wraps its lines
    assert "gate3neverchanged(notwired" in flat and "leftoutofr" in flat
    line = plain.getvalue().splitlines()[-1]
    assert " 3:never-changed" in line and "0:" in line and "r=0.9" in line


@pytest.mark.parametrize("header", [HEADER, ""])
def test_the_panel_refuses_channels_the_logger_lacks_once_it_knows(header):
    follower = LogFollower()
    panel = LivePanel(follower, "x", channels=[0, 4], stream=io.StringIO(),
                      logger="the logger on COM3")  # fmt: skip
    # A fragment first (a port opened mid-line) decides nothing.
    follower.feed("0-1 5\n")
    panel.tick(force=True)
    follower.feed(header + "".join(UNWIRED.splitlines(keepends=True)[:2]))
    if not header:
        panel.tick(force=True)  # two whole records do not settle it either
        follower.feed(UNWIRED.splitlines(keepends=True)[2])
    with pytest.raises(ParameterError, match=r"\[0, 3\] \(the logger on COM3: 4 gates per line\)"):
        panel.tick()  # not rate-limited: the first call after the count is known
    ok = LivePanel(follower, "x", channels=[0, 3], stream=io.StringIO())
    ok.tick(force=True)


def test_analyze_follow_refuses_at_once(tmp_path, capsys):
    path = tmp_path / "run.log"
    path.write_text(HEADER + UNWIRED)
    assert main(["analyze", str(path), "--follow", "--channels", "0,7"]) == 2
    err = capsys.readouterr().err
    assert f"[0, 3] ({path}: 4 gates per line), got [0, 7]" in err

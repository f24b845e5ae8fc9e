"""`metrosync record` on a pseudo-terminal: line for line, Ctrl-C, a pulled cable, a reconnect."""

from __future__ import annotations

import io
import os
import re
import select
import time
from pathlib import Path

import numpy as np
import pytest

from metrosync.cli import main
from metrosync.cli._live import LivePanel
from metrosync.lightgate import read_log
from metrosync.lightgate.follow import LogFollower
from metrosync.lightgate.messages import HEADER_REQUEST
from metrosync.lightgate.recorder import HEADER_WAIT, REQUEST_WAIT
from metrosync.lightgate.replay import replay
from ptyfeed import Command, Pty, wait_until

DATA = Path(__file__).parent.parent / "data"
CLEAN = (DATA / "clean.log").read_text()
HEADER = "# metrosync gate-logger 1.0 channels=3 tick_us=64 counter_bits=32 baud=115200"


@pytest.fixture(autouse=True)
def _cleanup(monkeypatch):
    """Close every pseudo-terminal and process a test opened, whatever happened."""
    opened: list = []
    original_pty, original_command = Pty.__init__, Command.__init__

    def pty_init(self, *args, **kwargs):
        original_pty(self, *args, **kwargs)
        opened.append(self)

    def command_init(self, *args, **kwargs):
        original_command(self, *args, **kwargs)
        opened.append(self)

    monkeypatch.setattr(Pty, "__init__", pty_init)
    monkeypatch.setattr(Command, "__init__", command_init)
    yield
    for thing in reversed(opened):
        thing.kill() if isinstance(thing, Command) else thing.unplug()


def start(pty: Pty, out: Path, *extra) -> Command:
    command = Command("record", pty.path, "--out", out, *extra)
    wait_until(out.exists)  # the port is open and configured: writing is safe now
    return command


def test_capture_is_what_was_sent_and_ctrl_c_ends_cleanly(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out)
    replay(CLEAN, pty.master, speed=40)
    wait_until(lambda: out.read_text().count("\n") == CLEAN.count("\n"))
    wait_until(lambda: "r=" in record.text, timeout=10)  # the live line has an r now
    code, err = record.interrupt()
    # Ctrl-C is Ctrl-C (status 130), and the line says the capture is kept.
    assert code == 130, err
    assert err.splitlines()[-1].startswith(
        f"metrosync record: interrupted: the capture {out} is kept, complete ("
    )
    # CR LF sent, LF written, nothing else changed; with no header sent, a note says so.
    text = out.read_text()
    assert text.startswith(CLEAN) and text[len(CLEAN) :].count("\n") == 1
    assert text[len(CLEAN) :].startswith("# metrosync record: no logger header seen ")
    assert f"recorded {CLEAN.count(chr(10)) + 1} lines" in record.lines[-1][1]
    assert "no logger header seen (interrupted)" in record.lines[-1][1]
    status = [line for _, line in record.lines if line.startswith("live ")]
    assert any("gates 0:" in line and "bpm" in line for line in status)


def test_a_vanished_port_is_reported_and_the_file_kept(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out)
    head = "".join(CLEAN.splitlines(keepends=True)[:20])
    pty.write(head.replace("\n", "\r\n") + "0-0-1 12")
    wait_until(lambda: out.read_text().count("\n") == 20)
    time.sleep(0.2)
    pty.unplug()
    code, err = record.wait()
    assert code == 1
    assert "vanished" in err and "is kept" in err and "--reconnect" in err
    text = out.read_text()
    assert text.startswith(head)
    # A line cut by the loss is kept as a note, not as a record with a wrong time, and
    # the note that no header came follows it.
    cut, no_header = text.splitlines()[-2:]
    assert cut == "# metrosync record: cut off when the port vanished: 0-0-1 12"
    assert no_header.startswith("# metrosync record: no logger header seen in the ")
    assert len(read_log(out).ticks) == 20


def test_reconnect_waits_and_marks_the_gap(tmp_path):
    link, out = tmp_path / "ttyACM0", tmp_path / "run.log"
    pty = Pty(link)
    record = start(pty, out, "--reconnect")
    body = "0-0-0 0\n1-0-0 10\n0-0-0 20\n0-1-0 800\n0-0-0 810\n"
    pty.write(f"{HEADER}\n{body}".replace("\n", "\r\n"))
    wait_until(lambda: out.read_text().count("\n") == 6)
    pty.unplug()
    time.sleep(1.0)
    pty = Pty(link)  # the logger is back, reset: a new header, its counter from 0
    wait_until(lambda: record.has_open(pty.name), timeout=10)
    time.sleep(0.1)  # opening flushes what is waiting: write once it is configured
    pty.write(f"{HEADER}\r\n0-0-0 3\r\n0-0-1 100\r\n")
    wait_until(lambda: out.read_text().count("\n") == 10)
    code, err = record.interrupt()
    assert code == 130, err
    lines = out.read_text().splitlines()
    assert lines[6].startswith("# metrosync record: gap of ") and str(link) in lines[6]
    gap = float(lines[6].split()[5])
    assert 1.0 <= gap < 5.0
    log = read_log(out)
    assert log.restarts == (9,)
    # The records after the restart continue the time line after the gap.
    assert abs(log.times[5] - (810 * 64e-6 + gap)) < 64e-6 * 4
    assert "1 gap marked" in record.lines[-1][1]
    pty.unplug()


def sent_to_logger(pty: Pty, timeout: float) -> bytes:
    """What the program on the port wrote to the logger within ``timeout`` s."""
    ready, _, _ = select.select([pty.master], [], [], timeout)
    return os.read(pty.master, 64) if ready else b""


def test_a_board_that_did_not_reset_is_asked_for_its_header(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out)
    opened = time.monotonic()
    # The port was opened without a reset: the stream starts in the middle of a line.
    pty.write("0-0 5\r\n" + "".join(CLEAN.splitlines(keepends=True)[:30]).replace("\n", "\r\n"))
    asked = sent_to_logger(pty, timeout=10)
    waited = time.monotonic() - opened
    assert asked == HEADER_REQUEST and HEADER_WAIT - 0.5 < waited < HEADER_WAIT + 2
    answer = HEADER.replace("counter_bits=32", "counter_bits=16")  # as CLEAN's logger
    pty.write(f"{answer} requested=1\r\n{CLEAN.splitlines()[30]}\r\n")  # firmware 1.1
    wait_until(lambda: out.read_text().count("\n") == 33)
    time.sleep(REQUEST_WAIT + 0.5)
    code, err = record.interrupt()
    assert code == 130, err
    assert "no logger header" not in out.read_text() + record.lines[-1][1]
    log = read_log(out)
    assert log.header.requested and log.restarts == () and len(log.ticks) == 31
    assert [s.reason for s in log.skipped] == ["partial record (2 gates, expected 3)",
                                               "logger header"]  # fmt: skip


def test_a_header_at_start_is_kept_and_nothing_is_asked(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out)
    pty.write(f"{HEADER}\r\n" + CLEAN.replace("\n", "\r\n"))
    assert sent_to_logger(pty, timeout=HEADER_WAIT + REQUEST_WAIT + 0.5) == b""
    code, err = record.interrupt()
    assert code == 130, err
    assert out.read_text() == f"{HEADER}\n{CLEAN}"
    assert "no logger header" not in record.lines[-1][1]


def test_no_answer_to_the_request_is_noted_in_the_capture_at_once(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out)
    pty.write("0-0-0 0\r\n")
    note = "# metrosync record: no logger header seen after a request for it"
    wait_until(lambda: note in out.read_text(), timeout=HEADER_WAIT + REQUEST_WAIT + 5)
    pty.write("1-0-0 10\r\n")  # the recording goes on after the note
    wait_until(lambda: out.read_text().endswith("1-0-0 10\n"))
    code, err = record.interrupt()
    assert code == 130, err
    assert out.read_text().count("no logger header") == 1
    assert "no logger header seen" in record.lines[-1][1]
    log = read_log(out, strict=True)  # the note is a known line, even when strict
    assert log.header is None and log.ticks.tolist() == [0, 10]
    assert [s.reason for s in log.skipped] == ["note of metrosync record"]


def test_refusals_name_the_option(tmp_path, capsys):
    taken = tmp_path / "taken.log"
    taken.write_text("x\n")
    assert main(["record", "/dev/null", "--out", str(taken)]) == 2
    assert "`--out`" in capsys.readouterr().err and taken.read_text() == "x\n"
    assert main(["record", str(tmp_path / "nope"), "--out", str(tmp_path / "a.log")]) == 2
    err = capsys.readouterr().err
    assert "cannot open the serial port" in err and "list_ports" in err
    assert main(["record", "/dev/null", "--out", str(tmp_path / "b.log"), "--channels", "9"]) == 2
    assert ("`channels` (--channels) must be distinct gate indices in [0, 7] (a logger has at "
            "most 8 gates), got [9]") in capsys.readouterr().err  # fmt: skip
    assert main(["record", "/dev/null", "--out", str(tmp_path / "c.log"), "--duration", "-1"]) == 2
    assert "`duration` (--duration) must be a time > 0 s" in capsys.readouterr().err


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_panel_on_a_terminal_shows_gates_bpm_silence_and_r():
    follower = LogFollower()
    follower.feed(CLEAN)
    stream = _Terminal()
    with LivePanel(follower, "recording test", stream=stream) as panel:
        panel.tick(force=True)
        panel.tick(idle=30.0, force=True)  # nothing for 30 s: every gate is silent
    shown = stream.getvalue()
    assert "\x1b[" in shown  # drawn by rich, in place
    for text in ("recording test", "passes", "BPM", "ok", "r(t), last 60 s:", "r = 0.9",
                 "SILENT for", "needs two gates"):  # fmt: skip
        assert text in shown, text


def test_plain_lines_when_not_a_terminal():
    follower = LogFollower()
    stream = io.StringIO()
    with LivePanel(follower, "x", stream=stream) as panel:
        panel.tick(force=True)
        follower.feed(CLEAN)
        panel.tick(force=True)
    first, second = stream.getvalue().splitlines()
    assert first.endswith("waiting for the first record")
    assert "lines=371" in second and "r=0.9" in second and "2:" in second
    assert np.isfinite(float(second.split("r=")[1].split()[0]))


@pytest.mark.parametrize("gates", [["--channels", "0,2"]])
def test_channels_choose_the_gates_shown(tmp_path, gates):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out, *gates, "--duration", "3")
    replay(CLEAN, pty.master, speed=40)
    code, err = record.wait()
    assert code == 0, err
    status = [line for _, line in record.lines if "gates 0:" in line]
    assert status and all(" 1:" not in line and " 2:" in line for line in status)
    assert "(duration)" in record.lines[-1][1]


@pytest.mark.parametrize("header", [True, False])
def test_channels_the_logger_lacks_are_refused_as_soon_as_it_says_how_many(tmp_path, header):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out, "--channels", "0,7")
    lines = CLEAN.splitlines(keepends=True)[:3]
    pty.write(("" if not header else HEADER + "\n") + "".join(lines).replace("\n", "\r\n"))
    sent = time.monotonic()
    code, err = record.wait(timeout=20)
    assert code == 2 and time.monotonic() - sent < 3
    assert (f"`channels` (--channels) must be distinct gate indices in [0, 2] (the logger on "
            f"{pty.path}: 3 gates per line), got [0, 7]") in err  # fmt: skip
    # As `analyze` refuses the same list for the capture, which is kept.
    assert f"lines recorded so far are in {str(out)!r}; give --overwrite" in err
    assert out.read_text().startswith((HEADER + "\n" if header else "") + "".join(lines))
    assert main(["analyze", str(out), "--channels", "0,7"]) == 2


def test_a_gate_that_never_changes_is_shown_and_named(tmp_path):
    pty, out = Pty(), tmp_path / "run.log"
    record = start(pty, out, "--duration", "3")
    unwired = re.sub(r"^([01](?:-[01])*) ", r"\1-1 ", CLEAN, flags=re.M)  # a steady 4th gate
    replay(unwired, pty.master, speed=40)
    code, err = record.wait()
    assert code == 0, err
    status = [line for _, line in record.lines if line.startswith("live ") and "r=" in line]
    assert status and "3:never-changed" in status[-1] and "0:" in status[-1]
    assert "warning: gate 3 never changed (not wired" in err and "analyze` leaves it out" in err

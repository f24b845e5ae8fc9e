"""docs/logger.md's first check: the panel it shows is what the firmware and `record`'s
panel give for a card waved through gates 1-7 with the eighth input unwired."""

from __future__ import annotations

import io
import re

from simlogger import REPO, run_logger

from metrosync.cli._live import LivePanel
from metrosync.lightgate.follow import LogFollower

DOC = REPO / "docs" / "logger.md"


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def documented_panel() -> list[str]:
    section = DOC.read_text().split("## First check", 1)[1]
    block = re.search(r"^```\n(╭.*?)^```$", section, flags=re.M | re.S)[1]
    return block.rstrip("\n").splitlines()


def test_the_documented_first_check_is_what_the_panel_shows(sim, tmp_path):
    edges = []
    for gate in range(1, 8):  # a card through each gate in turn, 0.15 s in the beam
        t = 0.5 + 0.6 * (gate - 1)
        edges += [(t, gate, 1), (t + 0.15, gate, 0)]
    # Gate 8 is not wired: the pull-up holds its pin at 1.
    run = run_logger(sim.harness, sim.firmware(), edges, end=5.0, workdir=tmp_path,
                     init="00000001")  # fmt: skip
    follower = LogFollower()
    follower.feed(run.text)
    stream = _Terminal()
    with LivePanel(follower, "recording /dev/ttyACM0 -> check.log", stream=stream) as panel:
        panel.tick(force=True)
    text = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", stream.getvalue())
    last = text[text.rindex("╭") :]
    shown = [line.rstrip() for line in last[: last.index("╯") + 1].splitlines()]
    assert shown == [line.rstrip() for line in documented_panel()]
    plain = io.StringIO()
    with LivePanel(follower, "x", stream=plain) as panel:
        panel.tick(force=True)
    assert "gates 0:1p/-bpm 1:1p/-bpm" in plain.getvalue()
    assert plain.getvalue().rstrip().endswith("7:never-changed")
    assert "`gates 0:1p/-bpm 1:1p/-bpm ... 7:never-changed`" in DOC.read_text()

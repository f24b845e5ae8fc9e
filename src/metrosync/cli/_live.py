"""The live panel of ``record`` and ``analyze --follow``: rich on a terminal, plain lines otherwise.

Contract: `LivePanel` is a context manager. Its `tick` is called often; about once a
second it asks the `LogFollower` for the capture so far (its recent part, for a
bounded cost), computes `live_status`, and shows it: on a terminal a `rich` panel
redrawn in place, otherwise one plain line. An error of the analysis (a capture that
is not readable yet, a gate count that changed) is shown in the panel and never
stops the recording; but chosen ``channels`` that the logger does not have are
refused (`ParameterError`, from `tick`) as soon as its header or its first records
tell its gate count, with the check `analyze` makes. A gate that never changed is
shown as such and named in a warning line: it is left out of r.
"""

from __future__ import annotations

import math
import sys
import time

from .._words import plural
from ..errors import EmptyLogError, MetrosyncError
from ..lightgate.channels import check_channels, never_changed_text
from ..lightgate.follow import LogFollower
from ..lightgate.live import LiveStatus, live_status

#: The live view analyses at most this many recent lines (about 3 min of 8 gates).
LIVE_LINES = 20_000
#: Seconds of r(t) drawn in the panel.
R_SHOWN = 60.0
_BARS = "▁▂▃▄▅▆▇█"


class LivePanel:
    """Shows the live status of ``follower`` about every ``interval`` seconds.

    title : what is shown (e.g. ``"recording /dev/ttyACM0 -> run.log"``).
    channels : gates to show and use for r (0-based), or None for all.
    plain : plain lines even on a terminal.
    logger : what sends the lines, for a refusal of ``channels`` ("the logger on COM3").
    """

    def __init__(self, follower: LogFollower, title: str, *, channels=None, plain=None,
                 interval: float = 1.0, stream=None, logger: str = "the logger"):  # fmt: skip
        self.follower = follower
        self.title = title
        self.channels = channels
        self.logger = logger
        self._checked = channels is None
        self.interval = interval
        self.stream = stream or sys.stdout
        self.plain = not self.stream.isatty() if plain is None else plain
        self._live = None
        self._next = 0.0
        self._start = time.monotonic()
        self.updates = 0

    def __enter__(self):
        if not self.plain:
            from rich.console import Console
            from rich.live import Live

            console = Console(file=self.stream)
            self._live = Live(self._render(None, "waiting for the first line"), console=console,
                              auto_refresh=False, transient=False)  # fmt: skip
            self._live.start()
        return self

    def __exit__(self, *exc):
        if self._live is not None:
            self._live.stop()
        return False

    def tick(self, idle: float = 0.0, *, force: bool = False) -> None:
        """Refresh when due (or ``force``); ``idle``: seconds since the last line arrived.

        Raises `ParameterError` when the chosen channels do not fit the logger's gates.
        """
        if not self._checked and (k := self.follower.gates) is not None:
            check_channels(self.channels, k,
                           where=f" ({self.logger}: {k} gates per line)")  # fmt: skip
            self._checked = True
        now = time.monotonic()
        if not force and now < self._next:
            return
        self._next = now + self.interval
        status, note = None, ""
        try:
            status = live_status(self.follower.log(last=LIVE_LINES), channels=self.channels,
                                 passes=self.follower.interruptions,
                                 changes=self.follower.changes, idle=idle)  # fmt: skip
        except EmptyLogError:
            note = "waiting for the first record"
        except MetrosyncError as error:
            note = f"cannot analyse yet: {error}"
        self.updates += 1
        if self._live is not None:
            self._live.update(self._render(status, note), refresh=True)
        else:
            print(self._plain(status, note), file=self.stream, flush=True)

    def _plain(self, status: LiveStatus | None, note: str) -> str:
        head = f"live t={time.monotonic() - self._start:.1f}s lines={self.follower.n_lines}"
        if status is None:
            return f"{head} {note}"
        gates = " ".join(
            f"{g.gate}:never-changed" if g.never_changed else
            f"{g.gate}:{g.passes}p/{_num(g.bpm, '.1f')}bpm{'/SILENT' if g.silent else ''}"
            for g in status.gates
        )  # fmt: skip
        lost = f" LOST={status.records_lost}" if status.records_lost else ""
        return (f"{head} r={_num(status.r_last, '.3f')} lag={_num(status.r_lag, '.1f')}s "
                f"gates {gates}{lost}")  # fmt: skip

    def _render(self, status: LiveStatus | None, note: str):
        from rich.console import Group
        from rich.panel import Panel
        from rich.table import Table
        from rich.text import Text

        elapsed = time.monotonic() - self._start
        foot = Text(f"{elapsed:.0f} s, {plural(self.follower.n_lines, 'line')}", style="dim")
        if status is None:
            return Panel(Group(Text(note), foot), title=self.title)
        table = Table(box=None, pad_edge=False)
        for name, just in (("gate", "right"), ("passes", "right"), ("BPM", "right"),
                           ("", "left")):  # fmt: skip
            table.add_column(name, justify=just)
        for g in status.gates:
            if g.never_changed:
                state = Text("never changed", style="yellow")
            elif g.silent:
                state = Text(f"SILENT for {_num(g.silent_for, '.0f')} s", style="bold red")
            else:
                state = Text("ok", style="green")
            table.add_row(str(g.gate), str(g.passes), _num(g.bpm, ".2f"), state)
        shown = status.r_time > status.r_time[-1] - R_SHOWN if status.r.size else []
        if status.r.size:
            r_line = Text(f"r = {status.r_last:.3f}", style="bold")
            r_line.append(f"  ({status.r_lag:.1f} s behind the newest record; gates "
                          f"{','.join(map(str, status.r_gates))})", style="")  # fmt: skip
            r_line.append(f"\nr(t), last {R_SHOWN:.0f} s: ")
            r_line.append(_spark(status.r[shown]), style="cyan")
        else:
            r_line = Text("r(t): needs two gates with two passes each", style="dim")
        parts = [table, r_line]
        if status.never_changed and len(status.never_changed) < len(status.gates):
            # Only once another gate has changed: at the start every gate is unchanged.
            parts.append(Text(f"{never_changed_text(status.never_changed)}: left out of r",
                              style="yellow"))  # fmt: skip
        if status.records_lost:
            lost = plural(status.records_lost, "record")
            parts.append(Text(f"the logger LOST {lost} (buffer full)", style="bold red"))
        if status.restarts:
            restarts = plural(status.restarts, "time")
            parts.append(Text(f"the logger restarted {restarts}", style="yellow"))
        return Panel(Group(*parts, foot), title=self.title)


def _num(value: float, spec: str) -> str:
    return "-" if value is None or not math.isfinite(value) else format(value, spec)


def _spark(values) -> str:
    """r in [0, 1] as at most 50 block characters, the newest at the right."""
    step = max(1, -(-len(values) // 50))
    out = []
    for v in values[::step]:
        out.append(" " if not math.isfinite(v) else _BARS[min(7, max(0, int(v * 8)))])
    return "".join(out)

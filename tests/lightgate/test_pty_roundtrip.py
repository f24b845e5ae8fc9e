"""End to end on a pseudo-terminal: simulation → virtual gate → pty → `record` → `analyze`.

The virtual gate's log is written into a pty at 30 times real time; `record` reads the
other end. The capture must equal what was sent, and its analysis must match the
simulation's crossing r as the file round trip does. The test also measures how
long a line takes from the pty to the capture file, and how old the newest line is
when the live r that includes it is printed (figures printed with ``-s``).
"""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from metrosync import analyze, simulate
from metrosync.lightgate import LightGate, format_log
from metrosync.lightgate.replay import replay
from ptyfeed import Command, Pty, wait_until

SPEED = 30.0


@pytest.fixture(scope="module")
def virtual_run():
    ds = simulate(7, 192.0, sigma_bpm=0.75, runs=1, duration=60.0, seed=11, record_every=1,
                  trajectories=True, progress=False)  # fmt: skip
    gate = LightGate(offset=0.1, width=0.05, tick=64e-6, counter_bits=16, start_tick=50000)
    text = format_log(ds.time.values, ds.theta.values[:, 0, :], ds.theta_dot.values[:, 0, :], gate)
    # A logger that resets when the port opens sends its header first (so `record`
    # neither asks for it nor notes its absence: the capture is what was sent).
    header = "# metrosync gate-logger 1.1 channels=7 tick_us=64 counter_bits=16 baud=115200\n"
    return ds, header + text


class FileWatcher(threading.Thread):
    """Notes when each line appears in a growing file (polled every millisecond)."""

    def __init__(self, path):
        super().__init__(daemon=True)
        self.path, self.seen, self.stop = path, [], False

    def run(self):
        while not self.stop:
            try:
                n = self.path.read_bytes().count(b"\n")
            except FileNotFoundError:
                n = 0
            now = time.monotonic()
            self.seen += [now] * (n - len(self.seen))
            time.sleep(0.001)


def test_record_over_a_pty_captures_what_was_sent_and_analyses_like_the_simulation(
    virtual_run, tmp_path
):
    ds, text = virtual_run
    pty, out = Pty(), tmp_path / "run.log"
    record = Command("record", pty.path, "--out", out)
    watcher = FileWatcher(out)
    try:
        wait_until(out.exists)
        watcher.start()
        sent = replay(text, pty.master, speed=SPEED)
        n = len(sent)
        wait_until(lambda: len(watcher.seen) >= n)
        wait_until(lambda: f"lines={n} " in record.text, timeout=10)
        code, err = record.interrupt()
    finally:
        watcher.stop = True
        record.kill()
        pty.unplug()
    assert code == 130, err
    assert out.read_text() == text

    res = analyze([out])
    sim = ds.r_crossing.isel(run=0).sel(time=res.time.values, method="nearest")
    delta = float(np.nanmax(np.abs(res.r.values - sim.values)))
    print(f"\nmax |r_capture - r_simulation| = {delta:.4f} over {res.sizes['time']} points")
    assert delta < 0.006  # what the file round trip reaches (test_roundtrip)

    # Latency: a line from the pty to the capture file ...
    to_file = np.array(watcher.seen[:n]) - np.array(sent)
    # ... and to the live r: each status line against the newest line it includes.
    # r itself is known up to the earliest of the gates' last passes: its lag (logger s).
    to_r, lag = [], []
    for printed, line in record.lines:
        if line.startswith("live ") and " r=" in line and "r=-" not in line:
            k = int(line.split("lines=")[1].split()[0])
            to_r.append(printed - sent[k - 1])
            lag.append(float(line.split("lag=")[1].split("s")[0]))
    to_r = np.array(to_r)
    print(f"line -> file: median {np.median(to_file) * 1e3:.1f} ms, "
          f"99% {np.percentile(to_file, 99) * 1e3:.1f} ms, max {to_file.max() * 1e3:.1f} ms; "
          f"line -> live r printed: median {np.median(to_r):.2f} s, max {to_r.max():.2f} s "
          f"({len(to_r)} updates); r lags the newest record by {np.median(lag):.2f} s "
          f"(median, logger time)")  # fmt: skip
    assert np.median(to_file) < 0.05 and to_file.max() < 1.0
    assert len(to_r) >= 2 and to_r.max() < 2.0

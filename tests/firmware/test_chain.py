"""The whole chain: simulation → virtual gate → firmware in simavr → pty → `record` → `analyze`."""

from __future__ import annotations

import time

import numpy as np
import pytest
from simlogger import simulation_edges, timer_start

from metrosync import analyze, simulate
from metrosync.lightgate import LightGate, read_log
from ptyfeed import Command, Pty, wait_until

DURATION = 40.0


@pytest.fixture(scope="module")
def simulated():
    return simulate(7, 192.0, sigma_bpm=0.75, runs=1, duration=DURATION, seed=5, record_every=1,
                    trajectories=True, progress=False)  # fmt: skip


def test_simulation_through_the_firmware_and_a_pty_analyses_like_the_simulation(
    sim, simulated, tmp_path
):
    from simlogger import run_logger

    ds = simulated
    init, edges = simulation_edges(ds, 0, LightGate(offset=0.1, width=0.05), until=DURATION)
    pty, out = Pty(), tmp_path / "run.log"
    record = Command("record", pty.path, "--out", out)
    try:
        wait_until(out.exists)
        # The firmware's UART goes into the pty, paced at 20 times real time.
        logger = run_logger(sim.harness, sim.firmware(), edges, end=DURATION + 0.1,
                            workdir=tmp_path, init=init, speed=20.0, stdout=pty.master)  # fmt: skip
        assert logger.wait(60) == 0
        origin = timer_start(logger.stderr.read().decode())
        logger.stderr.close()
        sent = len(np.loadtxt(tmp_path / "line_cycles.txt", ndmin=1))
        wait_until(lambda: out.read_bytes().count(b"\n") == sent, timeout=20)
        code, err = record.interrupt()
    finally:
        record.kill()
        pty.unplug()
    assert code == 130, err

    log = read_log(out, strict=True)  # every line is a record or the logger's header
    assert log.header is not None and log.records_lost == 0 and len(log.ticks) == sent - 1
    res = analyze([out], channels=range(7))  # gate 8 is not wired
    # The logger's clock starts when the firmware starts Timer1, a fraction of a tick
    # after the simulation's t = 0: compare at the simulation's times.
    shift = origin / 16e6
    sim_r = ds.r_crossing.isel(run=0).sel(time=res.time.values + shift, method="nearest")
    delta = float(np.nanmax(np.abs(res.r.values - sim_r.values)))
    print(f"\nfirmware chain: max |r_capture - r_simulation| = {delta:.4f} "
          f"over {res.sizes['time']} points")  # fmt: skip
    assert delta < 0.006


def test_a_board_that_did_not_reset_answers_record_s_request_for_its_header(sim, tmp_path):
    from simlogger import run_logger

    # The board runs before the port is opened, as one that does not reset on opening:
    # its start-up header waits in the port, and opening the port discards it.
    edges = sorted((0.05 * g + 0.25 * k + d, g, lv) for g in range(1, 5) for k in range(240)
                   for d, lv in ((0.0, 1), (0.01, 0)))  # fmt: skip
    pty, out = Pty(), tmp_path / "run.log"
    # Real time, for as long as the test needs it (it stops the board when done).
    logger = run_logger(sim.harness, sim.firmware(), edges, end=60.0, workdir=tmp_path,
                        speed=1.0, stdout=pty.master, stdin=pty.master)  # fmt: skip
    time.sleep(0.3)  # the header (10 ms) and a few records are out, unread
    record = Command("record", pty.path, "--out", out)
    try:
        wait_until(out.exists)
        wait_until(lambda: "requested=1" in out.read_text(), timeout=20)
        time.sleep(0.5)  # a few records after it
        code, err = record.interrupt()
    finally:
        record.kill()
        logger.kill()
        logger.wait(10)
        logger.stderr.close()
        pty.unplug()
    assert code == 130, err
    text = out.read_text()
    # Only the header asked for: the start-up one was discarded with the port's input.
    assert text.count("# metrosync gate-logger 1.1 channels=8 ") == 1
    assert "no logger header" not in text + record.text
    log = read_log(out)
    assert log.header.requested and log.header.channels == 8 and log.restarts == ()
    assert log.records_lost == 0 and len(log.ticks) > 30

"""The gate-logger firmware in simavr: its lines parse, its times are right to a tick,
bursts lose nothing (or say what they lost), and its counter wraps where documented."""

from __future__ import annotations

import numpy as np
import pytest
from simlogger import CYCLES_PER_TICK, F_CPU, NEAR_16_BIT_WRAP, NEAR_32_BIT_WRAP, run_logger

from metrosync.lightgate import parse_log

HOLDOFF_TICKS = 4


def metronome_edges(rng, *, gates=8, duration=8.0):
    """Edges of gates mounted off-centre on metronomes near 192 BPM: two passes per
    period (short and long intervals alternating), each interrupting the beam 6-12 ms."""
    edges = []
    for g in range(1, gates + 1):
        period = 60 / (96 * (1 + 0.01 * rng.standard_normal()))
        t = rng.uniform(0.01, period)
        while t < duration - 0.1:
            for offset in (0.0, 0.38 * period):
                start = t + offset + 1e-4 * rng.standard_normal()
                width = rng.uniform(6e-3, 12e-3)
                edges += [(start, g, 1), (start + width, g, 0)]
            t += period
    return sorted(edges)


def expected_tick(run, t, start_ticks=0):
    """The tick an ideal logger shows for an edge at t s: whole ticks since Timer1 started."""
    return (round(t * F_CPU) - run.timer_start) // CYCLES_PER_TICK + start_ticks


def printed_changes(lines, channels=8):
    """Per gate, [(counter, level)] of each change the stream shows after its first record."""
    records = [line.split() for line in lines if not line.startswith("#")]
    out = {g: [] for g in range(1, channels + 1)}
    previous = None
    for bits, value in records:
        levels = [int(b) for b in bits.split("-")]
        if previous is not None:
            for g in range(1, channels + 1):
                if levels[g - 1] != previous[g - 1]:
                    out[g].append((int(value), levels[g - 1]))
        previous = levels
    return out


def injected_changes(edges, init="00000000"):
    """Per gate, [(t, level)] of each injected edge that changes the gate's level."""
    level = {g: int(init[g - 1]) for g in range(1, 9)}
    out = {g: [] for g in range(1, 9)}
    for t, g, lv in edges:
        if lv != level[g]:
            out[g].append((t, lv))
            level[g] = lv
    return out


def assert_within_one_tick(run, edges, start_ticks=0):
    shown, injected = printed_changes(run.lines), injected_changes(edges)
    for g in range(1, 9):
        assert [lv for _, lv in shown[g]] == [lv for _, lv in injected[g]], f"gate {g}"
        got = np.array([value for value, _ in shown[g]], dtype=np.int64)
        want = np.array([expected_tick(run, t, start_ticks) for t, _ in injected[g]])
        late = (got - want) % (1 << 32)  # the printed counter is modulo 2**32
        assert np.all(late <= 1), f"gate {g}: ticks late by {sorted(set(late.tolist()))}"


@pytest.fixture(scope="module")
def metronome_run(sim, tmp_path_factory):
    edges = metronome_edges(np.random.default_rng(13))
    run = run_logger(sim.harness, sim.firmware(), edges, end=8.2,
                     workdir=tmp_path_factory.mktemp("metronomes"))  # fmt: skip
    return edges, run


def test_reader_parses_every_line(metronome_run):
    edges, run = metronome_run
    assert run.lines[0].startswith("# metrosync gate-logger 1.1 channels=8 tick_us=64 ")
    log = parse_log(run.text, strict=True)  # strict: any line not understood is an error
    assert len(log.ticks) == len(run.lines) - 1
    assert [s.reason for s in log.skipped] == ["logger header"]
    assert log.header.channels == 8 and log.counter_bits == 32 and log.records_lost == 0
    assert log.interrupted_level.tolist() == [1] * 8
    # More than 4.19 s: the 16-bit hardware counter overflowed and the time went on.
    assert log.times[-1] > 7.5 and log.wraps == 0


def test_every_timestamp_is_within_one_tick_of_its_edge(metronome_run):
    edges, run = metronome_run
    assert len(edges) > 350
    assert_within_one_tick(run, edges)


def test_a_line_leaves_the_uart_within_its_transmission_time(metronome_run):
    edges, run = metronome_run
    # A lone edge (none within 5 ms before it) is on the wire after one line's time:
    # 32 bytes at most at 115200 baud (11 bit times each in simavr) is 3.1 ms.
    lone = [t for (t, _, _), (u, _, _) in zip(edges[1:], edges[:-1], strict=True) if t - u > 5e-3]
    line_ends = run.line_cycles / F_CPU
    delays = [line_ends[np.searchsorted(line_ends, t)] - t for t in lone]
    assert 1.0e-3 < np.median(delays) and max(delays) < 3.2e-3


def test_simultaneous_edges_on_all_gates_make_one_line(sim, tmp_path):
    times = 0.05 + 3e-4 * np.arange(40)  # every 300 us, faster than a line leaves
    edges = [(t, g, (k + 1) % 2) for k, t in enumerate(times) for g in range(1, 9)]
    run = run_logger(sim.harness, sim.firmware(), edges, end=0.3, workdir=tmp_path)
    records = [line for line in run.lines if not line.startswith("#")]
    assert len(records) == 1 + 40
    assert records[1].startswith("1-1-1-1-1-1-1-1 ") and records[2].startswith("0-0-0-0-0-0-0-0 ")
    assert_within_one_tick(run, edges)


def staggered_burst(rounds, *, start=0.05, spacing=1e-4):
    """All 8 gates toggling in turn, one edge every ``spacing`` s: 8 edges a round."""
    return [(start + spacing * (8 * k + g - 1), g, (k + 1) % 2)
            for k in range(rounds) for g in range(1, 9)]  # fmt: skip


def test_a_burst_on_all_gates_waits_in_the_buffer_and_loses_nothing(sim, tmp_path):
    # 120 changes in 12 ms, ~20 times faster than the UART sends lines (2.3 ms each):
    # they queue in the 128-record ring and leave over the next quarter second.
    edges = staggered_burst(15)
    run = run_logger(sim.harness, sim.firmware(), edges, end=0.5, workdir=tmp_path)
    assert not any("overflow" in line for line in run.lines)
    assert len(run.lines) == 2 + 120
    assert run.line_cycles[-1] / F_CPU - edges[-1][0] > 0.2  # they did wait
    assert_within_one_tick(run, edges)


def test_a_burst_longer_than_the_buffer_reports_what_it_lost(sim, tmp_path):
    edges = staggered_burst(40)
    run = run_logger(sim.harness, sim.firmware(), edges, end=1.2, workdir=tmp_path)
    log = parse_log(run.text, strict=True)
    records = len(log.ticks) - 1
    overflows = sum(line.startswith("# overflow") for line in run.lines)
    # Each overflow line is followed by the levels as they were when room came back.
    assert log.records_lost > 100
    assert len(edges) <= records + log.records_lost <= len(edges) + overflows
    assert log.levels[-1].tolist() == [0] * 8  # the state after the burst is right
    # Every record before the overflow line is exact; the overflow line sits where
    # the ring was full.
    cut = next(i for i, line in enumerate(run.lines) if line.startswith("# overflow"))
    assert cut >= 128
    shown = printed_changes(run.lines[:cut])
    first = staggered_burst(40)[: cut - 2]
    assert sum(len(v) for v in shown.values()) == len(first)


def test_bounce_does_not_move_the_first_edge_and_a_spike_lasts_one_hold_off(sim, tmp_path):
    t0, t1 = 0.1, 0.2
    bounce = [(t0, 1, 1), (t0 + 2e-5, 1, 0), (t0 + 5e-5, 1, 1), (t0 + 9e-5, 1, 0),
              (t0 + 1.2e-4, 1, 1)]  # fmt: skip
    spike = [(t1, 2, 1), (t1 + 3e-5, 2, 0)]
    run = run_logger(sim.harness, sim.firmware(), bounce + spike, end=0.3, workdir=tmp_path)
    shown = printed_changes(run.lines)
    assert [lv for _, lv in shown[1]] == [1]
    assert 0 <= shown[1][0][0] - expected_tick(run, t0) <= 1
    (rise, up), (fall, down) = shown[2]
    assert (up, down) == (1, 0) and 0 <= rise - expected_tick(run, t1) <= 1
    assert HOLDOFF_TICKS <= fall - rise <= HOLDOFF_TICKS + 1


@pytest.mark.parametrize("start", [NEAR_32_BIT_WRAP, NEAR_16_BIT_WRAP])
def test_counter_wraps_where_documented(sim, tmp_path, start):
    elf = sim.firmware(START_TICKS=f"{start:#x}UL")
    edges = [(0.02 + 0.05 * k, 1 + k % 8, 1 - (k // 8) % 2) for k in range(16)]
    run = run_logger(sim.harness, elf, edges, end=0.9, workdir=tmp_path)
    values = [int(line.split()[1]) for line in run.lines[1:]]
    wrap_at = 4096 * CYCLES_PER_TICK / F_CPU  # 0.262 s after the start
    before = [v for (t, _, _), v in zip(edges, values[1:], strict=True) if t < wrap_at]
    after = [v for (t, _, _), v in zip(edges, values[1:], strict=True) if t > wrap_at]
    if start == NEAR_32_BIT_WRAP:
        # 32 bits: 2**32 ticks of 64 us, the wrap the docs give (76.4 h); it starts again at 0.
        assert min(before) > 2**32 - 4096 and max(after) < 12000
        log = parse_log(run.text)
        assert log.wraps == 1 and log.counter_bits == 32
    else:
        # The hardware counter's 16-bit overflow is extended in software: no wrap.
        assert max(before) < 2**16 <= min(after) and values == sorted(values)
        assert parse_log(run.text).wraps == 0
    assert_within_one_tick(run, edges, start_ticks=start)


def test_fewer_channels_print_fewer_gates(sim, tmp_path):
    elf = sim.firmware(channels=3)
    run = run_logger(sim.harness, elf, [(0.01, 3, 1), (0.02, 7, 1), (0.03, 3, 0)], end=0.1,
                     workdir=tmp_path)  # fmt: skip
    assert " channels=3 " in run.lines[0]
    assert [line.split()[0] for line in run.lines[1:]] == ["0-0-0", "0-0-1", "0-0-0"]


def test_a_question_mark_brings_the_header_again_between_records(sim, tmp_path):
    # Gate 1 passes every 20 ms; '?' arrives once while idle and once inside a burst
    # of all gates; another byte does nothing.
    edges = [(0.01 + 0.02 * k + d, 1, lv) for k in range(20) for d, lv in ((0, 1), (0.005, 0))]
    edges = sorted(edges + staggered_burst(6, start=0.2043))
    rx = [(0.1037, ord("?")), (0.15, ord("x")), (0.2050, ord("?"))]
    run = run_logger(sim.harness, sim.firmware(), edges, end=0.6, workdir=tmp_path, rx=rx)
    headers = [i for i, line in enumerate(run.lines) if line.startswith("#")]
    assert len(headers) == 3, run.lines
    first = run.lines[0]
    assert all(run.lines[i] == first + " requested=1" for i in headers[1:])
    # Each requested header goes out as soon as the line under way is: its last byte
    # leaves within its own time (108 bytes, 10.3 ms) plus a record's (3.1 ms) and the
    # time of the '?' itself (87 us) after the '?' began.
    took = run.line_cycles[headers[1:]] / F_CPU - [0.1037, 0.2050]
    assert np.all((took > 0.0100) & (took < 0.0137)), took
    # Nothing else moved: every record is there, each within a tick of its edge, and
    # the reader takes a requested header for what it is, not for a restart.
    assert_within_one_tick(run, edges)
    log = parse_log(run.text, strict=True)
    assert log.restarts == () and log.header.channels == 8 and log.records_lost == 0
    assert len(log.ticks) == len(run.lines) - 3

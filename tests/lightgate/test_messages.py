"""The logger's header and overflow lines, and `record`'s gap lines, in the reader."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.errors import ChannelCountError, LogFormatError, ParameterError, TimestampError
from metrosync.lightgate import parse_log
from metrosync.lightgate.messages import Gap, LoggerHeader, Overflow, format_gap, parse_message

HEADER = (
    "# metrosync gate-logger 1.0 channels=3 tick_us=64 counter_bits=32 baud=115200 holdoff_ticks=4"
)
BODY = "0-0-0 0\n1-0-0 10\n0-0-0 20\n0-1-0 800\n0-0-0 810\n"


def test_messages_are_recognised():
    h = parse_message(HEADER)
    assert h == LoggerHeader("1.0", 3, 64e-6, 32, 115200, {"holdoff_ticks": "4"})
    assert parse_message("# overflow: 12 records lost\r") == Overflow(12)
    assert parse_message(format_gap(12.3456, "/dev/ttyACM0")) == Gap(12.346)
    for other in ("# hello", "0-0 1", "Welcome to minicom", "", "# overflow: many"):
        assert parse_message(other) is None
    with pytest.raises(LogFormatError, match="tick_us"):
        parse_message("# metrosync gate-logger 2.0 channels=3 counter_bits=32")
    with pytest.raises(LogFormatError, match="out of range"):
        parse_message("# metrosync gate-logger 2.0 channels=9 tick_us=64 counter_bits=32")


def test_header_is_used_and_accounted_for():
    log = parse_log(f"{HEADER}\r\n{BODY}", strict=True)
    assert log.header.channels == 3 and log.counter_bits == 32
    assert log.ticks.tolist() == [0, 10, 20, 800, 810]
    assert [(s.line_number, s.reason) for s in log.skipped] == [(1, "logger header")]
    assert log.n_lines == len(log.ticks) + len(log.skipped)
    assert "gate-logger 1.0, 3 gates, 64 us tick, 32-bit counter" in log.report()


def test_a_requested_header_is_not_a_restart_and_may_come_first_after_records():
    requested = parse_message(HEADER + " requested=1")
    assert requested.requested and not parse_message(HEADER).requested
    assert requested.extra == {"holdoff_ticks": "4"}
    # The port opened without a reset: a fragment, records, then the header asked for.
    text = f"0 7\n{BODY}{HEADER} requested=1\n0-0-1 900\n"
    log = parse_log(text)
    assert log.restarts == () and log.header == requested and log.counter_bits == 32
    assert log.ticks.tolist() == [0, 10, 20, 800, 810, 900]
    # The same header without the key is a restart, which needs a marked gap.
    with pytest.raises(TimestampError, match="restarted"):
        parse_log(text.replace(" requested=1", ""))


def test_a_wrap_of_the_32_bit_counter_is_unwrapped():
    text = f"{HEADER}\n0-0-0 4294967000\n1-0-0 4294967290\n0-0-0 4\n"
    log = parse_log(text)
    assert log.ticks.tolist() == [0, 290, 2**32 - 4294967000 + 4]
    assert log.wraps == 1 and log.counter_bits == 32


def test_header_conflicts_are_errors_that_say_what_to_give():
    with pytest.raises(ParameterError, match="give tick=6.4e-05"):
        parse_log(f"{HEADER}\n{BODY}", tick=1e-3)
    with pytest.raises(ParameterError, match="'auto'"):
        parse_log(f"{HEADER}\n{BODY}", counter_bits=16)
    with pytest.raises(ChannelCountError, match="header says 3"):
        parse_log(f"{HEADER}\n0-0 1\n1-0 5\n")


def test_overflow_is_counted_and_reported():
    lost = "# overflow: 7 records lost\n0-0-1 900\n# overflow: 2 records lost\n"
    log = parse_log(f"{HEADER}\n{BODY}{lost}")
    assert log.records_lost == 9
    assert "LOST 9 records" in log.report()
    one = parse_log(f"{HEADER}\n{BODY}# overflow: 1 records lost\n")
    assert "LOST 1 record: " in one.report()


def test_restart_after_a_marked_gap_continues_the_time_line():
    gap = format_gap(2.0, "/dev/ttyACM0")
    text = f"{HEADER}\n{BODY}{gap}\n{HEADER}\n0-0-0 0\n0-0-1 100\n"
    log = parse_log(text)
    assert log.restarts == (9,)
    expected_after = 810 + round(2.0 / 64e-6)
    assert log.ticks.tolist() == [0, 10, 20, 800, 810, expected_after, expected_after + 100]
    assert "restarted 1 time (records resume at lines 9)" in log.report()
    assert np.all(np.diff(log.ticks) >= 0)


def test_gap_without_restart_keeps_the_counter():
    text = f"{HEADER}\n{BODY}{format_gap(5.0, 'x')}\n0-0-1 900\n"
    log = parse_log(text)
    assert log.ticks[-1] == 900 and log.restarts == ()


def test_restart_without_a_marked_gap_is_refused_with_the_fix():
    with pytest.raises(TimestampError, match="--reconnect"):
        parse_log(f"{HEADER}\n{BODY}{HEADER}\n0-0-0 0\n0-0-1 100\n")

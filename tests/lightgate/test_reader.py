"""The log reader: tolerance of messy captures, accounting of every line, refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from metrosync.errors import (
    ChannelCountError,
    EmptyLogError,
    LogFormatError,
    StrictModeError,
    TimestampError,
)
from metrosync.lightgate import parse_log, read_log

DATA = Path(__file__).parent.parent / "data"
CLEAN = (DATA / "clean.log").read_text()


def test_records_times_and_polarity():
    log = parse_log("0-0 100\n1-0 110\n0-0 120\n0-1 900\n0-0 910\n1-0 1700\n0-0 1712\n")
    assert log.channels == 2
    assert log.ticks.tolist() == [0, 10, 20, 800, 810, 1600, 1612]
    assert np.allclose(log.times, log.ticks * 64e-6)
    assert log.interrupted_level.tolist() == [1, 1]  # 1 is the short state
    assert log.skipped == ()


def test_polarity_is_detected_not_assumed():
    log = parse_log("1-1 0\n0-1 10\n1-1 20\n1-0 900\n1-1 910\n0-1 1700\n1-1 1712\n")
    assert log.interrupted_level.tolist() == [0, 0]
    assert log.interrupted[1].tolist() == [True, False]


def test_messy_capture_counts_every_skipped_line():
    log = read_log(DATA / "messy.log")
    assert log.n_lines == len(log.ticks) + len(log.skipped)
    numbers = {s.line_number: s.reason for s in log.skipped}
    assert numbers[2] == "not a gate record"  # the terminal banner
    assert numbers[1] == "blank line"
    assert "cut-off" in numbers[log.n_lines]
    assert log.wraps == 5 and log.counter_bits == 16


def test_crlf_and_cr_line_ends_parse_alike():
    lf = parse_log(CLEAN)
    crlf = parse_log(CLEAN.replace("\n", "\r\n"))
    assert np.array_equal(lf.ticks, crlf.ticks) and np.array_equal(lf.levels, crlf.levels)


def test_strict_mode_refuses_the_first_skipped_line():
    with pytest.raises(StrictModeError, match="line 2"):
        parse_log("0-0 1\nhello\n1-0 5\n", strict=True)


def test_counter_wrap_is_unwrapped_with_given_or_detected_width():
    text = "0 65000\n1 65530\n0 20\n1 500\n"
    for bits in ("auto", 16):
        log = parse_log(text, counter_bits=bits)
        assert log.ticks.tolist() == [0, 530, 556, 1036]
        assert log.wraps == 1 and log.counter_bits == 16


def test_refuses_empty_file(tmp_path):
    path = tmp_path / "empty.log"
    path.write_text("")
    with pytest.raises(EmptyLogError):
        read_log(path)
    with pytest.raises(EmptyLogError):
        parse_log("Welcome to minicom\n\n")


def test_refuses_channel_count_change_mid_file():
    with pytest.raises(ChannelCountError, match="line 3"):
        parse_log("0-0-0 1\n1-0-0 5\n1-0 9\n0-0-0 12\n0-1-0 20\n")


def test_partial_record_at_either_end_is_skipped_not_refused():
    log = parse_log("0-0 1\n0-0-0 5\n1-0-0 9\n0-0-0 12\n0-1")
    assert log.channels == 3
    assert [s.line_number for s in log.skipped] == [1, 5]


def test_refuses_timestamps_that_cannot_be_unwrapped():
    with pytest.raises(TimestampError, match="line 3"):
        parse_log("0 60000\n1 60010\n0 59000\n1 60100\n", counter_bits=16)
    with pytest.raises(TimestampError):
        parse_log("0 10\n1 5\n0 20\n", counter_bits=None)
    with pytest.raises(TimestampError, match="does not fit"):
        parse_log("0 70000\n1 70010\n", counter_bits=16)


def _accounted(text: str) -> None:
    try:
        log = parse_log(text)
    except LogFormatError:
        return
    n_lines = len(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"))
    n_lines -= text.endswith(("\n", "\r"))
    assert log.n_lines == n_lines
    assert len(log.ticks) + len(log.skipped) == log.n_lines
    assert np.all(np.diff(log.ticks) >= 0)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(alphabet=st.sampled_from("01- \t\r\n9x"), max_size=300))
def test_random_captures_raise_only_documented_errors(text):
    _accounted(text)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, len(CLEAN)), st.integers(0, len(CLEAN)))
def test_truncated_captures(start, stop):
    _accounted(CLEAN[min(start, stop) : max(start, stop)])


@settings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(st.integers(0, len(CLEAN) - 1), st.characters()), max_size=8))
def test_corrupted_captures(edits):
    chars = list(CLEAN[:2000])
    for pos, char in edits:
        chars[pos % len(chars)] = char
    _accounted("".join(chars))


@settings(max_examples=50, deadline=None)
@given(st.binary(max_size=200))
def test_random_bytes_from_files(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("bytes") / "capture.log"
    path.write_bytes(data)
    try:
        log = read_log(path)
    except LogFormatError:
        return
    assert len(log.ticks) + len(log.skipped) == log.n_lines

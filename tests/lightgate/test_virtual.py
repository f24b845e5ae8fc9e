"""The virtual gate: edges from Hermite-interpolated trajectories, and the log text."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.lightgate import LightGate, format_log, gate_edges, parse_log


def sine(dt=0.01, duration=5.0, amp=0.7, omega=20.0):
    t = np.arange(0, duration, dt)
    return t, amp * np.sin(omega * t), amp * omega * np.cos(omega * t)


def test_edges_match_the_exact_crossings_of_a_sine():
    t, th, thd = sine()
    amp, omega, offset, width = 0.7, 20.0, 0.1, 0.05
    initial, times, entering = gate_edges(t, th, thd, offset=offset, width=width)
    assert not initial
    lo, hi = (
        np.arcsin((offset - width / 2) / amp) / omega,
        np.arcsin((offset + width / 2) / amp) / omega,
    )
    assert entering[0] and np.isclose(times[0], lo, atol=2e-6)
    assert not entering[1] and np.isclose(times[1], hi, atol=2e-6)
    assert times.size % 2 == 0 and np.all(entering[0::2]) and not np.any(entering[1::2])


def test_log_round_trips_through_the_reader_with_wrap_and_inverted_polarity():
    t, th, thd = sine()
    theta = np.stack([th, np.roll(th, 7)], axis=1)
    theta_dot = np.stack([thd, np.roll(thd, 7)], axis=1)
    gate = LightGate(counter_bits=12, start_tick=4000, interrupted_level=0)
    log = parse_log(format_log(t, theta, theta_dot, gate))
    assert log.wraps > 0 and log.interrupted_level.tolist() == [0, 0]
    _, times, _ = gate_edges(t, th, thd, offset=gate.offset, width=gate.width)
    first = log.times[np.flatnonzero(log.interrupted[:, 0])[0]]
    assert abs(first - times[0]) <= gate.tick


def test_more_than_eight_metronomes_are_refused():
    t, th, thd = sine(duration=0.5)
    with pytest.raises(ParameterError, match="8 gates"):
        format_log(t, np.tile(th[:, None], 9), np.tile(thd[:, None], 9))


def test_gate_settings_are_checked():
    with pytest.raises(ParameterError, match="width"):
        LightGate(width=0.0)

"""Cleaning: one pass per period in one direction, glitches, missed passes, stops."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.lightgate import clean_channel
from metrosync.lightgate.cleaning import interruptions

PERIOD, SHORT, WIDTH = 0.6, 0.25, 0.004


def edges_for(passes, width=WIDTH, t_end=None):
    """Record times and states for interruptions centred on ``passes``."""
    times = [0.0]
    states = [False]
    for p in passes:
        times += [p - width / 2, p + width / 2]
        states += [True, False]
    if t_end is not None:
        times.append(t_end)
        states.append(False)
    return np.array(times), np.array(states)


def alternating(n=30, start=0.3):
    up = start + PERIOD * np.arange(n)
    return up, up + SHORT


def test_keeps_the_pass_opening_the_short_interval():
    up, down = alternating()
    res = clean_channel(*edges_for(np.sort(np.concatenate([up, down]))))
    assert np.allclose(res.kept, up)
    assert np.allclose(res.second, down)
    assert np.all(res.cycles == 1)
    assert res.dropped["second pass"] == up.size and not res.direction_ambiguous


def test_glitches_and_flicker_are_removed():
    up, down = alternating()
    passes = np.sort(np.concatenate([up, down]))
    times, states = edges_for(passes)
    # a 0.1 ms spurious interruption, and a 0.1 ms open flicker inside a pass
    extra_t = [up[5] + 0.1, up[5] + 0.1001, up[9] - 0.00005, up[9] + 0.00005]
    extra_s = [True, False, False, True]
    order = np.argsort(np.concatenate([times, extra_t]), kind="stable")
    t = np.concatenate([times, extra_t])[order]
    s = np.concatenate([states, extra_s])[order]
    res = clean_channel(t, s)
    assert res.dropped["glitch"] == 1 and res.merged == 1
    assert np.allclose(res.kept, up, atol=1e-4)


def test_missed_pass_is_bridged_as_two_periods():
    up, down = alternating()
    passes = np.sort(np.concatenate([np.delete(up, 12), down]))
    res = clean_channel(*edges_for(passes))
    assert res.kept.size == up.size - 1
    assert res.cycles.sum() == up.size - 1 and res.cycles.max() == 2


def test_partial_interruptions_at_both_ends_are_dropped():
    up, down = alternating()
    times, states = edges_for(np.sort(np.concatenate([up, down])))
    times = np.concatenate([[0.0], times[2:], [times[-1] + 0.1]])
    states = np.concatenate([[True], states[2:], [True]])
    res = clean_channel(times, states)
    assert res.dropped["partial at start"] == 1 and res.dropped["partial at end"] == 1


def test_a_stopping_metronome_ends_its_passes_and_a_stuck_beam_is_dropped():
    up, down = alternating(20)
    passes = np.sort(np.concatenate([up, down]))
    times, states = edges_for(passes)
    # the bob comes to rest inside the beam for 5 s, then the capture ends
    times = np.concatenate([times, [times[-1] + 0.5, times[-1] + 5.5, times[-1] + 6]])
    states = np.concatenate([states, [True, False, False]])
    res = clean_channel(times, states)
    assert res.dropped["too long"] == 1
    assert np.allclose(res.kept, up)


def test_centred_gate_is_flagged_ambiguous():
    passes = 0.3 + 0.3 * np.arange(40)
    res = clean_channel(*edges_for(passes))
    assert res.direction_ambiguous
    assert res.kept.size == 20


def test_every_interruption_is_accounted_for():
    rng = np.random.default_rng(3)
    up, down = alternating(40)
    passes = np.sort(np.concatenate([up, down]) + rng.normal(0, 0.01, 80))
    passes = np.delete(passes, [7, 30, 31])
    times, states = edges_for(passes)
    res = clean_channel(times, states)
    n_complete = interruptions(times, states)[0].size
    assert res.kept.size + sum(res.dropped.values()) == n_complete


def test_bad_options_are_refused():
    from metrosync.errors import ParameterError

    with pytest.raises(ParameterError, match="glitch"):
        clean_channel(np.arange(3.0), np.zeros(3, bool), glitch=-1)

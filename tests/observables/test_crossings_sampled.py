"""Passes from a sampled angle (video): sub-sample crossings, bridging, amplitude, beat."""

import numpy as np
import pytest

from metrosync.observables import crossings as ph


def sine_crossings(f, phase, t_end, upward=True):
    """Exact times where sin(2π f t + phase) crosses 0 upward (or downward) in [0, t_end]."""
    k = np.arange(-2, int(f * t_end) + 3)
    base = 0.0 if upward else np.pi
    t = (2 * np.pi * k + base - phase) / (2 * np.pi * f)
    return t[(t > 0) & (t < t_end)]


@pytest.mark.parametrize("fps", [30.0, 60.0])
def test_crossings_of_a_sampled_sine_are_found_well_inside_a_frame(fps, rng):
    f, phase, t_end = 1.43, 0.7, 30.0
    t = np.sort(np.arange(0, t_end, 1 / fps) + rng.uniform(-0.3, 0.3, int(t_end * fps)) / fps)
    angle = 0.4 * np.sin(2 * np.pi * f * t + phase)
    for upward in (True, False):
        got = ph.zero_crossings(t, angle, upward=upward)
        true = sine_crossings(f, phase, t_end, upward)
        true = true[(true > t[2]) & (true < t[-3])]
        got = got[(got > t[2]) & (got < t[-3])]
        assert got.size == true.size
        # the cubic through six samples: far below a frame, far below a linear fit's error
        assert np.max(np.abs(got - true)) < 2e-4


def test_noise_near_zero_gives_one_pass_with_hysteresis():
    t = np.arange(0, 10, 0.01)
    angle = np.sin(2 * np.pi * 0.5 * t)
    angle[(angle > -0.05) & (angle < 0.05)] *= -1  # a wiggle at every crossing
    assert ph.zero_crossings(t, angle).size > 5
    assert ph.zero_crossings(t, angle, hysteresis=0.2).size == 5


def test_no_crossing_is_placed_across_a_gap():
    t = np.arange(0, 4, 0.02)
    angle = np.sin(2 * np.pi * t)
    gap = (t > 0.9) & (t < 1.1)
    angle[gap] = np.nan
    got = ph.zero_crossings(t, angle)
    assert not np.any((got > 0.9) & (got < 1.1))
    assert np.allclose(got, [2.0, 3.0], atol=1e-5)  # 1.0 falls in the gap


def test_a_missed_pass_is_bridged_as_two_periods():
    up = np.array([0.0, 1.0, 2.0, 4.0, 5.0])
    kept, cycles = ph.passes_on_period_grid(up)
    assert list(cycles) == [1, 1, 2, 1]
    assert ph.mean_frequency_bpm(kept, cycles) == pytest.approx(120.0)


def test_amplitude_and_asymmetry_of_a_lopsided_swing():
    t = np.arange(0, 20, 0.002)
    f, delay = 1.0, 0.03  # the downward pass 30 ms late: right half-swing 6 % longer
    phase = 2 * np.pi * f * t
    angle = 0.3 * np.sin(phase)
    up = sine_crossings(f, 0.0, 20.0)
    down = sine_crossings(f, 0.0, 20.0, upward=False) + delay
    assert ph.beat_asymmetry(up, down) == pytest.approx(100 * 2 * delay, rel=1e-6)
    kept, _ = ph.passes_on_period_grid(ph.zero_crossings(t, angle))
    assert np.allclose(ph.swing_amplitudes(t, angle, kept), 0.3, rtol=1e-4)

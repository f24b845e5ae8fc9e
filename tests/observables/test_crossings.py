"""Phases, r(t), frequencies and σ from kept passes."""

from __future__ import annotations

import numpy as np

from metrosync.observables import crossings as ph


def test_phase_rises_linearly_between_kept_passes_and_across_bridged_gaps():
    kept = np.array([1.0, 2.0, 4.0])
    grid = np.array([0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 4.5])
    phase = ph.unwrapped_phase(kept, np.array([1, 2]), grid)
    assert np.isnan(phase[0]) and np.isnan(phase[-1])
    assert np.allclose(phase[1:-1], 2 * np.pi * np.array([0, 0.5, 1, 2, 3]))


def test_order_is_one_for_equal_phases_and_zero_for_balanced_ones():
    grid = np.linspace(1, 9, 50)
    base = np.arange(11.0)
    same = [(base, np.ones(10, int))] * 3
    assert np.allclose(ph.order_on_grid(same, grid), 1.0)
    spread = [(base + k / 3, np.ones(10, int)) for k in range(3)]
    assert np.allclose(ph.order_on_grid(spread, grid[grid > 1]), 0.0, atol=1e-12)


def test_frequency_jitter_and_sigma():
    kept = np.arange(0, 60.0001, 0.625)  # 0.625 s periods: 192 BPM
    assert np.isclose(ph.mean_frequency_bpm(kept, np.ones(kept.size - 1)), 192.0)
    assert ph.period_jitter(kept, np.ones(kept.size - 1)) < 1e-12
    assert np.isclose(ph.frequency_spread([191.0, 192.0, 193.0]), 1.0)
    # 0.75 BPM is the paper's 8e-7 per 64 µs tick (docs/model.md §6.4)
    assert np.isclose(ph.bpm_to_beats_per_tick(0.75, 64e-6), 8e-7)


def test_common_grid_is_the_intersection_on_multiples_of_dt():
    grid = ph.common_grid([(0.33, 10.0), (1.01, 9.55)], 0.1)
    assert np.isclose(grid[0], 1.1) and np.isclose(grid[-1], 9.5)


def test_passes_both_ways_keep_one_direction_and_count_missed_periods():
    """A sound hears a tick each way: ticks numbered in half periods, with one missed."""
    times = np.arange(10) * 0.3125
    half = np.arange(10)
    keep = half != 4  # a tick of the kept direction missed
    kept, cycles = ph.kept_from_half_periods(times[keep], half[keep])
    assert np.allclose(kept, times[[0, 2, 6, 8]])
    assert cycles.tolist() == [1, 2, 1]
    assert np.isclose(ph.mean_frequency_bpm(kept, cycles), 192.0)
    tocks, _ = ph.kept_from_half_periods(times, half, parity=1)
    assert np.allclose(tocks, times[1::2])

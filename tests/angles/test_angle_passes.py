"""The model: a sampled angle's passes through its rest value, against exact crossings."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.angles import AngleTableError, Swing, passes

PERIOD, SWING, REST = 1.137, 12.0, 7.1  # s, degrees, degrees


def swing(times, values, name="theta"):
    times = np.asarray(times, dtype=float)
    lines = np.arange(2, times.size + 2)
    return Swing(name, times, np.asarray(values, dtype=float), "deg", lines, f"angle {name!r}")


def sampled(rate=100.0, duration=60.0, *, jitter=0.0, seed=0):
    """A sine about REST, sampled at irregular times (jitter, s), and its exact upward
    crossings of REST."""
    rng = np.random.default_rng(seed)
    times = np.arange(0, duration, 1 / rate) + rng.uniform(0, jitter, int(duration * rate))
    times.sort()
    values = REST + SWING * np.sin(2 * np.pi * (times / PERIOD) + 0.4)
    first = (2 * np.pi - 0.4) / (2 * np.pi) * PERIOD
    exact = first + PERIOD * np.arange(int(duration / PERIOD) + 1)
    return times, values, exact[(exact > times[3]) & (exact < times[-4])]


def test_the_passes_are_the_exact_upward_crossings_of_the_rest_angle():
    times, values, exact = sampled(jitter=4e-3)
    found = passes(swing(times, values), "t.csv")
    # The median sits within the half step the bob moves between samples at the bottom;
    # the cubic through six samples times each crossing of it.
    step = SWING * 2 * np.pi / PERIOD * 0.01
    assert abs(found.rest - REST) < step / 2
    delay = (found.rest - REST) / (SWING * 2 * np.pi / PERIOD)
    assert found.kept.size == exact.size and np.all(found.cycles == 1)
    assert np.abs(found.kept - exact - delay).max() < 1e-5
    assert abs(found.amplitude - SWING) < 0.05 and found.gaps == found.irregular == 0


def test_encoder_steps_and_a_zero_off_the_vertical_leave_the_period():
    times, values, exact = sampled()
    counts = np.round(values / 0.36) * 0.36  # 1000 lines: 0.36 degree steps
    found = passes(swing(times, counts), "encoder.csv")
    periods = np.diff(found.kept)
    assert abs(periods.mean() - PERIOD) < 2e-4 and periods.std() < 3e-3
    assert abs(found.rest - REST) < 0.36


def test_no_pass_is_placed_across_a_gap_or_blank_cells_and_the_grid_bridges_it():
    times, values, exact = sampled()
    crossing = exact[10]
    lost = np.abs(times - crossing) < 0.1  # samples a logger lost around one crossing
    gap = passes(swing(times[~lost], values[~lost]), "gap.csv")
    blank = values.copy()
    blank[lost] = np.nan  # Tracker: frames not marked
    cells = passes(swing(times, blank), "blank.csv")
    for found in (gap, cells):
        assert found.kept.size == exact.size - 1 and found.bridged == 1
        assert np.min(np.abs(found.kept - crossing)) > 0.5
    assert gap.gaps == 1 and cells.gaps == 0


def test_a_time_that_goes_back_is_refused_naming_its_line():
    times, values, _ = sampled()
    times[500], times[501] = times[501], times[500]
    with pytest.raises(AngleTableError, match=r"t.csv: line 503: time 5 s follows 5.01 s "
                       r"\(line 502\): the time column must increase"):  # fmt: skip
        passes(swing(times, values), "t.csv")


def test_too_few_samples_or_passes_are_refused():
    times, values, _ = sampled(duration=60)
    with pytest.raises(AngleTableError, match="theta has 9 samples .*too few for a swing"):
        passes(swing(times[:9], values[:9]), "t.csv")
    with pytest.raises(AngleTableError, match=r"value [0-9.]+ upward 2 times in 2.49 s, too few"):
        passes(swing(times[:250], values[:250]), "t.csv")


def test_what_does_not_swing_keeps_no_period():
    """Tracker's track of the pivot: marks scattered about a point."""
    rng = np.random.default_rng(3)
    times = np.arange(0, 60, 1 / 30)
    with pytest.raises(AngleTableError, match=r"pivot A .* keeps no period: \d+ of \d+ "
                       r"intervals .*Is it a pendulum"):  # fmt: skip
        passes(swing(times, rng.normal(0, 1e-3, times.size), "pivot A"), "tracker.txt")

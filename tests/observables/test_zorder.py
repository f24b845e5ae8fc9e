import numpy as np
import pytest

from metrosync.observables import extrema_times, z_order

T = np.arange(0, 60, 0.01)
W = 2 * np.pi / 0.62


def test_extrema_are_refined_below_the_sampling_step():
    x = np.cos(W * (T - 0.1234))
    maxima = extrema_times(T, x, "max")
    period = 2 * np.pi / W
    np.testing.assert_allclose(
        (maxima - 0.1234) / period, np.round((maxima - 0.1234) / period), atol=1e-4
    )


@pytest.mark.parametrize("shift, expected", [(0.0, 1.0), (np.pi, -1.0)])
def test_z_is_one_in_phase_and_minus_one_in_antiphase(shift, expected):
    assert z_order(T, np.cos(W * T), np.cos(W * T + shift)) == pytest.approx(expected, abs=1e-3)


def test_z_of_a_quarter_period_lag_is_zero():
    # `start` drops the first swing, whose maximum of θ₂ has no earlier maximum of θ₁.
    assert z_order(T, np.cos(W * T), np.sin(W * T), start=1.0) == pytest.approx(0.0, abs=1e-3)


def test_z_is_nan_without_oscillation():
    assert np.isnan(z_order(T, np.ones_like(T), np.cos(W * T)))

import math

import numpy as np
import pytest

from metrosync import Metronome, MetronomeDesign, ParameterError, bpm_to_omega, omega_to_bpm
from metrosync.model import balance_amplitude


def test_bpm_means_two_beats_per_period():
    assert bpm_to_omega(60.0) == pytest.approx(math.pi)  # one period every 2 s
    assert omega_to_bpm(bpm_to_omega(192.0)) == pytest.approx(192.0)


def test_derived_quantities_follow_the_paper():
    d = MetronomeDesign()
    m = Metronome(d, 0.03)
    assert m.mass == pytest.approx(0.025 + 0.0069)
    assert m.h == pytest.approx((0.025 * 0.0358 - 0.0069 * 0.03) / 0.0319)
    assert m.j == pytest.approx(0.025 * 0.0358**2 + 0.0069 * 0.03**2)
    assert m.inertia == pytest.approx(m.mass * m.h**2 + m.j)
    assert m.natural_omega == pytest.approx(math.sqrt(m.mass * 9.81 * m.h / m.inertia))


@pytest.mark.parametrize("bpm", [100.0, 160.0, 185.0, 192.0, 208.0, 236.0])
def test_tuning_inverts_the_natural_frequency(bpm):
    d = MetronomeDesign()
    l2 = d.l2_for_bpm(bpm)
    assert d.l2_bounds[0] <= l2 <= d.l2_bounds[1]
    assert d.with_l2(l2).natural_bpm == pytest.approx(bpm, rel=1e-12)


def test_tuning_is_vectorised_and_monotone():
    d = MetronomeDesign()
    bpm = np.linspace(150, 230, 50)
    l2 = d.l2_for_bpm(bpm)
    assert l2.shape == bpm.shape
    assert np.all(np.diff(l2) < 0)  # a higher slider beats slower


def test_paper_l2_range_maps_to_185_to_227_bpm():
    # docs/model.md §6.2: the published L2 range does not tune 160–208 BPM in this model.
    d = MetronomeDesign()
    assert d.with_l2(0.049).natural_bpm == pytest.approx(185, abs=1)
    assert d.with_l2(0.019).natural_bpm == pytest.approx(227, abs=1)


def test_bpm_outside_tunable_range_is_rejected():
    d = MetronomeDesign()
    low, high = d.bpm_range()
    with pytest.raises(ParameterError, match=r"`bpm` = 300 is outside the tunable range"):
        d.l2_for_bpm(300.0)
    with pytest.raises(ParameterError, match="bpm"):
        d.l2_for_bpm(low - 1)
    with pytest.raises(ParameterError, match="finite"):
        d.l2_for_bpm(float("nan"))


@pytest.mark.parametrize("tuning", ["small-amplitude", "steady-swing"])
@pytest.mark.parametrize("bpm", [0.0, -5.0])
def test_a_tempo_at_or_below_zero_is_refused_as_such(bpm, tuning):
    # It once recursed without end: the fix offered for a low BPM asked a widened
    # design to tune to it, which was out of its range too.
    d = MetronomeDesign(tuning=tuning)
    with pytest.raises(ParameterError, match=r"`bpm` = -?\d+ BPM: a tempo must be positive"):
        d.l2_for_bpm(bpm)


def test_a_slow_tempo_no_slider_position_reaches_says_so():
    with pytest.raises(ParameterError, match=r"no slider position reaches it"):
        MetronomeDesign().l2_for_bpm(1e-3)


def test_inverted_pendulum_is_rejected():
    with pytest.raises(ParameterError, match=r"h = .* <= 0.*inverted"):
        Metronome(MetronomeDesign(), l2=0.2)
    with pytest.raises(ParameterError, match="inverted"):
        MetronomeDesign(l2_bounds=(0.0, 0.2))


@pytest.mark.parametrize(
    "field, value",
    [("w1", -0.01), ("w2", -1.0), ("l1", 0.0), ("c_theta", -1e-5), ("drive", -1.0), ("g", 0.0),
     ("w1", float("nan")), ("drive", float("inf"))],
)  # fmt: skip
def test_negative_or_non_finite_parameters_are_rejected(field, value):
    with pytest.raises(ParameterError, match=f"`{field}`"):
        MetronomeDesign(**{field: value})


def test_energy_balance_amplitude():
    assert balance_amplitude(6e-5, 5e-5) == pytest.approx(2 * 6e-5 / (math.pi * 5e-5))
    assert balance_amplitude(6e-4, 5e-5) == pytest.approx(7.64, abs=0.01)
    assert balance_amplitude(0.0, 0.0) == 0.0

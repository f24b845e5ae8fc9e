import math
import warnings

import pytest

from metrosync import PRESETS, OverturnWarning, ParameterError, Platform, get_preset


def test_disk_inertia_law_matches_the_published_range():
    p = Platform()
    assert p.disk_inertia(7) == pytest.approx(0.25515)
    assert p.j0 == pytest.approx(0.0729)
    assert p.disk_inertia(1000) == pytest.approx(0.0729 + 1000 * (0.25515 - 0.0729) / 7)


def test_fixed_and_rigid_inertia():
    assert Platform(inertia=1.0).disk_inertia(50) == 1.0
    assert Platform(inertia=math.inf).rigid


@pytest.mark.parametrize(
    "kwargs, name",
    [({"radius": -0.1}, "radius"), ({"c_phi": -1.0}, "c_phi"), ({"inertia": -2.0}, "inertia"),
     ({"j0": float("nan")}, "j0")],
)  # fmt: skip
def test_bad_platform_parameters(kwargs, name):
    with pytest.raises(ParameterError, match=f"`{name}`"):
        Platform(**kwargs)


def test_disk_inertia_needs_a_metronome():
    with pytest.raises(ParameterError, match="`n` must be >= 1"):
        Platform().disk_inertia(0)


def test_published_preset_warns_that_it_overturns():
    with pytest.warns(OverturnWarning, match="overturn"):
        params = get_preset("boda2013")
    assert params.metronome.drive == 6e-4
    assert params.overturns


def test_default_preset_is_quiet_and_swings_like_a_metronome():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        params = get_preset("default")
    assert params.balance_amplitude == pytest.approx(0.764, abs=0.001)
    assert not params.overturns


def test_published_values():
    p = PRESETS["boda2013"]
    m, d = p.metronome, p.platform
    assert (m.w1, m.w2, m.l1, m.c_theta, m.drive) == (0.025, 0.0069, 0.0358, 5e-5, 6e-4)
    assert (d.radius, d.c_phi) == (0.27, 1e-5)


def test_unknown_preset_lists_the_valid_ones():
    with pytest.raises(ParameterError, match=r"unknown preset 'nope'.*boda2013.*default"):
        get_preset("nope")


def test_with_changes_routes_names_and_rejects_unknown_ones():
    p = get_preset("default").with_changes(drive=1e-4, c_phi=0.0)
    assert p.metronome.drive == 1e-4 and p.platform.c_phi == 0.0
    with pytest.raises(ParameterError, match="unknown model parameter"):
        get_preset("default").with_changes(bogus=1.0)

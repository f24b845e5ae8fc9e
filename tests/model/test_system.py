"""Model quantities are computed once: `Metronome` and the ensemble's constants agree
exactly, and the tunable-range check names whichever argument was out of range."""

import numpy as np
import pytest

from metrosync import ParameterError, build_ensemble, get_preset
from metrosync.model import (
    Metronome,
    MetronomeDesign,
    centre_of_mass,
    natural_omega,
    pendulum_inertia,
    pivot_moment,
    system_arrays,
)


def test_metronome_properties_and_ensemble_constants_are_the_same_numbers():
    params = get_preset("default")
    ens = build_ensemble(4, 200.0, params=params, sigma_bpm=3.0, runs=3, seed=5)
    design = params.metronome
    for b in range(3):
        for i in range(4):
            m = Metronome(design=design, l2=float(ens.l2[b, i]))
            assert ens.system.inertia[b, i] == m.inertia
            assert ens.system.omega[b, i] == m.natural_omega
            assert ens.system.mh[b, i] == m.mass * m.h
            assert ens.frequency_bpm[b, i] == pytest.approx(m.natural_bpm, rel=1e-15)


def test_array_functions_broadcast_and_match_the_paper():
    w1, w2, l1 = 0.025, 0.0069, 0.0358
    l2 = np.array([0.01, 0.03, 0.05])
    h = centre_of_mass(w1, w2, l1, l2)
    np.testing.assert_allclose(h, (w1 * l1 - w2 * l2) / (w1 + w2))
    np.testing.assert_allclose(pivot_moment(w1, w2, l1, l2), w1 * l1**2 + w2 * l2**2)
    inertia = pendulum_inertia(w1, w2, l1, l2)
    np.testing.assert_allclose(inertia, (w1 + w2) * h**2 + w1 * l1**2 + w2 * l2**2)
    np.testing.assert_allclose(
        natural_omega(w1, w2, l1, l2, 9.81), np.sqrt((w1 + w2) * 9.81 * h / inertia)
    )


def test_explicit_metronomes_keep_their_own_design_values():
    params = get_preset("default")
    light = Metronome(design=MetronomeDesign(w1=0.02, drive=1e-5), l2=0.02)
    heavy = Metronome(design=MetronomeDesign(w1=0.03, c_theta=7e-5), l2=0.04)
    ens = build_ensemble(
        None, None, params=params, metronomes=[light, heavy], runs=2, amplitude=0.3
    )
    np.testing.assert_array_equal(ens.system.inertia, [[light.inertia, heavy.inertia]] * 2)
    np.testing.assert_array_equal(ens.system.drive, [[1e-5, 6e-5]] * 2)
    np.testing.assert_array_equal(ens.system.c_theta, [[5e-5, 7e-5]] * 2)


def test_an_inverted_pendulum_is_refused_by_the_builder():
    params = get_preset("default")
    with pytest.raises(ParameterError, match=r"h <= 0.*`l2`"):
        system_arrays(params, np.full((1, 2), 0.2))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"bpm": 400.0}, r"^`bpm` = 400 is outside the tunable range \[.*shorter rod `l1`"),
        ({"bpm": 80.0}, r"^`bpm` = 80 is outside the tunable range \[.*widen `l2_bounds`"),
        (
            {"bpm": None, "n": None, "frequencies_bpm": [200.0, 250.0]},
            r"^`frequencies_bpm\[1\]` = 250 is outside the tunable range",
        ),
        (
            {"sigma_bpm": 60.0},
            r"^with `sigma_bpm` = 60.0, a drawn natural frequency \(\d+\.\d+ BPM\) is outside "
            r"the tunable range .*Lower `sigma_bpm`",
        ),
    ],
)
def test_the_tunable_range_message_names_the_argument(kwargs, message):
    args = {"n": 3, "bpm": 200.0, "params": get_preset("default"), **kwargs}
    with pytest.raises(ParameterError, match=message):
        build_ensemble(args.pop("n"), args.pop("bpm"), **args)

"""Shared fixtures: small ensembles whose constants tests can reuse."""

import numpy as np
import pytest

from metrosync import build_ensemble, get_preset


@pytest.fixture
def small_ensemble():
    """3 runs × 5 metronomes with spread, friction and drive, random phases."""
    return build_ensemble(5, 192.0, params=get_preset("default"), sigma_bpm=2.0, runs=3, seed=11)


@pytest.fixture
def rng():
    return np.random.default_rng(20131)

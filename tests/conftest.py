"""Shared fixtures: small ensembles whose constants tests can reuse."""

import signal

import numpy as np
import pytest

from metrosync import build_ensemble, get_preset
from metrosync.equations import SystemArrays

# A suite started in the background of a non-interactive shell (`make test &`) inherits
# SIGINT ignored, and so would every process it starts. The Ctrl-C tests need Python's
# handler here and the default disposition in their children: restore it.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture
def small_ensemble():
    """3 runs × 5 metronomes with spread, friction and drive, random phases."""
    return build_ensemble(5, 192.0, params=get_preset("default"), sigma_bpm=2.0, runs=3, seed=11)


@pytest.fixture
def rng():
    return np.random.default_rng(20131)


@pytest.fixture
def random_system(rng):
    """A factory of random, physically sensible `SystemArrays` of B runs × N metronomes."""

    def make(b=4, n=6):
        mass = rng.uniform(0.02, 0.05, (b, n))
        h = rng.uniform(0.005, 0.03, (b, n))
        j = rng.uniform(1e-5, 1e-4, (b, n))
        radius = rng.uniform(0.1, 0.5, b)
        return SystemArrays(
            mh=mass * h,
            mgh=mass * 9.81 * h,
            inertia=mass * h**2 + j,
            c_theta=rng.uniform(0, 1e-4, (b, n)),
            drive=rng.uniform(0, 1e-3, (b, n)),
            omega=np.ones((b, n)),
            lever=radius,
            c_phi=rng.uniform(0, 1e-4, b),
            total_inertia=rng.uniform(0.05, 0.5, b) + radius**2 * mass.sum(axis=1),
            dry_friction=np.zeros(b),
        )

    return make

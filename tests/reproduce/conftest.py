"""Shared fixtures: one tiny reproduction, run once per test session."""

from __future__ import annotations

import pytest

from metrosync.paper.pipeline import reproduce
from metrosync.paper.studies import (
    ESTIMATION,
    FIG8_BOTTOM,
    FIG8_TOP,
    FIG10,
    FIG11,
    Z_STUDY,
    Statistics,
    reduced,
)


def tiny_studies():
    """Every study, shrunk to seconds of work (shapes and plumbing, not physics)."""
    return [
        reduced(FIG8_TOP, runs=3, duration=60.0),
        reduced(FIG8_BOTTOM, runs=3, duration=60.0),
        reduced(FIG10, ns=(7, 16), bpms=(170.0, 190.0, 210.0), stats=Statistics(3, 60.0)),
        reduced(FIG11, runs=2, duration=60.0),
        reduced(Z_STUDY, duration=60.0, theta2=(-0.1, 0.0, 0.1)),
        reduced(ESTIMATION, c_phi_scan=(1e-6, 1e-5, 1.0, 10.0)),
    ]


@pytest.fixture(scope="session")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("tiny-reproduction")
    return reproduce(out, studies=tiny_studies())


@pytest.fixture
def studies():
    """The studies of the `tiny` reproduction."""
    return tiny_studies()

"""Shared fixtures: one tiny reproduction, run once per test session."""

from __future__ import annotations

from dataclasses import replace

import pytest

from metrosync.paper.claims_map import CLAIMS_MAP, ClaimsMapGrid
from metrosync.paper.pipeline import reproduce
from metrosync.paper.readings import TODAY, ClaimStatistics, Reading
from metrosync.paper.sigma_map import SIGMA_MAP, SigmaMapGrid
from metrosync.paper.studies import (
    ESTIMATION,
    FIG8_BOTTOM,
    FIG8_TOP,
    FIG10,
    FIG11,
    Z_STUDY,
    Statistics,
    SweepGrid,
    ZGrid,
    reduced,
)

#: Claims-map statistics of seconds (plumbing, not physics), unlike the tiny studies'
#: (today's reading would reuse their points, by design).
TINY_CLAIMS = ClaimStatistics(
    fig11=Statistics(2, 50.0),
    fig8=Statistics(2, 50.0),
    fig10=SweepGrid(ns=(7, 16), bpms=(170.0, 190.0, 210.0), stats=Statistics(2, 50.0)),
    z=ZGrid(theta2=(-0.1, 0.0, 0.1), duration=50.0),
)
#: Today's reading, σ per period, and the published (overturning) drive.
TINY_READINGS = (TODAY, Reading(sigma="period"), Reading(drive="published"))


def tiny_maps():
    """The σ map and the claims map, shrunk to seconds."""
    sigma_map = replace(
        SIGMA_MAP,
        sigmas=(0.75, 1.5),
        tunings=SIGMA_MAP.tunings,
        centres=tuple((t, (c[1], c[4])) for t, c in SIGMA_MAP.centres),
        theory_bpms=(150.0, 185.0, 220.0),
        quick=SigmaMapGrid(ns=(4, 8, 16), half_width=10.0, step=10.0, stats=Statistics(3, 60.0)),
    )
    claims_map = replace(
        CLAIMS_MAP,
        readings=TINY_READINGS,
        quick=ClaimsMapGrid(screen=TINY_CLAIMS, best=TINY_CLAIMS, top=1),
    )
    return [sigma_map, claims_map]


def tiny_studies():
    """Every study, shrunk to seconds of work (shapes and plumbing, not physics)."""
    return [
        reduced(FIG8_TOP, runs=3, duration=60.0),
        reduced(FIG8_BOTTOM, runs=3, duration=60.0),
        reduced(FIG10, ns=(7, 16), bpms=(170.0, 190.0, 210.0), stats=Statistics(3, 60.0)),
        reduced(FIG11, runs=2, duration=60.0),
        reduced(Z_STUDY, duration=60.0, theta2=(-0.1, 0.0, 0.1)),
        reduced(ESTIMATION, c_phi_scan=(1e-6, 1e-5, 1.0, 10.0)),
        *tiny_maps(),
    ]


@pytest.fixture(scope="session")
def tiny(build_once):
    """The tiny reproduction, run once per test run (by one xdist worker for all)."""
    return build_once("tiny-reproduction", lambda out: reproduce(out, studies=tiny_studies()))


@pytest.fixture
def studies():
    """The studies of the `tiny` reproduction."""
    return tiny_studies()


@pytest.fixture
def maps():
    """The σ map and the claims map of the `tiny` reproduction."""
    return tiny_maps()

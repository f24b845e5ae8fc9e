"""Shared fixtures of the `metrosync.show` tests: small recorded runs."""

from __future__ import annotations

import shutil

import pytest

import metrosync
from system_packages import require


@pytest.fixture(scope="session")
def recorded_ds(build_once):
    """N = 7, 20 s, every step recorded with trajectories."""
    return build_once("show-recorded", lambda _: metrosync.simulate(
        7, 192.0, sigma_bpm=0.3, duration=20.0, record_every=1, trajectories=True, seed=3,
    ))  # fmt: skip


@pytest.fixture(scope="session")
def pair_ds(build_once):
    """Two metronomes at different rates, every step recorded: one on each side."""
    return build_once("show-pair", lambda _: metrosync.simulate(
        None, None, frequencies_bpm=[188.0, 196.0], theta0=[0.3, -0.2], theta_dot0=[0.0, 1.0],
        duration=12.0, record_every=1, trajectories=True,
    ))  # fmt: skip


# -- headless Chromium, for the pages' end-to-end tests ------------------------------


@pytest.fixture(scope="session")
def chromium_executable():
    """Debian's chromium; the test skips (naming the package) when it is missing."""
    require("chromium")
    return shutil.which("chromium")


@pytest.fixture
def browser(chromium_executable, tmp_path):
    from cdp import Browser

    profile = tmp_path / "profile"
    profile.mkdir()
    with Browser(chromium_executable, profile) as b:  # closing kills its process group
        yield b


@pytest.fixture(scope="session")
def board_ds(build_once):
    """Pantaleone's two metronomes on his board, 20 s, every step recorded."""
    return build_once("show-board", lambda _: metrosync.simulate(
        2, 208, preset="pantaleone2002", duration=20, trajectories=True, record_every=1,
    ))  # fmt: skip

"""Shared fixtures of the video tests: small videos drawn from known angles."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import synth_video  # noqa: E402


@pytest.fixture(scope="session")
def three_rods(build_once):
    """Three rods in a row, 20 s at a nominal 30 fps with jittered times and 2 % drops."""

    def build(folder):
        path = folder / "three.mp4"
        times, theta, pivots = synth_video.scene(path, n=3, seconds=20, fps=30, jitter=0.3,
                                                 drop=0.02, seed=3)  # fmt: skip
        return path, times, theta, pivots

    return build_once("video-three-rods", build)


@pytest.fixture(scope="session")
def two_with_sound(build_once):
    """Two rods and a click at each pass through the vertical, 15 s, AAC audio."""

    def build(folder):
        path = folder / "sound.mp4"
        times, theta, pivots = synth_video.scene(path, n=2, seconds=15, audio=True, seed=5)
        return path, times, theta, pivots

    return build_once("video-two-with-sound", build)

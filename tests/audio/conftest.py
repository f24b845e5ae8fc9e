"""Shared fixtures of the audio tests: recordings rendered from known tick times."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from metrosync.synthetic import clicks as synth  # noqa: E402


@pytest.fixture(scope="session")
def pair_recording(build_once):
    """Two metronomes, 192 and 188 BPM, the first 4 % out of beat, stereo, 40 s."""

    def build(folder):
        a = synth.metronome_train(192, 40, phase=0.1, asymmetry=0.04)
        b = synth.metronome_train(188, 40, phase=0.6)
        path = folder / "pair.wav"
        synth.write(path, synth.render([a, b], 40, pans=[-0.8, 0.8]))
        return path, [a, b]

    return build_once("audio-pair", build)


@pytest.fixture(scope="session")
def listen_run(build_once):
    """Three simulated metronomes falling into step, their WAV from `write_wav`, and
    the simulated crossing times (audio time = simulated time)."""

    def build(folder):
        import metrosync
        from metrosync.show.recording import RecordedRun
        from metrosync.show.sound import crossing_times, write_wav

        ds = metrosync.simulate(3, 192.0, sigma_bpm=0.75, duration=90.0, record_every=1,
                                trajectories=True, seed=4)  # fmt: skip
        path = folder / "listen.wav"
        write_wav(ds, path)
        return path, crossing_times(RecordedRun.from_dataset(ds))

    return build_once("audio-listen", build)


@pytest.fixture
def rng():
    return np.random.default_rng(2013)

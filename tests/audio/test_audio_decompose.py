"""Onsets of several metronomes, precursors and bounces included, told apart by timing."""

import numpy as np
import pytest
from test_audio_structure import metronome

from metrosync.audio.decompose import decompose


def mixture(bpms, duration=40.0, seed=0):
    rng = np.random.default_rng(seed)
    louds, onsets = [], []
    for i, bpm in enumerate(bpms):
        loud, heard = metronome(bpm, duration, limp=rng.uniform(0, 0.05), seed=10 * seed + i,
                                phase=rng.uniform(0.05, 0.5))  # fmt: skip
        louds.append(loud)
        onsets.append(heard)
    every = np.sort(np.concatenate(onsets))
    apart = np.ones(every.size, dtype=bool)
    apart[1:] = np.diff(every) > 2e-3  # a detector hears onsets 2 ms apart as one
    return louds, every[apart]


@pytest.mark.parametrize(("bpms", "seed"), [([96.4], 1), ([100.0, 131.0], 2),
                                            ([72.0, 118.0, 176.0], 3)])  # fmt: skip
def test_each_metronome_is_found_once_with_its_ticks(bpms, seed):
    louds, onsets = mixture(bpms, seed=seed)
    heard, owner = decompose(onsets)
    assert len(heard) == len(bpms)
    for loud, h in zip(louds, heard, strict=True):  # slowest first, as given
        assert h.followed.timing.bpm == pytest.approx(60 / np.median(np.diff(loud)), rel=0.05)
        found = onsets[h.ticks]
        recall = np.isin(np.round(loud, 6), np.round(found, 6)).mean()
        assert recall > 0.9
        assert np.all(owner[h.ticks] == heard.index(h))


def test_a_limping_metronome_is_not_also_its_half_tempo():
    louds, onsets = mixture([165.7], seed=14)
    heard, _ = decompose(onsets)
    assert [round(h.followed.timing.bpm) for h in heard] == [166]


def test_clutter_alone_is_no_metronome():
    rng = np.random.default_rng(5)
    assert decompose(np.sort(rng.uniform(0, 40, 120)))[0] == []

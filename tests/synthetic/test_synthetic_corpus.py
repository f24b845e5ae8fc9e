"""The benchmark corpus: frozen splits from seeds of their own, each recording drawn
as its spec says, the same on every run."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.synthetic import STRUCTURES
from metrosync.synthetic import corpus as bench


def test_the_splits_draw_from_seeds_of_their_own():
    assert bench.VERSION == "1"
    assert set(bench.SPLITS) == {"dev", "heldout"}
    seen: set[int] = set()
    for spec in bench.SPLITS.values():
        for seeds in (spec.mixed_seeds, spec.single_seeds):
            assert seen.isdisjoint(seeds)
            seen |= set(seeds)


@pytest.mark.parametrize("split", sorted(bench.SPLITS))
def test_a_split_holds_1_to_4_metronomes_alike_and_200_singles_of_every_structure(split):
    listed = bench.entries(split)
    mixed = [e for e in listed if e.kind == "mixed"]
    assert len(mixed) == 120
    assert {n: sum(e.metronomes == n for e in mixed) for n in (1, 2, 3, 4)} == dict.fromkeys(
        (1, 2, 3, 4), 30
    )
    for name in STRUCTURES:
        singles = [e for e in listed if e.kind == "single" and e.structure == name]
        assert len(singles) == 200 and all(e.metronomes == 1 for e in singles)
    assert len({e.name for e in listed}) == len(listed)


def test_each_recording_is_drawn_within_the_spec():
    plans = [e.plan() for e in bench.entries("dev") if e.kind == "mixed"]
    metronomes = [m for p in plans for m in p.metronomes]
    assert {m.structure for m in metronomes} == set(STRUCTURES)
    for m in metronomes:
        assert bench.BPM_RANGE[0] <= m.bpm <= bench.BPM_RANGE[1]
        assert bench.JITTER_RANGE[0] <= m.jitter_s <= bench.JITTER_RANGE[1]
        assert abs(m.drift_bpm_per_min) <= bench.DRIFT_MAX and 0 <= m.limp <= bench.LIMP_MAX
    for p in plans:
        bpms = np.sort([m.bpm for m in p.metronomes])
        assert np.all(np.diff(bpms) >= bench.MIN_BPM_GAP)
        imp = p.impairments
        # every impairment of a phone, in each recording
        assert imp.reverb_rt60 and imp.snr_db and imp.bumps >= 1 and imp.phone_band
        assert imp.compression and imp.resample_from == 48000 and imp.quantize_bits == 16
        assert p.duration == 40.0


def test_a_recording_is_the_same_every_time_and_singles_differ_only_in_structure():
    entry = bench.entries("heldout")[0]
    a, b = entry.recording(), entry.recording()
    np.testing.assert_array_equal(a.samples, b.samples)
    assert a.sample_rate == 44100 and len(a.truth) == entry.metronomes
    singles = [e for e in bench.entries("dev") if e.kind == "single" and e.index == 3]
    plans = [e.plan() for e in singles]
    assert [p.metronomes[0].structure for p in plans] == list(STRUCTURES)
    assert len({(p.metronomes[0].bpm, p.impairments) for p in plans}) == 1
    voices = [p.trains()[0].voice for p in plans]
    assert len({v.resonances for v in voices}) == 1 and len(set(voices)) == 3
    precursor = [e for e in singles if e.structure == "precursor"][0].recording()
    assert precursor.duration == 20.0
    assert np.isfinite(precursor.truth[0].precursors).mean() > 0.5


def test_an_unknown_split_is_named_with_the_known_ones():
    with pytest.raises(ParameterError, match="'dev', 'heldout'"):
        bench.entries("test")

"""Ticks timed against their metronome's learned waveform (`metrosync.audio.waveform`),
on constructed files: a tick in another's ring, where the rise of the envelope is
misplaced, and the timing model's prior choosing between two equally good matches."""

from __future__ import annotations

import numpy as np
import pytest
from test_audio_seek import RATE, _file

from metrosync.audio import detection as det
from metrosync.audio import waveform
from metrosync.synthetic import voices

CLEAN = 0.2 + 0.3 * np.arange(12)


def test_a_tick_in_another_s_ring_is_timed_by_its_waveform_where_its_rise_is_not(tmp_path):
    quiet, loud = voices(2, 1)
    tick, ring = 0.3 * quiet.waveform(RATE), loud.waveform(RATE)
    lags = np.array([2, 4, 6, 9, 12, 16, 20, 25, 30]) * 1e-3  # into the loud one's ring
    starts = 4.0 + 0.3 * np.arange(lags.size)
    crowded = starts + lags
    parts = [(t, tick) for t in np.concatenate([CLEAN, crowded])] + [(s, ring) for s in starts]
    rec = _file(tmp_path, "ring.wav", parts, duration=7.5, seed=1)
    scan = det.scan(rec)
    sound = waveform.learn(rec, scan, CLEAN)
    onsets = det.refine(rec, scan, np.round(crowded * RATE / scan.hop).astype(int)).time
    # the envelope's rise over the ring is up to 3 ms off ...
    assert np.abs(onsets - crowded).max() > 1e-3
    # ... the waveform's best match is not
    timed = waveform.matched(rec, scan, sound, onsets - waveform.REACH, onsets + waveform.REACH)
    assert timed == pytest.approx(crowded, abs=0.1e-3)


@pytest.mark.parametrize("which", [0, 1])
def test_of_two_equal_matches_the_prior_takes_the_one_the_timing_expects(tmp_path, which):
    quiet = voices(2, 1)[0]
    tick = 0.3 * quiet.waveform(RATE)
    t0, apart = 4.0, 2.5e-3
    parts = [(t, tick) for t in CLEAN] + [(t0, tick), (t0 + apart, tick)]
    rec = _file(tmp_path, "twice.wav", parts, duration=5.0, seed=1)
    scan = det.scan(rec)
    sound = waveform.learn(rec, scan, CLEAN)
    lower, upper = np.array([t0 - 4e-3]), np.array([t0 + 6e-3])
    expected = t0 + which * apart
    timed = waveform.matched(rec, scan, sound, lower, upper, np.array([expected]),
                             np.array([0.5e-3]))  # fmt: skip
    assert timed[0] == pytest.approx(expected, abs=0.1e-3)
    # never outside its window
    narrow = waveform.matched(rec, scan, sound, np.array([t0 + 1e-3]), np.array([t0 + 1.5e-3]))
    assert np.isnan(narrow[0]) or t0 + 1e-3 <= narrow[0] <= t0 + 1.5e-3

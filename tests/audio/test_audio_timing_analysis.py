"""The timing model's analysis end to end, on a recording as a phone hears one."""

import warnings

import numpy as np

from metrosync.audio.timing_analysis import analyze_timing
from metrosync.synthetic import Impairments, Voice, make_recording, steady_train
from metrosync.synthetic.score import match


def test_a_metronome_with_a_precursor_is_one_metronome_timed_by_its_loud_impact(tmp_path):
    # the real Neewer's structure: a quieter impact 10-45 ms before most loud ones
    voice = Voice.draw(3, structure="precursor")
    train = steady_train(96.4, 30.0, limp=0.039, jitter_s=0.5e-3, voice=voice, seed=3)
    recording = make_recording([train], impairments=Impairments.phone(bumps=1), seed=3)
    path = recording.write(tmp_path / "one.wav")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a phone's clipping and band limits
        ds = analyze_timing(path)
    assert ds.attrs["metronomes"] == 1
    truth = recording.truth[0].times
    recall, precision, errors = match(truth[truth > 0.1], ds.tick_time.values)
    assert recall >= 0.99 and precision >= 0.99
    assert np.abs(errors).max() < 1e-3
    assert abs(float(ds.bpm[0]) - 96.4) < 0.2

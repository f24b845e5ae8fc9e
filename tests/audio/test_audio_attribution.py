"""Two metronomes told apart, by side or by loudness, and their phase difference."""

from __future__ import annotations

import numpy as np
import pytest
import synth

from metrosync.audio import analyze_audio
from metrosync.audio.attribution import phase_difference


def assigned_right(ds, trains):
    """Share of the attributed ticks that lie within 1 ms of a tick of their metronome."""
    labels = ds.tick_metronome.values
    t = ds.tick_time.values
    right = [np.min(np.abs(trains[m] - x)) <= 1e-3 for x, m in zip(t, labels, strict=True)
             if m >= 0]  # fmt: skip
    return np.mean(right), np.mean(labels >= 0)


def test_stereo_recording_gives_each_metronome_its_ticks(pair_recording):
    path, trains = pair_recording
    ds = analyze_audio(path)
    assert ds.attrs["attribution"] == "stereo"
    right, share = assigned_right(ds, trains)  # metronome 0 is on the left: train 0
    assert right == 1.0 and share > 0.95
    assert float(ds.bpm[0]) == pytest.approx(192, abs=0.01)
    assert float(ds.bpm[1]) == pytest.approx(188, abs=0.01)
    assert float(ds.asymmetry[0]) == pytest.approx(4.0, abs=0.5)
    assert float(ds.asymmetry[1]) < 0.5
    assert "out of beat" in str(ds.beat_verdict.values[0])
    assert str(ds.beat_verdict.values[1]).startswith("in beat")


def test_mono_pair_of_different_loudness_is_told_apart(tmp_path, rng):
    trains = [synth.metronome_train(184, 40, phase=0.0),
              synth.metronome_train(184.6, 40, phase=0.3)]  # fmt: skip
    x = synth.render(trains, 40, gains=[0.6, 0.2])
    x = synth.add_noise(x, 15.0, trains, rng)
    ds = analyze_audio(synth.write(tmp_path / "mono.wav", x))
    assert ds.attrs["attribution"] == "loudness"
    right, share = assigned_right(ds, trains)
    assert right == 1.0 and share > 0.95
    # metronome 1 drifts through 0's beat, from 0.3 of it onwards
    phase = ds.phase_difference.values
    ok = np.isfinite(phase)
    t = ds.tick_time.values[ok]
    beat0 = 60 / 184
    frac = np.mod(t - trains[0][0], beat0) / beat0  # where in 0's beat each tick of 1 falls
    assert np.allclose(np.angle(np.exp(1j * (phase[ok] - 2 * np.pi * frac))), 0, atol=0.02)


def test_equally_loud_mono_pair_is_not_told_apart_and_says_why(tmp_path):
    trains = [synth.metronome_train(184, 30, phase=0.0),
              synth.metronome_train(187, 30, phase=0.3)]  # fmt: skip
    x = synth.render(trains, 30, pitches=[2000.0, 2000.0])  # the same click, as loud
    ds = analyze_audio(synth.write(tmp_path / "same.wav", x))
    assert ds.attrs["attribution"] == "none"
    assert "overlap" in ds.attrs["attribution_note"] or "groups" in ds.attrs["attribution_note"]
    assert "not told apart" in ds.attrs["summary"]
    assert np.all(ds.tick_metronome.values == -1)


def test_phase_difference_is_the_fraction_of_the_beat():
    ref = np.arange(0.0, 10.0, 0.5)
    other = ref[:-1] + 0.125  # a quarter beat later
    assert np.allclose(phase_difference(ref, other, 0.5), np.pi / 2)
    assert np.allclose(phase_difference(ref, ref[1:-1] + 0.375, 0.5), -np.pi / 2)


def test_listen_pair_told_apart_by_side(tmp_path):
    """`write_wav` pans the two metronomes of a simulation to opposite sides."""
    import metrosync
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times, write_wav

    ds = metrosync.simulate(2, 184.0, sigma_bpm=0.75, duration=40.0, record_every=1,
                            trajectories=True, seed=1)  # fmt: skip
    write_wav(ds, tmp_path / "two.wav")
    crossings = crossing_times(RecordedRun.from_dataset(ds))
    out = analyze_audio(tmp_path / "two.wav")
    assert out.attrs["attribution"] == "stereo"
    # metronome 0 of the analysis is the left one: the simulation's metronome 1 (at α = π)
    right, share = assigned_right(out, crossings[::-1])
    assert right == 1.0 and share > 0.95
    assert "locked" in out.attrs["summary"]


def test_loudness_that_drifts_over_time_is_not_taken_for_two_metronomes(tmp_path):
    """Two equal metronomes whose loudness fades together: early loud and late soft ticks
    are two groups of loudness, but not two tick trains."""
    trains = [synth.metronome_train(184, 40, phase=0.0),
              synth.metronome_train(187, 40, phase=0.3)]  # fmt: skip
    x = synth.render(trains, 40, pitches=[2000.0, 2000.0])
    x *= np.where(np.arange(x.shape[0]) < x.shape[0] // 2, 1.0, 0.1)[:, None]
    out = analyze_audio(synth.write(tmp_path / "fade.wav", x))
    assert out.attrs["attribution"] == "none"

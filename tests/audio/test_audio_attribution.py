"""Metronomes on one recording told apart, by their sound or their tempo, and their phase."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.audio import analyze_audio
from metrosync.audio.attribution import phase_difference
from metrosync.synthetic import clicks


def assigned_right(ds, trains):
    """Share of the attributed ticks that lie within 1 ms of a tick of their metronome,
    and the share attributed; the analysis's metronome m is matched to the train that
    holds most of its ticks (one train each)."""
    labels = ds.tick_metronome.values
    t = ds.tick_time.values
    owner = {}
    for m in range(ds.sizes["metronome"]):
        near = [np.sum(np.min(np.abs(np.subtract.outer(t[labels == m], tr)), axis=1) <= 1e-3)
                for tr in trains]  # fmt: skip
        owner[m] = int(np.argmax(near))
    assert sorted(owner.values()) == list(range(len(trains)))
    trains = [trains[owner[m]] for m in range(len(trains))]
    right = [np.min(np.abs(trains[m] - x)) <= 1e-3 for x, m in zip(t, labels, strict=True)
             if m >= 0]  # fmt: skip
    return np.mean(right), np.mean(labels >= 0)


def test_stereo_recording_gives_each_metronome_its_ticks(pair_recording):
    path, trains = pair_recording
    ds = analyze_audio(path)
    assert ds.attrs["attribution"] == "sound"
    right, share = assigned_right(ds, trains)  # equally loud: 0 is the one with more ticks
    assert right == 1.0 and share > 0.95
    assert float(ds.bpm[0]) == pytest.approx(192, abs=0.01)
    assert float(ds.bpm[1]) == pytest.approx(188, abs=0.01)
    assert float(ds.asymmetry[0]) == pytest.approx(4.0, abs=0.5)
    assert float(ds.asymmetry[1]) < 0.5
    assert "out of beat" in str(ds.beat_verdict.values[0])
    assert str(ds.beat_verdict.values[1]).startswith("in beat")


def test_mono_pair_of_different_loudness_is_told_apart(tmp_path, rng):
    trains = [clicks.metronome_train(184, 40, phase=0.0),
              clicks.metronome_train(184.6, 40, phase=0.3)]  # fmt: skip
    x = clicks.render(trains, 40, gains=[0.6, 0.2])
    x = clicks.add_noise(x, 15.0, trains, rng)
    ds = analyze_audio(clicks.write(tmp_path / "mono.wav", x))
    assert ds.attrs["attribution"] == "sound"  # metronome 0 is the louder
    right, share = assigned_right(ds, trains)
    assert right == 1.0 and share > 0.95
    # metronome 1 drifts through 0's beat, from 0.3 of it onwards
    phase = ds.phase_difference.values
    ok = np.isfinite(phase)
    t = ds.tick_time.values[ok]
    beat0 = 60 / 184
    frac = np.mod(t - trains[0][0], beat0) / beat0  # where in 0's beat each tick of 1 falls
    assert np.allclose(np.angle(np.exp(1j * (phase[ok] - 2 * np.pi * frac))), 0, atol=0.02)


def test_the_same_click_at_two_tempi_is_told_apart_by_tempo(tmp_path):
    trains = [clicks.metronome_train(184, 30, phase=0.0),
              clicks.metronome_train(187, 30, phase=0.3)]  # fmt: skip
    x = clicks.render(trains, 30, pitches=[2000.0, 2000.0])  # the same click, as loud
    ds = analyze_audio(clicks.write(tmp_path / "same.wav", x))
    assert ds.attrs["attribution"] == "tempo"
    order = np.argsort(ds.bpm.values)
    assert ds.bpm.values[order] == pytest.approx([184, 187], abs=0.1)
    right, share = assigned_right(ds, [trains[i] for i in np.argsort(order)])
    assert right == 1.0 and share > 0.9


def test_the_same_click_at_one_tempo_half_a_beat_apart_is_two(tmp_path):
    """Two identical metronomes locked half a beat apart: one metronome at twice the
    tempo (368 BPM) is beyond any metronome, so they are two, each its own train."""
    a = clicks.metronome_train(184, 30, phase=0.0)
    b = clicks.metronome_train(184, 30, phase=0.5)
    x = clicks.render([a, b], 30, pitches=[2000.0, 2000.0])
    ds = analyze_audio(clicks.write(tmp_path / "locked.wav", x))
    assert ds.attrs["metronomes"] == 2 and ds.attrs["attribution"] == "tempo"
    right, share = assigned_right(ds, [a, b])
    assert right == 1.0 and share > 0.98


def test_identical_metronomes_ticking_together_are_not_told_apart_and_say_so(tmp_path):
    """Ticks that fall together sound as one: told that two metronomes sound, the
    analysis says it told one apart and reports what needs no identities."""
    a = clicks.metronome_train(184, 30, phase=0.0)
    b = a + 0.5e-3
    x = clicks.render([a, b], 30, pitches=[2000.0, 2000.0])
    ds = analyze_audio(clicks.write(tmp_path / "together.wav", x), metronomes=2)
    assert ds.attrs["attribution"] == "none"
    assert "1 metronome told apart, 2 expected" in ds.attrs["attribution_note"]
    assert (
        "not told apart" in ds.attrs["summary"]
        and "acoustic order parameter" in ds.attrs["summary"]
    )
    assert np.nanmean(ds.r_acoustic.values) > 0.99
    assert "not told apart" in ds.attrs["summary"]


def test_phase_difference_is_the_fraction_of_the_beat():
    ref = np.arange(0.0, 10.0, 0.5)
    other = ref[:-1] + 0.125  # a quarter beat later
    assert np.allclose(phase_difference(ref, other, 0.5), np.pi / 2)
    assert np.allclose(phase_difference(ref, ref[1:-1] + 0.375, 0.5), -np.pi / 2)


def test_listen_pair_told_apart(tmp_path):
    """`write_wav` gives the two metronomes of a simulation their own pitch and side."""
    import metrosync
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times, write_wav

    ds = metrosync.simulate(2, 184.0, sigma_bpm=0.75, duration=40.0, record_every=1,
                            trajectories=True, seed=1)  # fmt: skip
    write_wav(ds, tmp_path / "two.wav")
    crossings = crossing_times(RecordedRun.from_dataset(ds))
    out = analyze_audio(tmp_path / "two.wav")
    assert out.attrs["attribution"] == "sound"
    right, share = assigned_right(out, crossings)
    assert right == 1.0 and share > 0.95
    assert "locked" in out.attrs["summary"]


def test_loudness_that_drifts_over_time_is_not_taken_for_more_metronomes(tmp_path):
    """Two equal metronomes whose loudness fades together: early loud and late soft ticks
    differ in loudness, but they are two metronomes, told apart by tempo."""
    trains = [clicks.metronome_train(184, 40, phase=0.0),
              clicks.metronome_train(187, 40, phase=0.3)]  # fmt: skip
    x = clicks.render(trains, 40, pitches=[2000.0, 2000.0])
    x *= np.where(np.arange(x.shape[0]) < x.shape[0] // 2, 1.0, 0.1)[:, None]
    out = analyze_audio(clicks.write(tmp_path / "fade.wav", x))
    assert out.attrs["metronomes"] == 2 and out.attrs["attribution"] == "tempo"

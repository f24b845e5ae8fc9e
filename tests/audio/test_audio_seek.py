"""Beats no onset was detected at, sought by the curve and by the metronome's sound
(`metrosync.audio.seek`): the sound matched on constructed files, and a quiet
metronome in a loud one's rings heard whole."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import soundfile as sf

from metrosync import synthetic
from metrosync.audio import detection as det
from metrosync.audio import seek, waveform
from metrosync.audio.analysis import analyze_audio
from metrosync.audio.reader import open_recording
from metrosync.synthetic import voices
from metrosync.synthetic.score import scores

RATE = 44100


def _file(tmp_path, name, parts, duration=4.0, seed=0):
    """A mono WAV of the waveforms ``parts`` (time s, waveform), summed, over a faint
    noise floor."""
    rng = np.random.default_rng(seed)
    x = rng.normal(0, 1e-4, round(duration * RATE))
    for t, w in parts:
        i = round(t * RATE)
        x[i : i + w.size] += w[: x.size - i]
    path = tmp_path / name
    sf.write(path, x.astype(np.float32), RATE)
    return open_recording(path)


def test_a_tick_in_another_s_ring_is_timed_by_its_sound(tmp_path):
    quiet, loud = voices(2, 4)
    tick = 0.3 * quiet.waveform(RATE)
    ring = loud.waveform(RATE)
    clean_times = 0.2 + 0.3 * np.arange(12)
    clean = _file(tmp_path, "clean.wav", [(t, tick) for t in clean_times])
    scan = det.scan(clean)
    sound = waveform.learn(clean, scan, clean_times)
    assert sound is not None and np.linalg.norm(sound) == pytest.approx(1.0)
    # the tick 12 ms into the loud one's ring, and a window in the ring alone
    t0 = 1.0123
    mixed = _file(tmp_path, "mixed.wav", [(1.0, ring), (t0, tick), (2.0, ring)], seed=1)
    score, at = seek._match(mixed, det.scan(mixed), sound, np.array([t0 + 1e-3, 2.0123]), 2e-3)
    assert at[0] == pytest.approx(t0, abs=0.2e-3)
    assert score[0] > 0.5 > score[1]


def test_too_few_clean_ticks_learn_no_sound(tmp_path):
    quiet = voices(1, 4)[0]
    times = 0.2 + 0.3 * np.arange(waveform.MIN_SOUND_TICKS - 1)
    rec = _file(tmp_path, "few.wav", [(t, quiet.waveform(RATE)) for t in times])
    assert waveform.learn(rec, det.scan(rec), times) is None


def _quiet_among_loud(tmp_path, seed):
    """A quiet metronome and two loud ones whose rings cover many of its ticks."""
    rng = np.random.default_rng([49, seed])
    sounds = voices(3, seed)
    bpms, gains = [97.0, 131.0, 176.0], [0.6, 1.0, 1.0]
    trains = [
        synthetic.steady_train(
            b,
            40.0,
            phase=rng.uniform(),
            voice=sounds[i],
            gain=gains[i],
            seed=10 * seed + i,
            jitter_s=0.5e-3,
        )  # fmt: skip
        for i, b in enumerate(bpms)
    ]
    rec = synthetic.make_recording(trains, impairments=synthetic.Impairments.phone(), seed=seed)
    path = rec.write(tmp_path / f"q{seed}.wav")
    return path, [t.times for t in rec.truth]


@pytest.mark.slow
def test_a_quiet_metronome_in_loud_ones_rings_is_heard_by_its_sound(tmp_path, monkeypatch):
    """Over five recordings: in four at least, every hearable tick of the quiet one,
    each within 1 ms, none of the others' (the fifth may be lost otherwise: a quiet
    metronome whose tocks go undetected can be followed at half its tempo); without
    the sound's route (the curve's alone) fewer of its ticks in all."""
    whole, heard, heard_without = 0, 0.0, 0.0
    for seed in range(1, 6):
        path, truth = _quiet_among_loud(tmp_path, seed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = analyze_audio(path)
            with monkeypatch.context() as m:
                m.setattr(seek, "_by_sound", lambda recording, *_: (
                    det.Ticks.none(recording.channels), np.zeros(0, dtype=np.int64)))  # fmt: skip
                without = analyze_audio(path)
        recall, precision, timing, bpm = scores(ds, truth)[0]
        whole += recall >= 0.99 and precision >= 0.98 and timing <= 1e-3 and bpm <= 0.1
        heard += recall
        heard_without += scores(without, truth)[0][0]
    assert whole >= 4
    assert heard_without < heard - 0.05

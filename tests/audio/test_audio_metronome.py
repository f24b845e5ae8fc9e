"""One metronome: tempo with its uncertainty, jitter, and the tick/tock asymmetry."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.audio import analyze_audio
from metrosync.audio.metronome import beat_statistics
from metrosync.synthetic import clicks


@pytest.mark.parametrize("asymmetry", [0.0, 0.012, 0.04, 0.10])
@pytest.mark.parametrize("noisy", [False, True], ids=["clean", "noise+reverb 10 dB"])
def test_asymmetry_from_the_sound_within_half_a_percentage_point(tmp_path, rng, asymmetry, noisy):
    train = clicks.metronome_train(152, 40, phase=0.2, asymmetry=asymmetry, jitter=5e-4, rng=rng)
    x = clicks.render([train], 40)
    if noisy:
        x = clicks.add_noise(clicks.add_reverb(x, rng), 10.0, [train], rng)
    ds = analyze_audio(clicks.write(tmp_path / "m.wav", x))
    assert ds.attrs["metronomes"] == 1
    assert abs(float(ds.asymmetry[0]) - 100 * asymmetry) <= 0.5
    if asymmetry >= 0.01:
        # the first interval of the train is the long one: tick→tock
        assert str(ds.long_beat.values[0]) == "tick→tock"
    assert abs(float(ds.bpm[0]) - 152) <= max(4 * float(ds.bpm_error[0]), 0.01)
    assert float(ds.jitter[0]) == pytest.approx(5e-4, rel=0.3)


def test_words_a_musician_would_use(rng):
    def verdict(asymmetry):
        t = clicks.metronome_train(120, 60, asymmetry=asymmetry, jitter=2e-4, rng=rng)
        return beat_statistics(t, 0.5).verdict()

    assert verdict(0.0).startswith("in beat")
    assert verdict(0.03).startswith("slightly out of beat")
    assert "limps audibly" in verdict(0.08) and verdict(0.08).startswith("out of beat")


def test_tempo_uncertainty_covers_the_truth(rng):
    """Over many recordings with period jitter, |BPM − true| < 2 SE about 95 % of the time."""
    inside = 0
    for _ in range(200):
        t = clicks.metronome_train(100, 60, jitter=2e-3, rng=rng)
        s = beat_statistics(t, 0.6)
        inside += abs(s.bpm - 100) < 2 * s.bpm_error
    assert 0.88 <= inside / 200 <= 1.0


def test_missed_ticks_keep_tick_and_tock_apart(rng):
    t = clicks.metronome_train(120, 60, asymmetry=0.05)
    kept = np.delete(t, [7, 30, 31, 64])  # a lone miss and two in a row
    s = beat_statistics(kept, 0.5)
    assert s.missed == 4
    assert s.asymmetry == pytest.approx(5.0, abs=1e-6)
    assert s.bpm == pytest.approx(120, rel=1e-9)


def test_the_louder_kind_of_tick_is_called_the_tick(rng):
    t = clicks.metronome_train(120, 30, asymmetry=0.05)
    loud = np.where(np.arange(t.size) % 2 == 1, -10.0, -16.0)  # the 2nd, 4th, ... louder
    s = beat_statistics(t, 0.5, loud)
    assert s.tick_is_louder and not s.is_tock[1] and s.is_tock[0]
    assert s.long_beat == "tock→tick"


def test_asymmetry_of_a_tick_off_the_vertical():
    """Ticks where a sinusoidal swing passes θ = ε give the asymmetry of the formula."""
    from metrosync.audio.metronome import asymmetry_from_offset

    amplitude, offset, omega = 0.7, 0.03, np.pi * 150 / 60
    rising = np.arcsin(offset / amplitude) / omega + 2 * np.pi / omega * np.arange(60)
    falling = (np.pi - np.arcsin(offset / amplitude)) / omega + 2 * np.pi / omega * np.arange(60)
    s = beat_statistics(np.sort(np.concatenate([rising, falling])), 0.4)
    assert s.asymmetry == pytest.approx(asymmetry_from_offset(offset, amplitude), rel=1e-9)
    assert asymmetry_from_offset(offset, amplitude) == pytest.approx(5.46, abs=0.01)


def test_simulated_escapement_offset_is_heard_as_its_asymmetry(tmp_path):
    """The model's escapement offset, rendered by `write_wav` (a click where each kick
    is) and analysed: the limp heard is the one the offset makes (measured 4.94 % for
    4.98 % expected)."""
    import metrosync
    from metrosync.audio.metronome import asymmetry_from_offset
    from metrosync.show.sound import write_wav

    offset = 0.03
    ds = metrosync.simulate(1, 150.0, duration=60.0, record_every=1, trajectories=True,
                            changes={"escapement_offset": offset})  # fmt: skip
    write_wav(ds, tmp_path / "offset.wav", start=20.0)
    amplitude = float(np.abs(ds.theta.isel(run=0).values[-2000:]).max())
    out = analyze_audio(tmp_path / "offset.wav")
    expected = asymmetry_from_offset(offset, amplitude)
    assert abs(float(out.asymmetry[0]) - expected) <= 0.5


def test_a_train_with_no_single_beat_of_one_kind_has_no_asymmetry_error():
    """Every other beat missed: each gap spans two beats but one, so one kind of single
    beat is never heard; the statistics say so instead of dividing by zero."""
    times = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 4.5, 6.5, 8.5, 10.5])
    stats = beat_statistics(times, 0.5)
    assert np.isnan(stats.asymmetry_error) and np.isfinite(stats.bpm)

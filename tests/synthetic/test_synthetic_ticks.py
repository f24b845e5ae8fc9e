"""Realistic ticks: the structure of real ones, measured from the synthesised waveform."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from metrosync.errors import ParameterError
from metrosync.synthetic.ticks import LOUDNESS_WINDOW, REFERENCE_RMS, Voice, voices

RATE = 44100
SEEDS = range(16)


def impacts(wave):
    """Times (samples) and heights, relative to the first, of the impacts in ``wave``:
    the peaks, at least 3 ms apart and above 10 % of the highest, of the envelope above
    12 kHz, where the strikes sound and the resonances (≤ 9 kHz) do not."""
    sos = signal.butter(8, 12000, "highpass", fs=RATE, output="sos")
    high = np.abs(signal.sosfiltfilt(sos, np.pad(wave, 300))[300:-300])
    peaks, _ = signal.find_peaks(high, distance=int(0.003 * RATE), height=0.1 * high.max())
    return peaks, high[peaks] / high[peaks[0]]


def decay_time(wave, start, stop):
    """Time for the 2 ms RMS envelope to fall by 60 dB, from its slope in [start, stop] s."""
    width = int(0.002 * RATE)
    env = np.sqrt(np.convolve(wave**2, np.ones(width) / width, mode="same"))
    k = np.arange(int(start * RATE), min(int(stop * RATE), wave.size - width))
    slope = np.polyfit(k / RATE, 20 * np.log10(env[k]), 1)[0]
    return -60.0 / slope


def spectrum_db(wave):
    """Power spectrum (dB, 0 dB = the wave's mean power) in 1/3-octave bands 300–8000 Hz,
    floored 30 dB below its loudest band: the shape one hears, not the noise between
    resonances."""
    f, p = signal.welch(np.pad(wave, (0, 8192 - wave.size)), fs=RATE, nperseg=1024)
    edges = 300 * 2 ** (np.arange(0, 15) / 3)
    bands = [p[(f >= lo) & (f < hi)].mean() for lo, hi in zip(edges[:-1], edges[1:], strict=True)]
    level = 10 * np.log10(np.array(bands) / np.mean(wave**2))
    return np.maximum(level, level.max() - 30)


def loudness_db(wave):
    return 10 * np.log10(np.mean(wave[: int(LOUDNESS_WINDOW * RATE)] ** 2))


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("tock", [False, True])
def test_secondary_impacts_come_15_to_35_ms_later_at_40_to_70_percent(seed, tock):
    voice = Voice.draw(seed)
    wave = voice.waveform(RATE, tock=tock)
    lags, heights = impacts(wave)
    assert lags[0] < 0.0005 * RATE  # the main impact opens the waveform
    delays = (lags[1:] - lags[0]) / RATE
    assert 1 <= delays.size <= 3
    assert np.all((delays >= 0.015 - 1 / RATE) & (delays <= 0.035 + 1 / RATE))
    np.testing.assert_allclose(delays, voice.sub_delays, atol=1 / RATE)
    ratios = heights[1:]
    assert np.all((ratios > 0.4 - 0.01) & (ratios < 0.7 + 0.01))
    np.testing.assert_allclose(ratios, voice.sub_gains, rtol=0.02)


def test_as_heard_secondary_impacts_peak_at_40_to_70_percent_of_the_main():
    """The waveform's peak at a secondary impact also holds the ring of the earlier ones,
    in or out of phase: most such peaks still lie in 40–70 % of the main impact's."""
    heard = []
    for seed in range(100):
        voice = Voice.draw(seed)
        for tock in (False, True):
            wave = voice.waveform(RATE, tock=tock)
            main = np.abs(wave[: int(0.002 * RATE)]).max()
            for delay in voice.sub_delays:
                k = int(round(delay * RATE))
                heard.append(np.abs(wave[k : k + int(0.002 * RATE)]).max() / main)
    low, median, high = np.percentile(heard, [5, 50, 95])
    assert 0.45 < median < 0.65
    assert 0.3 < low and high < 0.85


@pytest.mark.parametrize("seed", SEEDS)
def test_a_tick_rings_for_about_80_ms(seed):
    voice = Voice.draw(seed)
    wave = voice.waveform(RATE)
    last = voice.sub_delays[-1]
    measured = decay_time(wave, last + 0.02, last + 0.06)
    assert measured == pytest.approx(voice.ring, rel=0.1)
    assert 0.06 < measured < 0.1
    # It starts at once: 0 at the onset, above a third of its peak within 0.3 ms.
    assert wave[0] == 0.0
    assert np.abs(wave[: int(0.0003 * RATE)]).max() > np.abs(wave).max() / 3


@pytest.mark.parametrize("seed", SEEDS)
def test_tick_and_tock_differ_in_sound_and_loudness(seed):
    voice = Voice.draw(seed)
    tick, tock = voice.waveform(RATE), voice.waveform(RATE, tock=True)
    louder = loudness_db(tick) - loudness_db(tock)
    assert louder == pytest.approx(-20 * np.log10(voice.tock_gain), abs=0.01)
    assert 1.4 < louder < 4.5  # tock_gain 0.6–0.85

    # The late ring is the main resonance; the tock's is moved by tock_shift.
    def ring_peak(w):
        tail = w[int((voice.sub_delays[-1] + 0.01) * RATE) :]
        power = np.abs(np.fft.rfft(tail * np.hanning(tail.size), 1 << 16)) ** 2
        return np.fft.rfftfreq(1 << 16, 1 / RATE)[np.argmax(power)]

    assert ring_peak(tick) == pytest.approx(voice.resonances[0], rel=0.01)
    assert ring_peak(tock) == pytest.approx(voice.resonances[0] * voice.tock_shift, rel=0.01)
    assert abs(ring_peak(tock) / ring_peak(tick) - 1) > 0.05
    assert np.mean(np.abs(spectrum_db(tick) - spectrum_db(tock))) > 1.0


@pytest.mark.parametrize("seed", range(6))
def test_metronomes_of_different_makes_differ_in_spectrum_more_than_in_loudness(seed):
    group = voices(4, seed)
    for i in range(4):
        for j in range(i + 1, 4):
            a, b = group[i].waveform(RATE), group[j].waveform(RATE)
            spectral = np.mean(np.abs(spectrum_db(a) - spectrum_db(b)))
            loudness = abs(loudness_db(a) - loudness_db(b))
            assert loudness < 1.5
            assert spectral > 5.0
            assert spectral > 4 * loudness


def test_loudness_is_level_times_the_reference():
    voice = Voice.draw(4)
    assert np.sqrt(np.mean(voice.waveform(RATE)[: int(LOUDNESS_WINDOW * RATE)] ** 2)) == (
        pytest.approx(REFERENCE_RMS * voice.level)
    )
    # Every drawn tick stays below full scale.
    assert max(np.abs(Voice.draw(s).waveform(RATE)).max() for s in range(50)) < 1.0


def test_a_voice_sounds_the_same_every_time_and_seeds_differ():
    assert Voice.draw(7) == Voice.draw(7)
    np.testing.assert_array_equal(Voice.draw(7).waveform(RATE), Voice.draw(7).waveform(RATE))
    assert Voice.draw(7) != Voice.draw(8)
    assert voices(3, 1) == voices(3, 1)
    for rate in (8000, 48000):  # resonances above Nyquist are left out
        wave = Voice.draw(2).waveform(rate)
        assert np.all(np.isfinite(wave)) and wave.size == round(Voice.draw(2).duration * rate) + 1


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: Voice.draw(-1), "`seed`"),
        (lambda: voices(0), "`n`"),
        (lambda: Voice.draw(0).waveform(100), "`sample_rate`"),
        (lambda: Voice((1000.0,), (1.0,), (1.0,), 0.08, (0.02,), (0.5,), 1.0, 0.7), "`tock_shift`"),
        (
            lambda: Voice((1000.0,), (1.0,), (1.0,), 0.08, (0.03, 0.02), (0.5, 0.5), 1.1, 0.7),
            "`sub_delays`",
        ),  # fmt: skip
        (
            lambda: Voice((1000.0,), (1.0, 2.0), (1.0,), 0.08, (0.02,), (0.5,), 1.1, 0.7),
            "`resonances`",
        ),  # fmt: skip
    ],
)
def test_bad_voices_name_the_argument(call, name):
    with pytest.raises(ParameterError, match=name):
        call()


def test_metronomes_of_one_make_sound_alike_but_not_the_same():
    def distance(a, b):
        return np.mean(np.abs(spectrum_db(a.waveform(RATE)) - spectrum_db(b.waveform(RATE))))

    near, far = [], []
    for seed in range(4):
        group = voices(3, seed)
        for i, make in enumerate(group):
            others = min(distance(make, v) for j, v in enumerate(group) if j != i)
            far.append(others)
            for k in range(3):
                sibling = make.sibling(k)
                assert sibling != make and sibling.sibling(0) != sibling
                near.append(distance(make, sibling))
                assert near[-1] < others  # closer to its make than to any other make
                loud = loudness_db(sibling.waveform(RATE)) - loudness_db(make.waveform(RATE))
                assert abs(loud) < 2.0
                np.testing.assert_allclose(sibling.resonances, make.resonances, rtol=0.08)
    assert np.median(near) < np.median(far) / 3
    assert min(near) > 0.1
    assert voices(1)[0].sibling(3) == voices(1)[0].sibling(3)
    with pytest.raises(ParameterError, match="`spread`"):
        Voice.draw(0).sibling(1, spread=0.5)

"""The test corpus itself: its truth is where the sound is, and each impairment does
what it says."""

from __future__ import annotations

import numpy as np
import pytest
from corpus import (
    Impairments,
    Microphone,
    TickTrain,
    make_recording,
    simulated_trains,
    steady_train,
)
from scipy import signal

from metrosync.errors import ParameterError
from metrosync.show.ticks import Voice, voices


def first_rise(x, t, rate, *, fraction=0.05, window=0.005):
    """Time (s) of the first sample in [t − window, t + window] where |x| exceeds
    ``fraction`` of the largest |x| in that window."""
    lo, hi = max(int((t - window) * rate), 0), int((t + window) * rate)
    seg = np.abs(x[lo:hi])
    return (lo + np.flatnonzero(seg > fraction * seg.max())[0]) / rate


def isolated(trains_truth, gap=0.15):
    """(train, index) of the ticks with no tick of any train in the ``gap`` s before
    them or within 5 ms after."""
    times = np.concatenate([t.times for t in trains_truth])
    out = []
    for i, truth in enumerate(trains_truth):
        for k, t in enumerate(truth.times):
            d = times - t
            if not np.any(((d < 0) & (d > -gap)) | ((d > 0) & (d < 0.005))):
                out.append((i, k))
    return out


@pytest.fixture(scope="module")
def four():
    """Four metronomes of distinct voices at 96, 100, 104 and 184 BPM, 20 s."""
    v = voices(4, seed=1)
    return [
        steady_train(bpm, 20.0, phase=phase, limp=limp, voice=v[i], seed=i)
        for i, (bpm, phase, limp) in enumerate(
            [(96, 0.0, 0.0), (100, 0.3, 0.02), (104, 0.5, 0.0), (184, 0.7, 0.05)]
        )
    ]


@pytest.mark.parametrize("rate", [44100, 48000])
def test_truth_is_where_the_energy_rises_in_the_clean_signal(four, rate):
    rec = make_recording(four, sample_rate=rate)
    assert rec.samples.dtype == np.float32 and rec.samples.ndim == 1
    assert rec.sample_rate == rate
    checked = isolated(rec.truth)
    assert len(checked) > 40
    errors = [first_rise(rec.samples, rec.truth[i].times[k], rate) - rec.truth[i].times[k]
              for i, k in checked]  # fmt: skip
    assert np.max(np.abs(errors)) <= 1e-4  # the attack: 0.08 ms
    # Every tick is in the truth: as many ticks as the trains hold, tick and tock alternating.
    for train, truth in zip(four, rec.truth, strict=True):
        np.testing.assert_array_equal(truth.times, train.times)
        assert np.all(truth.is_tock[1:] != truth.is_tock[:-1])


def test_each_microphone_hears_each_metronome_at_its_delay_and_gain(four):
    rec = make_recording(four, microphones=3, seed=5)
    assert rec.samples.shape == (int(round(rec.duration * 44100)), 3)
    for truth in rec.truth:
        assert truth.gains.shape == truth.delays.shape == (3,)
        assert truth.gains.max() == pytest.approx(1.0)
        assert 0.0005 < truth.delays.min() and truth.delays.max() < 0.004  # 0.2–1.4 m
    checked = isolated(rec.truth, gap=0.16)
    for c in range(3):
        errors = [first_rise(rec.samples[:, c], rec.truth[i].arrivals(c)[k], 44100)
                  - rec.truth[i].arrivals(c)[k] for i, k in checked]  # fmt: skip
        assert np.max(np.abs(errors)) <= 1e-4


def test_given_microphones_set_gains_and_delays():
    train = steady_train(120, 3.0, voice=Voice.draw(3))
    mics = [Microphone((1.0,), (0.0,)), Microphone((0.25,), (0.01,))]
    rec = make_recording([train], microphones=mics)
    x = rec.samples
    lag = np.argmax(signal.correlate(x[:, 1], x[:, 0], mode="full", method="fft")) - (len(x) - 1)
    assert lag == 441
    assert np.abs(x[:, 1]).max() / np.abs(x[:, 0]).max() == pytest.approx(0.25, rel=1e-3)
    np.testing.assert_allclose(rec.truth[0].arrivals(1), rec.truth[0].times + 0.01)


def test_the_same_seed_gives_the_same_recording(four):
    a = make_recording(four, impairments=Impairments.phone(), seed=2)
    b = make_recording(four, impairments=Impairments.phone(), seed=2)
    c = make_recording(four, impairments=Impairments.phone(), seed=3)
    np.testing.assert_array_equal(a.samples, b.samples)
    assert not np.array_equal(a.samples, c.samples)


def test_simulated_trains_tick_at_the_crossings_upward_and_tock_downward():
    import metrosync
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times

    ds = metrosync.simulate(2, 184.0, sigma_bpm=1.0, duration=6.0, record_every=1,
                            trajectories=True, seed=1)  # fmt: skip
    trains = simulated_trains(ds, start=1.0)
    run = RecordedRun.from_dataset(ds)
    for i, (train, times) in enumerate(zip(trains, crossing_times(run), strict=True)):
        times = times[times >= 1.0]
        np.testing.assert_allclose(train.times, times - 1.0)
        up = run.theta_dot_at(times)[:, i] > 0
        np.testing.assert_array_equal(train.is_tock, ~up)
        assert np.all(train.is_tock[1:] != train.is_tock[:-1])
    assert trains[0].voice != trains[1].voice
    rec = make_recording(trains, impairments=Impairments.phone(), seed=1)
    assert rec.duration == pytest.approx(trains[0].times.max() + 1.0, abs=0.6)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: steady_train(0, 10), "`bpm`"),
        (lambda: steady_train(100, 10, phase=1.2), "`phase`"),
        (lambda: steady_train(100, 10, limp=0.7), "`limp`"),
        (lambda: TickTrain([0.0, 0.5], [False], Voice.draw(0)), "`is_tock`"),
        (lambda: TickTrain([0.5, 0.1], [False, True], Voice.draw(0)), "`times`"),
        (lambda: Impairments(reverb_rt60=10.0), "`reverb_rt60`"),
        (lambda: Impairments(clipping=1.5), "`clipping`"),
        (lambda: Impairments(noise="blue"), "`noise`"),
        (lambda: make_recording([]), "`trains`"),
        (lambda: make_recording([steady_train(100, 2)], microphones=0), "`microphones`"),
        (lambda: make_recording([steady_train(100, 2)], duration=1.0), "`duration`"),
        (lambda: make_recording([steady_train(100, 2)], sample_rate=100), "`sample_rate`"),
    ],
)
def test_bad_arguments_are_named(call, name):
    with pytest.raises(ParameterError, match=name):
        call()

"""Synthetic recordings themselves: their truth is where the sound is, and each
impairment does what it says."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from metrosync.errors import ParameterError
from metrosync.synthetic import (
    Impairments,
    Microphone,
    TickTrain,
    Voice,
    make_recording,
    random_trains,
    simulated_trains,
    steady_train,
    voices,
)


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


def test_microphones_split_into_phones_started_at_different_times(four):
    rec = make_recording(four, microphones=2, seed=5)
    files = rec.files([0.0, 1.25])
    assert [f.channels for f in files] == [1, 1]
    assert files[1].samples.size == rec.samples.shape[0] - round(1.25 * 44100)
    np.testing.assert_array_equal(files[1].samples, rec.samples[round(1.25 * 44100) :, 1])
    for i, truth in enumerate(files[1].truth):
        want = rec.truth[i].arrivals(1) - 1.25
        np.testing.assert_allclose(truth.times, want[want >= 0])
        assert truth.gains[0] == rec.truth[i].gains[1]
    # (The file may open in the ring of a tick struck before it started: from 0.2 s.)
    late = [(i, k) for i, k in isolated(files[1].truth) if files[1].truth[i].times[k] > 0.2]
    errors = [first_rise(files[1].samples, files[1].truth[i].times[k], 44100)
              - files[1].truth[i].times[k] for i, k in late]  # fmt: skip
    assert len(errors) > 20 and np.max(np.abs(errors)) <= 1e-4
    with pytest.raises(ParameterError, match="`starts`"):
        rec.files([0.0])


def test_phones_whose_clocks_run_fast_stretch_their_files_and_truth():
    trains = random_trains(2, 40.0, seed=3)
    rec = make_recording(trains, microphones=2, seed=4)
    same = rec.files([0.5, 0.5])[1]
    fast = rec.files([0.5, 0.5], clock_ppm=[0.0, 50.0])[1]
    assert fast.samples.size == round(same.samples.size * (1 + 50e-6))
    for a, b in zip(same.truth, fast.truth, strict=True):
        np.testing.assert_allclose(b.times, a.times * (1 + 50e-6))
    assert fast.truth[0].times[-1] - same.truth[0].times[-1] > 0.0018  # 2 ms at the end
    late = [(i, k) for i, k in isolated(fast.truth) if fast.truth[i].times[k] > 0.2]
    errors = [first_rise(fast.samples, fast.truth[i].times[k], 44100)
              - fast.truth[i].times[k] for i, k in late]  # fmt: skip
    assert len(errors) > 20 and np.max(np.abs(errors)) <= 1e-4
    with pytest.raises(ParameterError, match="`clock_ppm`"):
        rec.files(clock_ppm=[0.0])


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
        (lambda: make_recording([steady_train(100, 2)], seed=-1), "`seed`"),
        (lambda: make_recording([steady_train(100, 2)], impairments=True), "`impairments`"),
        (lambda: steady_train(100, 2, seed=1.5), "`seed`"),
        (lambda: random_trains(3, 10, bpm_range=(100, 101), min_bpm_gap=2), "`bpm_range`"),
        (lambda: random_trains(9, 10), "`n`"),
        (lambda: steady_train(100, 2, bounce_jitter_s=0.1), "`bounce_jitter_s`"),
    ],
)
def test_bad_arguments_are_named(call, name):
    with pytest.raises(ParameterError, match=name):
        call()


# --- tick trains ---------------------------------------------------------------------


def test_a_steady_train_has_its_tempo_phase_and_limp():
    train = steady_train(96, 60.0, phase=0.25, limp=0.04, seed=1)
    beat = 60 / 96
    assert train.times[0] == pytest.approx(0.25 * beat)
    intervals = np.diff(train.times)
    long, short = intervals[0::2].mean(), intervals[1::2].mean()
    assert (long - short) / ((long + short) / 2) == pytest.approx(0.04, abs=1e-9)
    assert 120 / (long + short) == pytest.approx(96, abs=1e-6)
    assert not train.is_tock[0] and np.all(train.is_tock[1::2]) and not train.is_tock[2::2].any()
    assert steady_train(96, 10.0, tock_first=True).is_tock[0]


def test_the_tempo_drifts_up_as_the_spring_unwinds():
    train = steady_train(100, 120.0, drift_bpm_per_min=1.5)
    t, bpm = train.times[1:], 60 / np.diff(train.times)
    slope, start = np.polyfit(t, bpm, 1)
    assert slope * 60 == pytest.approx(1.5, rel=0.01)
    assert start == pytest.approx(100, abs=0.05)


def test_jitter_and_level_jitter_are_seeded_and_of_the_size_asked():
    a = steady_train(120, 120.0, jitter_s=0.001, level_jitter_db=1.0, seed=4)
    b = steady_train(120, 120.0, jitter_s=0.001, level_jitter_db=1.0, seed=4)
    np.testing.assert_array_equal(a.times, b.times)
    displacement = a.times - steady_train(120, 120.0).times[: a.times.size]
    assert displacement.std() == pytest.approx(0.001, rel=0.15)
    assert np.std(20 * np.log10(a.levels)) == pytest.approx(1.0, rel=0.15)


def test_random_free_running_trains_keep_their_tempos_apart_and_voices_distinct():
    for seed in range(20):
        trains = random_trains(4, 30.0, seed=seed, min_bpm_gap=4.0)
        bpm = [120 / (t.times[2] - t.times[0]) for t in trains]  # one full swing
        assert np.diff(np.sort(bpm)).min() > 3.5
        assert all(85 < b < 205 for b in bpm)
        assert len({t.voice for t in trains}) == 4
    assert [t.times.size for t in random_trains(3, 30.0, seed=5)] == [
        t.times.size for t in random_trains(3, 30.0, seed=5)
    ]


def test_random_trains_of_one_make_sound_alike():
    trains = random_trains(3, 10.0, seed=4, same_make=True)
    base = Voice.draw(4)
    assert [t.voice for t in trains] == [base.sibling(i) for i in range(3)]
    assert len({t.voice for t in trains}) == 3


def test_random_locked_trains_share_a_tempo_and_stay_in_step():
    trains = random_trains(3, 60.0, seed=2, locked=True, phase_spread=0.05, same_voice=True)
    assert len({t.voice for t in trains}) == 1
    counts = {t.times.size for t in trains}
    assert max(counts) - min(counts) <= 1
    k = min(counts)
    spread = np.ptp([t.times[:k] for t in trains], axis=0)
    period = np.median(np.diff(trains[0].times))
    # In step: within the phase spread plus the limp's half and the jitter.
    assert spread.max() < (0.05 + 0.02) * period + 0.002


def test_bounce_jitter_moves_the_secondary_impacts_not_the_first():
    voice = Voice.draw(0)  # one secondary impact
    assert len(voice.sub_delays) == 1
    train = steady_train(60, 40.0, voice=voice, bounce_jitter_s=0.001)
    rec = make_recording([train], seed=3)
    x = rec.samples.astype(float)
    sos = signal.butter(8, 12000, "highpass", fs=44100, output="sos")
    high = np.abs(signal.sosfiltfilt(sos, x))
    bounces, starts = [], []
    for t in rec.truth[0].times:
        k = int(round(t * 44100))
        starts.append(first_rise(rec.samples, t, 44100) - t)
        main = np.argmax(high[k : k + int(0.002 * 44100)])
        window = high[k + int(0.005 * 44100) : k + int(0.05 * 44100)]
        bounces.append((np.argmax(window) + int(0.005 * 44100) - main) / 44100)
    assert np.max(np.abs(starts)) <= 1e-4
    assert np.std(bounces) == pytest.approx(0.001, rel=0.35)
    # The mean of 16 variants: within three of its standard errors (0.25 ms).
    assert np.mean(bounces) == pytest.approx(voice.sub_delays[0], abs=0.00075)
    plain = make_recording([steady_train(60, 40.0, voice=voice)], seed=3).samples
    assert not np.array_equal(plain, rec.samples)


# --- impairments ---------------------------------------------------------------------


def one_tick(voice_seed=3):
    return [TickTrain([0.2], [False], Voice.draw(voice_seed))]


@pytest.mark.parametrize("rt60", [0.2, 0.5, 0.8])
def test_reverberation_decays_60_db_in_rt60(rt60):
    rec = make_recording(one_tick(), impairments=Impairments(reverb_rt60=rt60), duration=2.0)
    # Schroeder's backward integral of the energy, its slope from −5 to −25 dB.
    x = rec.samples.astype(float)[int(0.35 * 44100) :]  # after the dry tick
    decay = 10 * np.log10(np.cumsum(x[::-1] ** 2)[::-1] / np.sum(x**2))
    t = np.arange(x.size) / 44100
    fit = (decay < -5) & (decay > -25)
    slope = np.polyfit(t[fit], decay[fit], 1)[0]
    assert -60 / slope == pytest.approx(rt60, rel=0.15)
    dry = make_recording(one_tick(), duration=2.0).samples
    assert np.abs(dry[int(0.35 * 44100) :]).max() == 0.0


def transfer_db(impairments, seed=0):
    """Frequencies and the gain (dB) of what ``impairments`` add, measured with white
    noise 10 dB above the tick (the same noise with and without them)."""
    base = Impairments(snr_db=-10.0, noise="white")
    kwargs = dict(duration=20.0, seed=seed)
    a = make_recording(one_tick(), impairments=base, **kwargs).samples
    b = make_recording(one_tick(), impairments=impairments, **kwargs)
    f, pa = signal.welch(a, fs=44100, nperseg=8192)
    f, pb = signal.welch(b.samples, fs=44100, nperseg=8192)
    gain = 10 * np.log10(pb / pa)
    return f, gain - np.median(gain[(f > 1000) & (f < 2000)]), b


def test_the_phone_band_cuts_below_and_above_its_corners():
    imp = Impairments(snr_db=-10.0, noise="white", phone_band=(200.0, 6000.0))
    f, gain, rec = transfer_db(imp)
    at = lambda hz: np.interp(hz, f, gain)  # noqa: E731
    assert at(200) == pytest.approx(-3.0, abs=1.0)
    assert at(6000) == pytest.approx(-3.0, abs=1.0)
    assert at(50) < -20 and at(12000) < -20  # 12 dB/octave below, 24 above
    assert abs(at(1000)) < 0.5 and abs(at(3000)) < 0.5
    assert rec.applied["phone_band"] == (200.0, 6000.0)
    drawn = [make_recording(one_tick(), impairments=Impairments(phone_band=True), seed=s)
             .applied["phone_band"] for s in range(20)]  # fmt: skip
    assert all(100 <= low <= 300 and 4000 <= high <= 8000 for low, high in drawn)
    assert len(set(drawn)) == 20


@pytest.mark.parametrize("noise", ["white", "pink"])
@pytest.mark.parametrize("snr_db", [0.0, 20.0])
def test_noise_comes_at_the_signal_to_noise_ratio_asked(four, noise, snr_db):
    clean = make_recording(four).samples.astype(float)
    noisy = make_recording(four, impairments=Impairments(snr_db=snr_db, noise=noise))
    x = noisy.samples.astype(float)
    scale = np.dot(x, clean) / np.dot(clean, clean)
    residual = x - scale * clean
    measured = 10 * np.log10(np.mean((scale * clean) ** 2) / np.mean(residual**2))
    assert measured == pytest.approx(snr_db, abs=0.2)
    f, p = signal.welch(residual, fs=44100, nperseg=4096)
    octave = 10 * np.log10(np.interp(400, f, p) / np.interp(3200, f, p)) / 3
    assert octave == pytest.approx(3.0 if noise == "pink" else 0.0, abs=0.7)  # dB/octave


def test_compression_brings_loud_and_soft_ticks_closer():
    voice = Voice.draw(5)
    train = TickTrain([0.2, 1.2], [False, False], voice, levels=[1.0, 0.25])  # 12 dB apart

    def apart(impairments):
        x = make_recording([train], impairments=impairments, duration=2.0).samples
        rms = [np.sqrt(np.mean(x[int((t + 0.01) * 44100) : int((t + 0.04) * 44100)] ** 2))
               for t in (0.2, 1.2)]  # fmt: skip
        return 20 * np.log10(rms[0] / rms[1])

    assert apart(Impairments()) == pytest.approx(12.04, abs=0.05)
    # Both above the threshold: 12 dB in, 12/ratio out.
    squeezed = Impairments(compression=True, compression_threshold_db=-40.0)
    assert apart(squeezed) == pytest.approx(12.04 / 4, abs=1.0)
    harder = Impairments(compression=True, compression_threshold_db=-40.0, compression_ratio=8)
    assert apart(harder) == pytest.approx(12.04 / 8, abs=1.0)


def test_clipping_flattens_the_loudest_peaks_at_full_scale(four):
    clean = make_recording(four)
    assert np.abs(clean.samples).max() == pytest.approx(0.9)
    clipped = make_recording(four, impairments=Impairments(clipping=0.5))
    flat = np.abs(clipped.samples) >= 1.0
    assert flat.any() and np.abs(clipped.samples).max() == 1.0
    # Exactly the samples louder than half the peak are clipped.
    np.testing.assert_array_equal(flat, np.abs(clean.samples) / 0.9 >= 0.5)


def test_bumps_are_low_thumps_at_the_times_reported(four):
    rec = make_recording(four, impairments=Impairments(bumps=3), seed=7)
    bumps = rec.applied["bumps"]
    assert len(bumps) == 3 and all(c == 0 for _, c in bumps)
    sos = signal.butter(4, 120, "lowpass", fs=44100, output="sos")
    low = np.abs(signal.sosfilt(sos, rec.samples.astype(float)))
    quiet = np.abs(signal.sosfilt(sos, make_recording(four).samples.astype(float))).max()
    for t, _ in bumps:
        k = int(t * 44100)
        assert low[k : k + int(0.05 * 44100)].max() > 3 * quiet
    # Through a phone's band the thump is weaker, but loud beside the ticks still.
    phone = Impairments(bumps=3, phone_band=(300.0, 4000.0))
    rec = make_recording(four, impairments=phone, seed=7)
    x = np.abs(rec.samples)
    during = np.zeros(x.size, bool)
    for t, _ in rec.applied["bumps"]:
        during[int(t * 44100) : int((t + 0.15) * 44100)] = True
    for t, _ in rec.applied["bumps"]:
        assert x[int(t * 44100) : int((t + 0.15) * 44100)].max() > 0.25 * x[~during].max()
    # On several microphones, each bump on one of them.
    rec = make_recording(four, microphones=2, impairments=Impairments(bumps=6), seed=7)
    assert {c for _, c in rec.applied["bumps"]} == {0, 1}
    # At times given, besides those drawn; the drawn ones are those drawn without them.
    placed = make_recording(four, impairments=Impairments(bumps=3, bump_times=(1.25, 2.5)), seed=7)
    drawn = make_recording(four, impairments=Impairments(bumps=3), seed=7).applied["bumps"]
    times = sorted(t for t, _ in placed.applied["bumps"])
    assert times == sorted([t for t, _ in drawn] + [1.25, 2.5])
    with pytest.raises(ParameterError, match="bump_times"):
        Impairments(bump_times=(-1.0,))
    with pytest.raises(ParameterError, match="within the recording"):
        make_recording(four, impairments=Impairments(bump_times=(1e4,)), seed=7)


def test_resampling_keeps_the_truth_and_quantization_the_grid(four):
    imp = Impairments(resample_from=48000, quantize_bits=16)
    rec = make_recording(four, sample_rate=44100, impairments=imp)
    assert rec.samples.shape == (int(round(rec.duration * 44100)),)
    last = max(train.times[-1] for train in four)
    assert rec.duration == pytest.approx(last + 1.0, abs=1 / 44100)
    np.testing.assert_array_equal(rec.samples * 32768, np.round(rec.samples * 32768))
    errors = [first_rise(rec.samples, rec.truth[i].times[k], 44100) - rec.truth[i].times[k]
              for i, k in isolated(rec.truth)]  # fmt: skip
    assert np.max(np.abs(errors)) <= 1e-4


def test_the_phone_set_keeps_the_onsets_within_half_a_millisecond(four):
    """Band limits, compression and reverberation move where a tick's energy rises by
    well under the 1 ms the analysis must reach."""
    imp = Impairments.phone(snr_db=60.0, bumps=0)
    trains = [steady_train(60, 20.0, voice=v, phase=0.5 * i) for i, v in enumerate(voices(2))]
    rec = make_recording(trains, impairments=imp, seed=1)
    errors = [first_rise(rec.samples, rec.truth[i].times[k], 44100, fraction=0.2)
              - rec.truth[i].times[k] for i, k in isolated(rec.truth, gap=0.4)]  # fmt: skip
    assert len(errors) == 40
    assert np.max(np.abs(errors)) <= 5e-4

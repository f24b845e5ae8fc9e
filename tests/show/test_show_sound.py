"""The click track: file format and length, and clicks on the simulated crossings."""

from __future__ import annotations

import wave

import numpy as np
import pytest

import metrosync
from metrosync.errors import ParameterError
from metrosync.show.recording import RecordedRun
from metrosync.show.sound import click_track, crossing_times, write_wav


def simulated_crossings(theta, time):
    """Zero crossings of an every-step trajectory, found as the integrator finds them:
    a strict sign change between consecutive steps, time interpolated linearly."""
    out = []
    for k in range(theta.size - 1):
        a, b = theta[k], theta[k + 1]
        if (a < 0 < b) or (a > 0 > b):
            out.append(time[k] + (time[k + 1] - time[k]) * a / (a - b))
    return np.array(out)


def read_wav(path):
    with wave.open(str(path), "rb") as f:
        params = (f.getnchannels(), f.getsampwidth(), f.getframerate(), f.getnframes())
        pcm = np.frombuffer(f.readframes(f.getnframes()), dtype="<i2").reshape(-1, 2)
    return params, pcm / 32767.0


def onsets(channel, threshold=0.25, quiet=30):
    """Samples where |x| first exceeds ``threshold`` after ``quiet`` samples below it."""
    loud = np.abs(channel) > threshold
    index = np.flatnonzero(loud)
    return np.array([k for k in index if not loud[max(0, k - quiet) : k].any()])


@pytest.mark.parametrize(
    ("rate", "speedup", "start", "end"), [(44100, 1.0, None, None), (22050, 2.5, 2.0, 13.0)]
)
def test_wav_sample_rate_channels_and_length(recorded_ds, tmp_path, rate, speedup, start, end):
    path = tmp_path / "ticks.wav"
    write_wav(recorded_ds, path, sample_rate=rate, speedup=speedup, start=start, end=end)
    (channels, width, framerate, frames), samples = read_wav(path)
    span = (end or 20.0) - (start or 0.0)
    assert (channels, width, framerate) == (2, 2, rate)
    assert frames == round(span / speedup * rate)
    assert 0.05 < np.abs(samples).max() <= 0.9 + 1e-4  # audible, never clipping


@pytest.mark.parametrize("speedup", [1.0, 3.0])
def test_clicks_fall_on_the_simulated_crossings_within_one_sample(pair_ds, tmp_path, speedup):
    rate = 44100
    path = tmp_path / "pair.wav"
    write_wav(pair_ds, path, sample_rate=rate, speedup=speedup, start=1.0)
    _, samples = read_wav(path)
    time = pair_ds.time.values
    # Metronome 0 sits at x = +R (right channel), metronome 1 at x = −R (left).
    for metronome, channel in ((0, 1), (1, 0)):
        expected = simulated_crossings(pair_ds.theta.values[:, 0, metronome], time)
        expected = expected[(expected >= 1.0) & (expected < 12.0)]
        expected_audio = (expected - 1.0) / speedup
        heard = onsets(samples[:, channel]) / rate
        assert heard.size == expected.size > 20
        assert np.max(np.abs(heard - expected_audio)) <= 1.0 / rate


def test_crossings_use_both_directions_and_match_the_integrator(pair_ds):
    run = RecordedRun.from_dataset(pair_ds)
    assert run.every_step
    found = crossing_times(run)
    for i in range(2):
        theta = run.theta[:, i]
        expected = simulated_crossings(theta, run.time)
        np.testing.assert_allclose(found[i], expected, rtol=0, atol=1e-12)
        # Up and down crossings alternate: half a period apart on average.
        period = 120.0 / float(pair_ds.frequency_bpm[0, i])
        assert np.median(np.diff(found[i])) == pytest.approx(period / 2, rel=0.05)


def test_sparse_records_find_crossings_by_hermite_interpolation():
    kwargs = dict(
        frequencies_bpm=[188.0, 196.0], theta0=[0.3, -0.2], duration=12.0, trajectories=True
    )
    every = crossing_times(
        RecordedRun.from_dataset(metrosync.simulate(None, None, record_every=1, **kwargs))
    )
    sparse = crossing_times(
        RecordedRun.from_dataset(metrosync.simulate(None, None, record_every=5, **kwargs))
    )
    for a, b in zip(every, sparse, strict=True):
        assert a.size == b.size
        # Records 0.05 s apart (five steps, escapement kicks in between) still place
        # each crossing within 2 ms, typically within half a millisecond.
        assert np.max(np.abs(a - b)) < 2e-3
        assert np.median(np.abs(a - b)) < 5e-4


def test_pan_follows_the_place_on_the_disk(pair_ds):
    track = click_track(RecordedRun.from_dataset(pair_ds), end=3.0)
    left, right = np.abs(track.samples).sum(axis=0)
    assert right > 0 and left > 0
    only_right = click_track(RecordedRun.from_dataset(pair_ds.isel(metronome=[0])), end=3.0)
    l0, r0 = np.abs(only_right.samples).sum(axis=0)
    assert l0 < 0.05 * r0


def test_on_a_board_the_row_goes_from_left_to_right(board_ds):
    run = RecordedRun.from_dataset(board_ds)
    times = np.linspace(0.0, 10.0, 5)
    np.testing.assert_array_equal(run.stereo_position(0, times), -1.0)
    np.testing.assert_array_equal(run.stereo_position(1, times), 1.0)
    alone = click_track(RecordedRun.from_dataset(board_ds.isel(metronome=[0])), end=3.0)
    left, right = np.abs(alone.samples).sum(axis=0)
    assert left > 0 and left == pytest.approx(right)  # one metronome alone: in the middle


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"speedup": 0}, "speedup"),
        ({"sample_rate": 1000}, "sample_rate"),
        ({"start": 50.0}, "start"),
        ({"start": 5.0, "end": 4.0}, "end"),
    ],
)
def test_bad_options_name_the_argument(pair_ds, options, name):
    with pytest.raises(ParameterError, match=f"`{name}`"):
        click_track(RecordedRun.from_dataset(pair_ds), **options)


# -- bounded memory and lengths that make sense --------------------------------------


def test_blocks_add_up_to_the_same_audio_whatever_their_size(recorded_ds):
    track = click_track(RecordedRun.from_dataset(recorded_ds), speedup=1.5)
    whole = np.concatenate(list(track.blocks(10**8)))
    small = np.concatenate(list(track.blocks(997)))  # clicks straddle most block edges
    assert whole.shape == (track.n_samples, 2) and np.abs(whole).max() > 0.05
    np.testing.assert_array_equal(small, whole)


def test_writing_does_not_hold_the_audio_in_memory(recorded_ds, tmp_path):
    import tracemalloc

    run = RecordedRun.from_dataset(recorded_ds)
    peaks = []
    for speedup in (1.0, 0.25):  # 20 s and 80 s of audio
        track = click_track(run, speedup=speedup)
        tracemalloc.start()
        try:
            track.write(tmp_path / f"x{speedup}.wav")
            peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
    samples_bytes = 80.0 * 44100 * 2 * 8  # the longer track as float samples: 56 MB
    assert peaks[1] < 0.1 * samples_bytes
    assert peaks[1] < 1.5 * peaks[0]  # four times the audio, not four times the memory


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"speedup": 1e6}, r"`speedup` = 1e\+06 brings a metronome's ticks .* closer than one "
                           r"click \(6 ms\).*at most 51\."),
        ({"speedup": 1e-6}, r"`speedup` = 1e-06 makes 20 s of simulation last 231 days of "
                            r"audio, more than 1 h; use a `speedup` of at least 0.00556"),
        ({"start": 5.0, "end": 5.2}, r"shorter than one tick period \(0.31\d s\)"),
    ],
)  # fmt: skip
def test_useless_lengths_are_refused(recorded_ds, options, match):
    with pytest.raises(ParameterError, match=match):
        click_track(RecordedRun.from_dataset(recorded_ds), **options)


def test_a_metronome_out_of_beat_clicks_where_its_escapement_acts():
    """With `escapement_offset`, the clicks sit where θ crosses the offset (where the
    kicks are), each metronome its own, not at the vertical."""
    design = metrosync.MetronomeDesign()
    offsets = (0.05, -0.02)
    metronomes = [
        metrosync.Metronome(metrosync.MetronomeDesign(escapement_offset=d), design.l2_for_bpm(b))
        for d, b in zip(offsets, (188.0, 196.0), strict=True)
    ]
    ds = metrosync.simulate(None, None, metronomes=metronomes, theta0=[0.5, -0.4],
                            duration=8.0, record_every=1, trajectories=True)  # fmt: skip
    np.testing.assert_array_equal(ds.escapement_offset.values, [offsets])
    run = RecordedRun.from_dataset(ds)
    np.testing.assert_array_equal(run.tick_angles, offsets)
    found = crossing_times(run)
    for i, offset in enumerate(offsets):
        want = simulated_crossings(run.theta[:, i] - offset, run.time)
        np.testing.assert_allclose(found[i], want, rtol=0, atol=1e-12)
        # Each click is where the escapement kicks: θ̇ jumps there.
        jumps = np.abs(np.diff(run.theta_dot[:, i], 2))
        kicked = run.time[1:-1][jumps > 10 * np.median(jumps)]
        assert kicked.size >= found[i].size > 10
        assert np.all(np.min(np.abs(kicked[:, None] - found[i][None, :]), axis=1) < 0.02)
    # The model's one value is used when the dataset has no per-metronome variable.
    same = metrosync.simulate(1, 192, duration=2.0, record_every=1, trajectories=True,
                              changes={"escapement_offset": 0.04}).drop_vars("escapement_offset")  # fmt: skip  # noqa: E501
    np.testing.assert_array_equal(RecordedRun.from_dataset(same).tick_angles, [0.04])
    plain = metrosync.simulate(1, 192, duration=2.0, record_every=1, trajectories=True)
    assert "escapement_offset" not in plain
    np.testing.assert_array_equal(RecordedRun.from_dataset(plain).tick_angles, [0.0])


# -- realistic tick sounds -----------------------------------------------------------


def test_realistic_ticks_start_on_the_crossings_tick_up_and_tock_down(pair_ds):
    from metrosync.synthetic.ticks import voices

    run = RecordedRun.from_dataset(pair_ds)
    track = click_track(run, start=1.0, end=11.0, tick_sound="realistic")
    samples = track.samples
    assert 0.05 < np.abs(samples).max() <= 0.9
    sounds = voices(2)
    found = crossing_times(run)
    # Each metronome rendered alone: its ticks where the energy rises.
    for metronome in (0, 1):
        one = RecordedRun.from_dataset(pair_ds.isel(metronome=[metronome]))
        alone = click_track(one, start=1.0, end=11.0, tick_sound="realistic").samples.sum(axis=1)
        times = found[metronome][(found[metronome] >= 1.0) & (found[metronome] < 11.0)] - 1.0
        up = run.theta_dot_at(times + 1.0)[:, metronome] > 0
        np.testing.assert_array_equal(track.is_tock[metronome], ~up)
        onsets = []
        for t in times:
            k = int(round(t * 44100))
            seg = np.abs(alone[max(k - 200, 0) : k + 200])
            onsets.append((max(k - 200, 0) + np.flatnonzero(seg > 0.05 * seg.max())[0]) / 44100)
        assert np.max(np.abs(np.array(onsets) - times)) < 1e-4
        # The tock is the softer, and each metronome sounds with its own voice.
        voice = sounds[metronome]
        tick = np.abs(alone[int(round(times[up][0] * 44100)) :][:4000]).max()
        tock = np.abs(alone[int(round(times[~up][0] * 44100)) :][:4000]).max()
        assert tock < tick
        np.testing.assert_array_equal(track.waveforms[metronome], voice.waveform(44100))
    # The other sound: one 6 ms click per crossing, the same at every crossing.
    plain = click_track(run, start=1.0, end=11.0)
    assert plain.tock_waveforms is None and plain.waveforms[0].size == round(0.006 * 44100)


def test_realistic_ticks_never_clip_even_sped_up(recorded_ds, tmp_path):
    track = write_wav(recorded_ds, tmp_path / "fast.wav", speedup=6.0, tick_sound="realistic")
    (channels, _, _, frames), samples = read_wav(tmp_path / "fast.wav")
    assert frames == track.n_samples
    assert 0.02 < np.abs(samples).max() <= 0.9 + 1e-4
    with pytest.raises(ParameterError, match=r"`tick_sound` must be one of 'click', 'realistic'"):
        click_track(RecordedRun.from_dataset(recorded_ds), tick_sound="wood")


def test_the_cli_offers_the_tick_sounds_the_library_knows():
    from metrosync.cli.listen import TICK_SOUNDS as offered
    from metrosync.show.sound import TICK_SOUNDS

    assert offered == TICK_SOUNDS


def test_the_overlap_bound_holds_for_any_train_at_least_that_far_apart(rng):
    from metrosync.show.sound import _overlap_peak
    from metrosync.synthetic.ticks import Voice

    wave = Voice.draw(2).waveform(44100)
    for spacing in (200, 700, 3000, 10000):
        bound = _overlap_peak(wave, spacing)
        worst = 0.0
        for _ in range(20):
            starts = np.cumsum(spacing + rng.integers(0, spacing // 2 + 1, 40))
            out = np.zeros(starts[-1] + wave.size)
            for k in starts:
                out[k : k + wave.size] += wave
            worst = max(worst, np.abs(out).max())
        assert worst <= bound
        assert bound < 4 * worst  # not so loose that the file is needlessly quiet
    assert _overlap_peak(wave, np.inf) == _overlap_peak(wave, 10**6) == np.abs(wave).max()

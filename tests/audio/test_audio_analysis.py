"""The timing model's analysis (`analyze_audio`) end to end on recordings built as the
world makes them: metronomes of every tick structure (`metrosync.synthetic.structures`),
through a phone, scored with
`metrosync.synthetic.score` (recall over the ticks a single microphone can hear,
precision over every tick given to a metronome). Each test draws its own recordings
from its own seeds; none is a corpus recording, and none pins one."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from phones import two_phone_files

from metrosync import synthetic
from metrosync.audio.analysis import analyze_audio
from metrosync.synthetic import clicks, voices
from metrosync.synthetic.score import scores
from metrosync.synthetic.structures import STRUCTURES, widen


def _trains(n, seed, *, structure="classic", same_voice=False, bpms=None, duration=40.0):
    rng = np.random.default_rng([48, seed])
    sounds = [voices(1, seed)[0]] * n if same_voice else voices(n, seed)
    bpms = list(rng.uniform(90, 210, n)) if bpms is None else bpms
    return [
        synthetic.steady_train(
            b,
            duration,
            phase=rng.uniform(),
            limp=0.05 * rng.uniform(),
            voice=widen(sounds[i], structure),
            seed=10 * seed + i,
            jitter_s=rng.uniform(0.3e-3, 1e-3),
            drift_bpm_per_min=0.2 * rng.uniform(-1, 1),
        )  # fmt: skip
        for i, b in enumerate(bpms)
    ]


def _analysed(tmp_path, trains, seed, impairments=None, **options):
    impairments = synthetic.Impairments.phone() if impairments is None else impairments
    rec = synthetic.make_recording(trains, impairments=impairments, seed=seed)
    path = rec.write(tmp_path / f"r{seed}.wav")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "too short" for a recording under a minute
        ds = analyze_audio(path, **options)
    return ds, [t.times for t in rec.truth]


def _tick_by_tick(table, recall=0.99, precision=0.99):
    r, given, timing, bpm = table.T
    assert np.all(r >= recall), r
    assert np.all(given >= precision), given
    assert np.all(timing <= 1e-3), timing
    assert np.all(bpm <= 0.1), bpm


@pytest.mark.parametrize("structure", sorted(STRUCTURES))
def test_a_tick_of_several_impacts_is_one_tick_at_its_loud_impact(tmp_path, structure):
    """One metronome whose tick is several impacts (bounces after the loud one; for
    "precursor", a quieter one 10-45 ms before it too, its lead wandering tick to tick):
    one metronome, every tick once, timed at its loud impact, and its learned tick
    says what came before and after."""
    ds, truth = _analysed(tmp_path, _trains(1, 3, structure=structure), 3)
    assert ds.attrs["metronomes"] == 1
    _tick_by_tick(scores(ds, truth), recall=1.0)
    assert int((ds.tick_metronome == 0).sum()) == truth[0].size
    words = str(ds.tick_impacts.values[0])
    assert "0 ms (main)" in words
    if structure == "precursor":  # heard before most ticks, and learned as part of them
        assert ds.attrs["impacts"] > 1.5 * truth[0].size
        assert "−" in words.split(";")[0]
    assert float(ds.tick_probability.min()) > 0.5 and float(ds.explained[0]) > 0.9


@pytest.mark.parametrize("seed", range(4))
def test_one_metronome_is_never_two(tmp_path, seed):
    """Through a phone made too loud, with bumps, every structure in turn."""
    structure = sorted(STRUCTURES)[seed % len(STRUCTURES)]
    trains = _trains(1, 20 + seed, structure=structure, duration=30.0)
    impairments = synthetic.Impairments.phone(clipping=0.7, bumps=4)
    ds, _ = _analysed(tmp_path, trains, 20 + seed, impairments)
    assert ds.attrs["metronomes"] == 1


@pytest.mark.parametrize("n", [2, 3])
def test_metronomes_of_different_makes_and_tempi_are_each_heard_tick_by_tick(tmp_path, n):
    bpms = [100.0, 131.0, 172.0][:n]
    ds, truth = _analysed(tmp_path, _trains(n, 40 + n, structure="uneven", bpms=bpms), 40 + n)
    assert ds.attrs["metronomes"] == n
    assert ds.attrs["attribution"] == "sound"
    # a tick 20-40 ms into another's ring can be timed a cycle of its resonance late
    # (1.1 ms), by its rise and by its learned waveform alike, where the ring adds to
    # the later cycle: allowed twice in 64-85 ticks (precision 0.97)
    _tick_by_tick(scores(ds, truth), recall=0.95, precision=0.97)
    assert ds.attrs["no_common_beat"]


def test_two_metronomes_of_one_make_4_bpm_apart_are_two(tmp_path):
    """Told apart by their timing alone: the same sound, drifting through each other."""
    trains = _trains(2, 7, same_voice=True, bpms=[100.0, 104.0], duration=60.0)
    ds, truth = _analysed(tmp_path, trains, 7)
    assert ds.attrs["metronomes"] == 2
    table = scores(ds, truth)
    assert np.all(table[:, 3] <= 0.1) and np.all(table[:, 0] >= 0.9)


def test_a_setting_near_the_tempo_changes_nothing_and_one_far_off_draws_a_warning(tmp_path):
    trains = _trains(1, 11, bpms=[150.0])
    ds, truth = _analysed(tmp_path, trains, 11, bpm=152)
    _tick_by_tick(scores(ds, truth), recall=1.0)
    rec = synthetic.make_recording(trains, impairments=synthetic.Impairments.phone(), seed=11)
    path = rec.write(tmp_path / "far.wav")
    with pytest.warns(UserWarning, match="not near `bpm` 90"):
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="the recording holds only")
            analyze_audio(path, bpm=90)


def test_a_metronome_count_given_that_differs_from_the_one_heard_is_noted(tmp_path):
    ds, _ = _analysed(tmp_path, _trains(1, 12), 12, metronomes=2)
    assert ds.attrs["metronomes"] == 2 and ds.attrs["metronomes_source"] == "given"
    assert "1 metronome told apart, 2 expected" in ds.attrs["summary"]


def test_two_microphones_in_two_files_recorded_together(tmp_path):
    """Two metronomes of one make, each near its own phone: the files start 0.73 s and
    0 s into the session; aligned, both metronomes heard, every hearable tick their own."""
    files, truth = two_phone_files(tmp_path, (150.0, 156.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "too short"
        ds = analyze_audio(files)
    # within the sound's travel between the microphones (1 ms here)
    assert ds.attrs["offsets"] == pytest.approx([0.0, -0.73], abs=1.5e-3)
    assert ds.attrs["channels"] == 2 and ds.attrs["metronomes"] == 2
    # each tick is timed where it is heard first, up to 1 ms before microphone 0 hears it
    table = scores(ds, truth, tolerance=2e-3)
    assert np.all(table[:, 0] >= 0.95) and np.all(table[:, 1] >= 0.97)
    assert np.all(table[:, 3] <= 0.1)


def test_files_not_recorded_together_draw_a_warning(tmp_path):
    a = clicks.metronome_train(150, 30, phase=0.1)
    b = clicks.metronome_train(97, 30, phase=0.4)
    pa = clicks.write(tmp_path / "a.wav", clicks.render([a], 30))
    pb = clicks.write(tmp_path / "b.wav", clicks.render([b], 30, pitches=[2400.0]))
    with pytest.warns(UserWarning, match="hardly match at any offset"):
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="the recording holds only")
            analyze_audio([pa, pb])


def test_two_metronomes_of_one_tempo_half_a_beat_apart_are_two(tmp_path):
    """The same click, locked half a beat apart: the tempo's own frequency cancels in the
    periodicity search, its second harmonic finds them (`MODEL.harmonics`)."""
    a = clicks.metronome_train(184, 30, phase=0.0)
    b = clicks.metronome_train(184, 30, phase=0.5)
    x = clicks.render([a, b], 30, pitches=[2000.0, 2000.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = analyze_audio(clicks.write(tmp_path / "locked.wav", x))
    assert ds.attrs["metronomes"] == 2
    assert scores(ds, [a, b])[:, :2].min() == 1.0


def test_two_metronomes_locked_in_step_heard_from_two_sides_are_two(tmp_path):
    """`metrosync listen`'s two metronomes, in step within seconds: in timing one tick of
    two impacts; heard from two sides, two metronomes (`decompose.elsewhere`)."""
    import metrosync
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times, write_wav

    run = metrosync.simulate(2, 184.0, sigma_bpm=0.75, duration=40.0, record_every=1,
                             trajectories=True, seed=1)  # fmt: skip
    write_wav(run, tmp_path / "two.wav")
    crossings = crossing_times(RecordedRun.from_dataset(run))
    ds = analyze_audio(tmp_path / "two.wav")
    assert ds.attrs["metronomes"] == 2
    assert scores(ds, crossings)[:, :2].min() >= 0.95


@pytest.mark.xfail(strict=True, reason="what the timing model cannot do yet: three of one "
                   "sound falling into step over 90 s are all found and followed (their wander "
                   "smoothed), but two of them swap identities where their ticks cross, "
                   "told apart by timing alone")  # fmt: skip
def test_three_metronomes_falling_into_step_over_90_s_are_each_followed(listen_run):
    path, crossings = listen_run
    ds = analyze_audio(path, metronomes=3)
    assert ds.sizes.get("metronome", 0) == 3
    assert scores(ds, crossings)[:, :2].min() >= 0.95


def test_a_click_train_through_mp3_is_one_metronome_with_every_click(tmp_path):
    """MP3's pre-echo puts a quieter onset 7-12 ms before nearly every click, at a lead
    that changes with the click's place in the coder's frames: a precursor, which
    must neither pull the first timing off the clicks nor become a metronome."""
    import soundfile as sf

    from metrosync.synthetic import score

    train = clicks.metronome_train(160, 12, phase=0.2)
    path = tmp_path / "rec.mp3"
    sf.write(str(path), clicks.render([train], 12, rate=48000), 48000, subtype="MPEG_LAYER_III")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "too short"
        ds = analyze_audio(path)
    assert ds.attrs["metronomes"] == 1
    recall, precision, errors = score.match(train, ds.tick_time.values, 5e-3)
    assert recall == 1.0 and precision == 1.0 and np.abs(errors).max() <= 5e-3


@pytest.mark.parametrize("lead", [(1e-3, 3e-3), (3e-3, 5e-3)])
def test_a_tick_just_behind_a_knock_is_timed_at_its_own_impact(tmp_path, lead):
    """A knock on the phone 1–5 ms before 12 of a metronome's ticks: the detector hears
    the knock's crack as the onset and the tick, within the refractory time, is not
    heard apart (`test_audio_detection`). Where the onset on a beat is off its strike's
    predicted time, the strike is sought by its sound too (`audio.seek`): the knocked
    ticks are timed within 1 ms at least 46 times in 48 (47 and 48, 2026-12-03; 38 and
    40 before), and every other tick heard keeps its time."""
    from test_audio_detection import _knocked

    from metrosync.audio import detection as det

    right = 0
    for seed in range(4):
        recording, truth, knocked = _knocked(tmp_path, seed, lead)
        ds = analyze_audio(recording.path)
        assert ds.attrs["metronomes"] == 1
        found = ds.tick_time.values[ds.tick_metronome.values == 0]
        error = np.min(np.abs(found[None, :] - truth[:, None]), axis=1)
        right += int((error[knocked] <= 1e-3).sum())
        heard = truth > det.RESOLUTION
        heard[knocked] = False
        assert (error[heard] <= 1e-3).all()
    assert right >= 46


def test_the_model_s_parameters_are_few_named_documented_and_recorded(tmp_path):
    """At most fifteen, each with a unit and a meaning, each in docs/sound.md's table,
    and every dataset records the ones it used."""
    import json
    from pathlib import Path

    from metrosync.audio.settings import MODEL, TimingModel

    described = TimingModel.described()
    assert len(described) <= 15
    assert all(meaning for _, _, _, meaning in described)
    page = (Path(__file__).parents[2] / "docs" / "sound.md").read_text(encoding="utf-8")
    assert all(f"| `{name}` |" in page for name, *_ in described)
    train = clicks.metronome_train(150, 20, phase=0.1)
    ds = analyze_audio(clicks.write(tmp_path / "one.wav", clicks.render([train], 20)))
    recorded = json.loads(ds.attrs["timing_model"])
    assert recorded == json.loads(json.dumps(dataclasses.asdict(MODEL)))


def test_two_metronomes_each_on_its_own_channel_falling_into_step_are_two(tmp_path, capsys):
    """`metrosync listen`'s stereo track of two metronomes, one a channel, that lock a
    third of a beat apart after about 30 s (docs/sound.md's figure): two metronomes.
    A channel that hears none of a tick hears what else sounds there, the other's ring,
    louder once they lock; counted down to 30 dB below the loudest channel, that does
    not make the metronome two sounds (it had: three, one of them split at 29 s)."""
    from metrosync.cli import main

    path = tmp_path / "two.wav"
    assert main(["listen", "--n", "2", "--sigma", "0.75", "--seed", "1", "--duration", "120",
                 "--out", str(path)]) == 0  # fmt: skip
    capsys.readouterr()
    ds = analyze_audio(path)
    assert ds.attrs["metronomes"] == 2 and ds.attrs["attribution"] == "sound"
    assert np.all(ds.ticks.values > 360)  # each heard all along, 369 beats

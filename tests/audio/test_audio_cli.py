"""``metrosync analyze recording.wav`` as a user meets it: output, files, and errors."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import metrosync
from metrosync.cli import main
from metrosync.synthetic import clicks


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_lazy_export():
    assert metrosync.analyze_audio is metrosync.audio.analyze_audio


def test_summary_dataset_and_plot(capsys, tmp_path, pair_recording):
    path, _ = pair_recording
    nc, png = tmp_path / "pair.nc", tmp_path / "pair.png"
    code, out, err = run(capsys, "analyze", str(path), "--out", str(nc), "--plot", str(png))
    assert code == 0, err
    assert (
        "told apart by sound" in out
        and "attribution: sure" in out
        and "out of beat" in out
        and "in beat" in out
    )
    assert f"wrote {nc}" in out and png.stat().st_size > 10_000
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert {"tick_time", "tick_strength", "detection", "threshold", "r_acoustic",
                "asymmetry", "phase_difference"} <= set(ds.variables)  # fmt: skip
        assert ds.tick_time.attrs["units"] == "s"
        assert np.all(np.diff(ds.tick_time.values) > 0)


def test_options_reach_the_analysis(capsys, pair_recording):
    path, _ = pair_recording
    code, out, _ = run(capsys, "analyze", str(path), "--bpm", "190", "--metronomes", "2",
                       "--band", "800,8000", "--refractory", "0.005")  # fmt: skip
    assert code == 0
    assert "metronomes: 2 (given)" in out and "impacts heard" in out


@pytest.mark.parametrize(
    ("setup", "argv", "message"),
    [
        (None, ["missing.wav"], "does not exist"),
        ("empty", ["e.wav"], "empty (0 bytes)"),
        ("text", ["t.wav"], "as audio"),
        ("m4a", ["phone.m4a"], "ffmpeg -i phone.m4a phone.wav"),
        ("silent", ["s.wav"], "silent"),
        ("two", ["a.wav", "b.wav"], "one recording at a time"),
        ("mixed", ["a.wav", "run.log"], "not both"),
        ("silent", ["s.wav", "--bpm", "1000"], "`bpm` (--bpm) must be a tempo in 20..400"),
        ("silent", ["s.wav", "--out", "x.txt"], "`--out` 'x.txt' must end in .nc"),
        ("silent", ["s.wav", "--band", "5000,2000"], "`band` (--band) must be two frequencies"),
        # The filter's edges must lie below the Nyquist frequency, not be cut down to it.
        ("silent", ["s.wav", "--band", "1000,30000"], "high < 22050 Hz, the Nyquist frequency"),
        ("silent", ["s.wav", "--band", "1000,22050"], "got (1000.0, 22050.0)"),
        # the option that chose between the stages and the timing model, gone with them
        ("silent", ["s.wav", "--analysis", "stages"], "--analysis stages is no longer an"),
        ("mixed", ["run.log", "--analysis", "timing"], "the timing model is the one sound"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, monkeypatch, setup, argv, message):
    monkeypatch.chdir(tmp_path)
    if setup == "empty":
        (tmp_path / "e.wav").write_bytes(b"")
    elif setup == "text":
        (tmp_path / "t.wav").write_text("hello")
    elif setup == "m4a":
        (tmp_path / "phone.m4a").write_bytes(b"\0\0\0\x18ftypM4A ")
    elif setup == "silent":
        clicks.write(tmp_path / "s.wav", np.zeros((44100, 1)))
    elif setup in ("two", "mixed"):
        clicks.write(tmp_path / "a.wav", np.zeros((44100, 1)))
        clicks.write(tmp_path / "b.wav", np.zeros((44100, 1)))
        (tmp_path / "run.log").write_text("0 1\n")
    code, out, err = run(capsys, "analyze", *argv)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_light_gate_options_with_a_recording_warn(capsys, pair_recording):
    path, _ = pair_recording
    code, _, err = run(capsys, "analyze", str(path), "--glitch", "0.01")
    assert code == 0
    assert "a recording ignores --glitch" in err


def test_audio_options_with_logs_warn(capsys):
    from pathlib import Path

    log = Path(__file__).parents[1] / "data" / "clean.log"
    code, _, err = run(capsys, "analyze", str(log), "--bpm", "180")
    assert "light-gate logs ignore --bpm" in err


def test_a_tempo_far_from_the_ticks_warns(capsys, pair_recording):
    path, _ = pair_recording
    code, _, err = run(capsys, "analyze", str(path), "--bpm", "62")
    assert code == 0
    assert "the ticks sound like 190" in err and "not near `bpm` (--bpm) 62" in err


def test_follow_with_a_recording_warns(capsys, pair_recording):
    path, _ = pair_recording
    code, _, err = run(capsys, "analyze", str(path), "--follow")
    assert code == 0
    assert "a recording ignores --follow" in err


def test_a_band_just_below_nyquist_is_used_as_given(capsys, pair_recording):
    path, _ = pair_recording
    code, out, err = run(capsys, "analyze", str(path), "--band", "1000,22000")
    assert code == 0, err
    assert "error" not in err


def test_three_of_our_own_clicks_in_a_mixture_are_three(capsys, tmp_path):
    """`listen` three metronomes falling into step, then `analyze` it: three metronomes
    near their 184.6 BPM, with or without the setting given, and no warning."""
    wav = tmp_path / "t30.wav"
    code, _, err = run(capsys, "listen", "--n", "3", "--sigma", "0.75", "--seed", "1",
                       "--duration", "30", "--out", str(wav))  # fmt: skip
    assert code == 0, err
    for extra in ([], ["--bpm", "184.6"]):
        code, out, err = run(capsys, "analyze", str(wav), *extra)
        assert code == 0 and "warning" not in err, err
        assert "metronomes: 3 (told apart by sound)" in out
        bpms = [float(line.split(":")[1].split("±")[0]) for line in out.splitlines()
                if line.startswith("  metronome ") and "BPM" in line]  # fmt: skip
        assert len(bpms) == 3 and all(abs(b - 184.6) < 0.5 for b in bpms)
        assert "= 184." in out


def test_one_metronome_with_a_quiet_impact_before_its_tick_is_one(capsys, tmp_path):
    """One metronome whose tick has a quieter impact 10-45 ms before the loud one (as a
    real tick has) is one metronome, with its dataset and plot."""
    from metrosync import synthetic
    from metrosync.synthetic.structures import widen

    train = synthetic.steady_train(96.4, 30, phase=0.3, limp=0.039, jitter_s=0.6e-3, seed=5,
                                   voice=widen(synthetic.voices(1, 5)[0], "precursor"))  # fmt: skip
    rec = synthetic.make_recording([train], impairments=synthetic.Impairments.phone(), seed=5)
    path = rec.write(tmp_path / "one.wav")
    nc, png = tmp_path / "one.nc", tmp_path / "one.png"
    code, out, err = run(capsys, "analyze", str(path), "--out", str(nc),
                         "--plot", str(png))  # fmt: skip
    assert code == 0, err
    assert "metronomes: 1 (one tick train)" in out and "its sound: tick: −" in out
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert {"tick_time", "tick_metronome", "tick_probability", "bpm", "explained"} <= set(
            ds.variables
        )
        assert abs(float(ds.bpm[0]) - 96.4) < 0.1
    assert png.stat().st_size > 10_000

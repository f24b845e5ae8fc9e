"""`metrosync animate`, `listen` and `page`: from a file or by simulating."""

from __future__ import annotations

import wave

import pytest

from metrosync._files import write_netcdf
from metrosync.cli import main

SMALL = ["--n", "3", "--duration", "4", "--sigma", "0.5"]


def test_listen_simulates_every_step(tmp_path, capsys):
    out = tmp_path / "ticks.wav"
    assert main(["listen", *SMALL, "--speedup", "2", "--out", str(out)]) == 0
    with wave.open(str(out)) as f:
        assert f.getnframes() == 2 * 44100
    assert "clicks" in capsys.readouterr().out


def test_listen_sounds_real_ticks_on_request(tmp_path, capsys):
    import numpy as np

    paths = {}
    for sound in ("click", "realistic"):
        paths[sound] = tmp_path / f"{sound}.wav"
        argv = ["listen", *SMALL, "--seed", "2", "--tick-sound", sound, "--out", str(paths[sound])]
        assert main(argv) == 0
    capsys.readouterr()
    read = {}
    for sound, path in paths.items():
        with wave.open(str(path)) as f:
            read[sound] = np.frombuffer(f.readframes(f.getnframes()), "<i2").reshape(-1, 2)
    assert read["click"].shape == read["realistic"].shape
    # The same ticks with longer sounds: far more sound between them.
    busy = {k: np.mean(np.abs(v.astype(float)).sum(axis=1) > 30) for k, v in read.items()}
    assert busy["realistic"] > 5 * busy["click"]
    # Each file's first sound starts at the same first tick.
    first = {
        k: np.flatnonzero(np.abs(v.astype(float)).sum(axis=1) > 30)[0] for k, v in read.items()
    }
    assert abs(first["realistic"] - first["click"]) <= 3


def test_animate_and_page_read_a_simulation_file(recorded_ds, tmp_path):
    source = tmp_path / "run.nc"
    write_netcdf(recorded_ds, source)
    gif = tmp_path / "a.gif"
    html = tmp_path / "a.html"
    assert main(["animate", str(source), "--fps", "4", "--speedup", "4", "--end", "4",
                 "--dpi", "30", "--out", str(gif)]) == 0  # fmt: skip
    assert main(["page", str(source), "--out", str(html)]) == 0
    assert gif.stat().st_size > 0 and html.stat().st_size > 0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["listen", "missing.nc"], "does not exist"),
        (["page", "{nc}", "--n", "5"], "not both"),
        (["animate", "{nc}", "--run", "3"], "`run`"),
        (["listen", "{bare}"], "no trajectories"),
        (["listen", "{nc}", "--out", "ticks.mp3"], "must end in .wav"),
        (["page", "{nc}", "--out", "run.txt"], "must end in .html"),
        (["animate", "{nc}", "--out", "run.png"], "must end in .gif, .mp4"),
        (["animate", "{nc}", "--out", "{nc}/a.gif"], "is not a directory"),
    ],
)
def test_errors_are_reported_with_exit_code_2(recorded_ds, tmp_path, capsys, argv, message):
    import metrosync

    nc, bare = tmp_path / "run.nc", tmp_path / "bare.nc"
    write_netcdf(recorded_ds, nc)
    write_netcdf(metrosync.simulate(2, 192.0, duration=1.0), bare)
    argv = [a.format(nc=nc, bare=bare) for a in argv]
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_a_bad_time_step_is_reported_by_simulate(tmp_path, capsys):
    assert main(["page", *SMALL, "--dt", "0", "--out", str(tmp_path / "x.html")]) == 2
    assert "`dt` = 0.0 s does not resolve" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("speedup", "message"),
    [
        ("1e6", "`speedup` = 1e+06 brings a metronome's ticks 0.312 µs apart"),
        ("1e-6", "`speedup` = 1e-06 makes 600 s of simulation last 19 years of audio"),
    ],
)
def test_listen_refuses_a_useless_speedup_before_simulating(
    tmp_path, capsys, monkeypatch, speedup, message
):
    from metrosync.cli import _show_source

    def no_simulation(args):
        raise AssertionError("simulated before refusing")

    monkeypatch.setattr(_show_source, "simulate_from_args", no_simulation)
    assert main(["listen", "--speedup", speedup, "--out", str(tmp_path / "t.wav")]) == 2
    assert message in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--dpi", "1e6"], "`dpi` = 1e+06 makes 8 x 4 in frames of 8000000 x 4000000 pixels"),
        (["--fps", "60"], "`fps` = 60 is faster than a GIF can play"),
        (["--speedup", "0.001"], "9000001 frames exceed 20000; raise `speedup`"),
    ],
)
def test_animate_refuses_impossible_options_before_simulating(
    tmp_path, capsys, monkeypatch, argv, message
):
    from metrosync.cli import _show_source

    def no_simulation(args):
        raise AssertionError("simulated before refusing")

    monkeypatch.setattr(_show_source, "simulate_from_args", no_simulation)
    assert main(["animate", *argv, "--out", str(tmp_path / "a.gif")]) == 2
    assert message in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_animate_defaults_pick_a_speedup_and_say_so(tmp_path, capsys):
    out = tmp_path / "a.gif"
    assert main(["animate", *SMALL[:2], "--duration", "45", "--dpi", "30", "--out", str(out)]) == 0
    assert "(338 frames at 15 fps, speed-up 2, 23 s)" in capsys.readouterr().out

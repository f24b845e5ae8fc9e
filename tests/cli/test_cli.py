"""The command line as a user meets it: help, outputs, errors, warnings."""

import errno
import re
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

from metrosync.cli import SUBCOMMANDS, main, name_options


def test_simulate_writes_netcdf_and_plot(tmp_path, capsys):
    out, png = tmp_path / "r.nc", tmp_path / "r.png"
    code = main(["simulate", "--n", "3", "--runs", "2", "--duration", "10", "--save-every", "5",
                 "--theta0", "0.1,0,-0.1", "--out", str(out), "--plot", str(png)])  # fmt: skip
    assert code == 0
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert {"r", "r_crossing", "r_eq", "status", "theta", "theta_dot", "phi", "phi_dot"} <= set(ds)
    assert png.stat().st_size > 1000
    text = capsys.readouterr().out
    assert "equilibrium r" in text and "oscillator-steps/s" in text


def test_presets_lists_both_with_values(capsys):
    assert main(["presets"]) == 0
    text = capsys.readouterr().out
    assert "boda2013" in text and "default" in text and "OVERTURNS" in text and "0.0006" in text


def test_bad_input_is_a_clear_error_not_a_traceback(capsys):
    assert main(["simulate", "--bpm", "400", "--duration", "1"]) == 2
    assert "`bpm` = 400 is outside the tunable range" in capsys.readouterr().err
    assert main(["simulate", "--set", "drive", "--duration", "1"]) == 2
    assert "NAME=VALUE" in capsys.readouterr().err


def _help(argv, capsys) -> str:
    with pytest.raises(SystemExit) as stop:
        main([*argv, "--help"])
    assert stop.value.code == 0
    return capsys.readouterr().out


@pytest.mark.parametrize(
    "argv",
    [[name] for name in SUBCOMMANDS] + [["calibrate", q] for q in ("c-theta", "drive", "c-phi")],
)
def test_help_shows_each_default_once_and_only_real_ones(argv, capsys):
    text = " ".join(_help(argv, capsys).split())  # undo line wrapping
    assert "(default: None)" not in text and "(default: [])" not in text
    assert "(default: False)" not in text
    assert not re.search(r"\(default [^:]", text), "a default written by hand and by argparse"
    if argv == ["simulate"]:
        assert "--runs RUNS independent runs (default: 20; 1 with --n 1 or --theta0)" in text
        assert "--integrator {verlet,located,exact} verlet: the paper's fixed-step" in text


def test_show_commands_default_to_one_run(capsys):
    assert "--runs RUNS independent runs (default: 1)" in " ".join(
        _help(["listen"], capsys).split()
    )


def test_errors_name_the_option_that_set_the_argument(tmp_path, capsys):
    assert main(["simulate", "--sigma", "-1", "--duration", "1"]) == 2
    assert "`sigma_bpm` (--sigma) must be >= 0" in capsys.readouterr().err
    assert main(["simulate", "--save-every", "0", "--duration", "1"]) == 2
    assert "`record_every` (--save-every)" in capsys.readouterr().err
    argv = ["simulate", "--duration", "1", "--lightgate-dir", str(tmp_path), "--gate-counter-bits"]
    assert main([*argv, "4"]) == 2
    assert "`counter_bits` (--gate-counter-bits)" in capsys.readouterr().err
    assert name_options("`n` and `sigma_bpm`", {"sigma_bpm": "--sigma"}) == (
        "`n` and `sigma_bpm` (--sigma)"
    )


def test_bad_outputs_are_refused_before_any_simulation(tmp_path, capsys, monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("simulated although an output was bad")

    monkeypatch.setattr(sys.modules["metrosync.simulate"], "simulate", boom)
    out = tmp_path / "r.nc"
    assert main(["simulate", "--out", str(out), "--plot", str(tmp_path / "r.xyz")]) == 2
    assert "`--plot`" in (err := capsys.readouterr().err) and "must end in" in err and ".png" in err
    assert main(["simulate", "--out", str(tmp_path / "r.png")]) == 2
    assert "`--out` " in (err := capsys.readouterr().err) and "must end in .nc" in err
    a_file = tmp_path / "file"
    a_file.write_text("")
    assert main(["simulate", "--out", str(a_file / "r.nc")]) == 2
    assert "is not a directory" in capsys.readouterr().err
    assert main(["simulate", "--out", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err
    assert main(["simulate", "--lightgate-dir", str(a_file)]) == 2
    assert "`--lightgate-dir`" in capsys.readouterr().err
    assert not out.exists()


def test_a_failed_write_is_one_line_and_leaves_no_partial_file(tmp_path, capsys, monkeypatch):
    def full_disk(self, path, *args, **kwargs):
        Path(path).write_bytes(b"half a file")
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_disk)
    log = Path(__file__).parent.parent / "data" / "clean.log"
    assert main(["analyze", str(log), "--out", str(tmp_path / "a.nc")]) == 1
    err = capsys.readouterr().err
    assert "No space left on device" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_warnings_are_one_line(capsys):
    assert main(["simulate", "--preset", "boda2013", "--n", "2", "--runs", "1",
                 "--duration", "1"]) == 0  # fmt: skip
    err = capsys.readouterr().err
    assert "metrosync simulate: warning:" in err and "overturn" in err
    assert "warnings.warn" not in err


def test_a_closed_output_pipe_ends_quietly():
    log = Path(__file__).parent.parent / "data" / "clean.log"
    code = f"from metrosync.cli import main; raise SystemExit(main(['analyze', {str(log)!r}]))"
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)  # fmt: skip
    child.stdout.close()  # like `metrosync analyze ... | head -0`
    with child.stderr:
        err = child.stderr.read()
    assert child.wait() == 1
    assert "Traceback" not in err and "Exception ignored" not in err and "error" not in err


def test_options_that_would_be_ignored_are_not_silent(capsys):
    assert main(["simulate", "--gate-jitter", "1e-4", "--duration", "1"]) == 2
    assert "`--gate-jitter` sets up the virtual light gate" in capsys.readouterr().err
    argv = ["simulate", "--integrator", "exact", "--backend", "numpy", "--n", "2", "--runs", "1"]
    assert main([*argv, "--duration", "0.2"]) == 0
    assert "`--backend numpy` applies to `--integrator verlet` only" in capsys.readouterr().err


def test_a_warning_raised_twice_is_shown_once(monkeypatch, capsys):
    import warnings

    from metrosync import cli

    def twice(args) -> int:
        for _ in range(2):  # as a size check before the work and again inside it
            warnings.warn("the animation is estimated to take about 15 min", stacklevel=2)
        warnings.warn("something else", stacklevel=2)
        return 0

    parser = cli.build_parser()
    args = parser.parse_args(["presets"])
    args.func = twice
    monkeypatch.setattr(cli.argparse.ArgumentParser, "parse_args", lambda self, argv=None: args)
    assert cli.main(["presets"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "metrosync presets: warning: the animation is estimated to take about 15 min",
        "metrosync presets: warning: something else",
    ]


def test_simulate_groups_from_the_command_line(tmp_path, capsys):
    out, plot = tmp_path / "g.nc", tmp_path / "g.png"
    argv = ["simulate", "--group", "2@184", "--group", "3@200:0.5", "--runs", "2",
            "--duration", "6", "--out", str(out), "--plot", str(plot)]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "N=5 in groups 2@184:0.75 3@200:0.5" in text
    assert "group 0 (2@184:0.75):" in text and "group 1 (3@200:0.5):" in text
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.group_bpm.values.tolist() == [184.0, 200.0]
        assert ds.group_sigma_bpm.values.tolist() == [0.75, 0.5]
        assert ds.r_group.dims == ("time", "run", "group")
    assert plot.stat().st_size > 0


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--group", "7"], "argument --group: expected N@BPM or N@BPM:SIGMA"),
        (["--group", "7@184:x"], "argument --group: BPM and SIGMA must be numbers"),
        (["--group", "7@184", "--n", "7"], "`--group` sets the number and BPM .* drop --n"),
        (["--group", "7@184", "--bpm", "184"], "drop --bpm"),
        (["--group", "7@900"], r"`groups` \(--group\) entry 0 \(7@900:0.75\) has BPM 900,"),
        (
            ["--group", "5@184", "--group", "5@200", "--lightgate-dir", "x"],
            r"at most 8 gates, got 10 metronomes \(--group\)",
        ),
    ],
)
def test_bad_groups_on_the_command_line_name_the_option(argv, message, capsys, tmp_path):
    argv = [str(tmp_path / "logs") if item == "x" else item for item in argv]
    try:
        code = main(["simulate", *argv, "--duration", "1"])
    except SystemExit as done:  # argparse's own errors
        code = done.code
    assert code == 2
    assert re.search(message, capsys.readouterr().err)

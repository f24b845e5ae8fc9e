"""What `simulate` does at its defaults, and what its messages blame."""

import pytest
import xarray as xr

import metrosync
from metrosync import OverturnWarning, ParameterError, simulate
from metrosync.cli import main


def test_version_option_prints_the_package_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"metrosync {metrosync.__version__}"


def test_one_metronome_takes_no_spread_and_one_run(tmp_path, capsys):
    out = tmp_path / "one.nc"
    assert main(["simulate", "--n", "1", "--duration", "4", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "sigma=0.0 BPM (one metronome), 1 run (one metronome) x 4 s" in text
    assert "1 runs" not in text
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert ds.sizes["run"] == 1 and float(ds.frequency_bpm[0, 0]) == pytest.approx(192.0)


def test_explicit_initial_conditions_imply_one_run_without_spread(tmp_path, capsys):
    out = tmp_path / "z.nc"
    argv = ["simulate", "--n", "2", "--theta0", "0.1,-0.05", "--duration", "3", "--out", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "sigma=0.0 BPM (explicit --theta0), 1 run (explicit --theta0)" in text
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert ds.sizes["run"] == 1 and ds.attrs["sigma_bpm"] == 0.0
    # What is given is kept.
    assert main([*argv, "--runs", "2", "--sigma", "0.5"]) == 0
    text = capsys.readouterr().out
    assert "sigma=0.5 BPM, 2 runs x 3 s" in text
    assert xr.load_dataset(out, engine="h5netcdf").sizes["run"] == 2


def test_a_plain_ensemble_keeps_the_papers_defaults(capsys):
    assert main(["simulate", "--n", "3", "--duration", "2"]) == 0
    assert "sigma=0.75 BPM, 20 runs x 2 s" in capsys.readouterr().out


def test_the_summary_states_the_tick_rate_below_the_nominal_bpm(capsys):
    assert main(["simulate", "--n", "1", "--duration", "20"]) == 0
    text = capsys.readouterr().out
    line = next(li for li in text.splitlines() if "tick rate" in li)
    low = float(line.split(": ")[1].split(" ..")[0])
    assert 184.0 < low < 185.2 and "small-swing frequency" in line


def test_an_overturning_start_warns_and_prints_no_equilibrium_r(capsys):
    assert main(["simulate", "--amplitude", "2", "--runs", "3", "--duration", "3"]) == 0
    captured = capsys.readouterr()
    assert "warning: `amplitude` = 2.0 rad is beyond `overturn_angle`" in captured.err
    assert "3 of 3 runs start overturned" in captured.err
    out = captured.out
    assert "crossing phases): not meaningful, every run is flagged" in out
    assert "runs flagged: 3 of 3 (3 overturned, 0 diverged, 0 stopped)" in out
    assert "not meaningful" in out.split("runs flagged")[1]
    assert "final r" not in out


def test_an_overturning_start_warns_in_python_too():
    with pytest.warns(OverturnWarning, match=r"`amplitude` = 2.0 rad .* 2 of 2 run"):
        simulate(2, 192.0, runs=2, duration=1.0, amplitude=2.0)
    with pytest.warns(OverturnWarning, match=r"`theta0`, `theta_dot0`\) swings up to 1.8"):
        simulate(2, 192.0, duration=1.0, theta0=[1.8, 0.1])


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--duration", "0.001"], "`duration` = 0.001 s is shorter than one time step"),
        (
            ["--duration", "0.05"],
            "`duration` = 0.05 s is shorter than the default recording "
            "interval (0.1 s, 10 steps of 0.01 s); lengthen `duration`, or give `record_every` "
            "(--save-every) <= 5 steps.",
        ),
        (
            ["--duration", "0.05", "--save-every", "8"],
            "`record_every` (--save-every) = 8 steps exceeds the 5 steps",
        ),
    ],
)
def test_a_too_short_run_blames_what_was_given(argv, expected, capsys):
    assert main(["simulate", *argv]) == 2
    err = capsys.readouterr().err
    assert expected in err
    if "--save-every" not in argv:
        assert "`record_every` (--save-every) =" not in err


def test_the_l2_bounds_suggestion_is_one_that_set_accepts(capsys):
    assert main(["simulate", "--bpm", "80", "--duration", "1"]) == 2
    err = capsys.readouterr().err
    assert "widen `l2_bounds` (--set l2_bounds=LOW,HIGH) to (0, 0.1024) m" in err
    argv = ["simulate", "--bpm", "80", "--sigma", "0", "--runs", "1", "--duration", "1"]
    assert main([*argv, "--set", "l2_bounds=0,0.1024"]) == 0
    assert "natural frequencies (small swing): 80.000" in capsys.readouterr().out
    # Above the fastest setting no bounds help, and the message does not pretend.
    assert main(["simulate", "--bpm", "250", "--duration", "1"]) == 2
    err = capsys.readouterr().err
    assert "no slider position beats faster than 236.72 BPM" in err
    assert "widen" not in err and "`l1` (--set l1=METRES)" in err
    assert main(["simulate", "--set", "l2_bounds=0.1", "--duration", "1"]) == 2
    assert "`--set l2_bounds` takes two numbers LOW,HIGH, got '0.1'" in capsys.readouterr().err


def test_explicit_frequencies_must_agree_with_n_and_sigma():
    with pytest.raises(ParameterError, match=r"`n` = 3 but `frequencies_bpm` gives 2 metronome"):
        simulate(n=3, frequencies_bpm=[190, 192], duration=1.0)
    with pytest.raises(ParameterError, match=r"`sigma_bpm` = 0.5 has no effect"):
        simulate(None, None, frequencies_bpm=[190, 192], sigma_bpm=0.5, duration=1.0)
    with pytest.raises(ParameterError, match=r"^`frequencies_bpm\[1\]` = 400 is outside"):
        simulate(None, None, frequencies_bpm=[190, 400], duration=1.0)
    with pytest.raises(ParameterError, match=r"^`frequencies_bpm\[1\]\[0\]` = 300 is outside"):
        simulate(None, None, runs=2, frequencies_bpm=[[190, 192], [300, 192]], duration=1.0)
    ds = simulate(2, None, frequencies_bpm=[190, 192], duration=1.0)
    assert ds.sizes["metronome"] == 2


@pytest.mark.parametrize("sigma", [None, "0.5", float("nan"), -1.0])
def test_a_bad_sigma_is_a_parameter_error(sigma):
    with pytest.raises(ParameterError, match=r"`sigma_bpm` must be >= 0 BPM"):
        simulate(2, 192.0, sigma_bpm=sigma, duration=1.0)


def test_api_and_cli_document_their_different_defaults(capsys):
    doc = " ".join(simulate.__doc__.split())
    assert "(σ = 0.75 BPM, 20 runs)" in doc and "(σ = 0, one run)" in doc
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "metrosync.simulate defaults to one run of identical metronomes" in help_text
    assert "(default: 0.75, the paper's; 0 with --n 1 or --theta0)" in help_text

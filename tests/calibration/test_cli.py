"""`metrosync calibrate`."""

from __future__ import annotations

import math

import pytest

from metrosync import MetronomeDesign, simulate
from metrosync._files import write_netcdf
from metrosync.calibration import c_theta_from_trajectory
from metrosync.cli import main


def test_calibrate_drive_prints_and_plots(tmp_path, capsys):
    png = tmp_path / "m.png"
    assert (
        main(["calibrate", "drive", "--amplitude", "0.7", "--c-theta", "5e-5", "--plot", str(png)])
        == 0
    )
    assert capsys.readouterr().out.startswith("M = ")
    assert png.stat().st_size > 1000


def test_calibrate_c_phi_refusal_is_a_clean_error(capsys):
    argv = ["calibrate", "c-phi", "--amplitude", "1.0", "--c-theta", "5e-5", "--drive", "6e-5"]
    assert main(argv) == 2
    assert "no c_phi" in capsys.readouterr().err


@pytest.fixture(scope="module")
def decay_file(tmp_path_factory):
    """A free decay whose metronome is not tuned to 192 BPM (σ = 3 BPM)."""
    path = tmp_path_factory.mktemp("decay") / "decay.nc"
    ds = simulate(1, 192.0, sigma_bpm=3.0, seed=4, duration=8.0, record_every=1,
                  trajectories=True, theta0=[0.8], theta_dot0=[0.0], progress=False,
                  changes={"drive": 0.0, "inertia": math.inf})  # fmt: skip
    write_netcdf(ds, path)
    return path, ds


def test_c_theta_from_a_trajectory_uses_the_files_metronome(decay_file, capsys):
    path, ds = decay_file
    metronome = MetronomeDesign().with_l2(float(ds.l2[0, 0]))
    expected = c_theta_from_trajectory(ds.time.values, ds.theta.values[:, 0, 0],
                                       metronome=metronome)  # fmt: skip
    assert abs(float(ds.frequency_bpm[0, 0]) - 192.0) > 0.5
    assert main(["calibrate", "c-theta", "--trajectory", str(path)]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith(f"c_theta = {expected.value:.6g} kg m²/s")
    assert "warning" not in captured.err


def test_c_theta_warns_about_a_driven_run_and_refuses_log_options(decay_file, tmp_path, capsys):
    driven = tmp_path / "driven.nc"
    write_netcdf(simulate(2, 192.0, duration=10.0, record_every=1, trajectories=True,
                          progress=False), driven)  # fmt: skip
    assert main(["calibrate", "c-theta", "--trajectory", str(driven), "--channel", "1"]) == 0
    assert "not a free decay on a rigid support" in capsys.readouterr().err
    path, _ = decay_file
    for extra, message in ((["--offset", "0.1"], "`--offset` applies to `--log` only"),
                           (["--channel", "3"], "`--channel` 3 is out of range"),
                           (["--run", "1"], "`--run` 1 is out of range")):  # fmt: skip
        assert main(["calibrate", "c-theta", "--trajectory", str(path), *extra]) == 2
        assert message in capsys.readouterr().err
    assert main(["calibrate", "c-theta", "--trajectory", str(tmp_path / "none.nc")]) == 2
    assert "cannot read trajectory" in capsys.readouterr().err

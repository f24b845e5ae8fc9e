"""`metrosync calibrate`."""

from __future__ import annotations

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

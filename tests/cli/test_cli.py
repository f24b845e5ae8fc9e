import xarray as xr

from metrosync.cli import main


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
    assert "`bpm` = 400.0 is outside the tunable range" in capsys.readouterr().err
    assert main(["simulate", "--set", "drive", "--duration", "1"]) == 2
    assert "NAME=VALUE" in capsys.readouterr().err

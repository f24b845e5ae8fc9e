"""``metrosync sweep`` and ``metrosync critical`` from the command line."""

import numpy as np
import pytest
import xarray as xr

from metrosync.cli import main


def test_sweep_then_critical(tmp_path, capsys, monkeypatch):
    out = tmp_path / "s.nc"
    args = ["sweep", "--bpm", "184:192:2", "--n", "2,3", "--runs", "4", "--duration", "5",
            "--set", "c_phi=2e-5", "--out", str(out), "--no-progress"]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "10 computed, 0 reused" in text and "oscillator-steps/s" in text
    assert (tmp_path / "s.points" / "points").is_dir()
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.r_eq.dims == ("n", "bpm", "run") and ds.attrs["fixed_c_phi"] == 2e-5
    assert main(args) == 0
    assert "0 computed, 10 reused" in capsys.readouterr().out

    here = tmp_path / "here"  # the default figure goes to the working folder, not the sweep's
    here.mkdir()
    monkeypatch.chdir(here)
    assert main(["critical", str(out), "--bootstrap", "50", "--out", str(tmp_path / "c.nc")]) == 0
    text = capsys.readouterr().out
    assert "omega_c (sigma_r peak)" in text and "N -> inf (peak)" in text
    assert (here / "s_critical.png").stat().st_size > 0 and "wrote s_critical.png" in text
    assert not (tmp_path / "s_critical.png").exists()
    with xr.open_dataset(tmp_path / "c.nc", engine="h5netcdf") as c:
        assert c.omega_c_peak.dims == ("n",) and c.omega_c_peak.attrs["units"] == "BPM"
        assert [name for name in c.variables if "long_name" not in c[name].attrs] == []


def test_grid_file_with_overrides(tmp_path, capsys):
    grid = tmp_path / "g.toml"
    grid.write_text('[grid]\nbpm = "186:190:2"\n[fixed]\nn = 2\nruns = 2\nduration = 5\n')
    out = tmp_path / "g.nc"
    assert main(["sweep", str(grid), "--sigma", "0,0.5", "--out", str(out), "--no-progress"]) == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert dict(ds.sizes) == {"bpm": 3, "sigma_bpm": 2, "run": 2}


def test_errors_are_reported_not_raised(tmp_path, capsys):
    out = str(tmp_path / "x.nc")
    assert main(["sweep", "--bpm", "150:220", "--out", out]) == 2
    assert "START:STOP:STEP" in capsys.readouterr().err
    assert main(["sweep", "--runs", "4", "--out", out]) == 2
    assert "nothing to sweep" in capsys.readouterr().err
    assert main(["sweep", "--bpm", "180,190", "--set", "colour=1", "--out", out]) == 2
    assert "unknown sweep parameter 'colour'" in capsys.readouterr().err
    assert (
        main(["sweep", "--bpm", "180,190", "--drive", "1e-4", "--set", "M=2e-4", "--out", out]) == 2
    )
    assert "`drive` is given twice ('1e-4' and '2e-4'" in capsys.readouterr().err
    assert main(["critical", str(tmp_path / "missing.nc")]) == 2
    assert "cannot read sweep" in capsys.readouterr().err


def test_ignored_or_failing_settings_are_not_silent(tmp_path, capsys):
    out = str(tmp_path / "x.nc")
    base = ["sweep", "--bpm", "186,190", "--runs", "1", "--duration", "2", "--no-progress"]
    assert main([*base, "--workers", "2", "--out", out]) == 2
    assert "`n_workers` (--workers) = 2 applies to scheduler='local' only" in (
        capsys.readouterr().err
    )
    assert main([*base, "--dt", "0.5", "--out", out]) == 1  # every point fails: not a success
    assert "2 points without a result" in capsys.readouterr().out


def test_critical_marks_estimates_at_the_end_of_the_grid(tmp_path, capsys):
    bpm = np.arange(180.0, 190.5, 2.0)
    rng = np.random.default_rng(0)
    x = (bpm - 180)[None, :, None]  # r rises ever faster and scatters ever more: up to 190
    r = 0.2 + 0.006 * x**2 + rng.normal(0, 1, (1, 6, 40)) * (0.002 + 0.01 * x)
    path = tmp_path / "rising.nc"
    xr.Dataset({"r_eq": (("n", "bpm", "run"), r)}, coords={"n": [7], "bpm": bpm}).to_netcdf(
        path, engine="h5netcdf"
    )
    assert main(["critical", str(path), "--bootstrap", "20", "--no-plot"]) == 0
    assert "* at an end of the bpm grid (180 .. 190 BPM)" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["critical", str(path), "--no-plot", "--plot", str(tmp_path / "c.png")])


def test_sweep_the_offset_between_two_groups(tmp_path, capsys):
    out = tmp_path / "g.nc"
    args = ["sweep", "--group", "2@184", "--group", "3@184:0.1", "--group-offset-bpm", "0,16",
            "--runs", "2", "--duration", "20", "--out", str(out), "--no-progress"]  # fmt: skip
    assert main(args) == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.r_eq_group.dims == ("group_offset_bpm", "run", "group")
        assert ds.r_eq_group_mean.shape == (2, 2) and ds.attrs["groups"] == "2@184 3@184:0.1"
        assert np.isfinite(ds.r_eq_group).all()
    assert main([*args[:-3], "--n", "3", "--out", str(out)]) == 2
    assert "drop `n` (--n)" in capsys.readouterr().err


def _scaling_sweep(path, sizes=(64, 256, 1024), seed=0):
    """r = N^(−1/5)·F((ω₀ − 185)/8·N^(2/5)) plus noise, 16 runs a point: ω_c(∞) = 185 BPM."""
    rng = np.random.default_rng(seed)
    bpm = np.arange(177.0, 193.5, 1.5)
    n = np.array(sizes)
    u = (bpm[None, :] - 185.0) / 8 * n[:, None] ** 0.4
    r = n[:, None] ** -0.2 * (0.5 / (1 + np.exp(-u)) + 0.1)
    runs = r[..., None] + rng.normal(0, 0.02, r.shape + (16,))
    xr.Dataset({"r_eq": (("n", "bpm", "run"), runs)}, coords={"n": n, "bpm": bpm}).to_netcdf(
        path, engine="h5netcdf"
    )


def test_critical_scaling_collapses_the_sweep(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the default figures go to the working folder
    path = tmp_path / "s.nc"
    _scaling_sweep(path)
    args = ["critical", str(path), "--bootstrap", "20", "--scaling", "kuramoto",
            "--out", str(tmp_path / "c.nc")]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "collapse over N = [64, 256, 1024] (exponents fixed at 1/5, 2/5" in text
    assert "omega_c(inf) = " in text and "fit windows and N sets" in text
    assert (tmp_path / "s_collapse.png").stat().st_size > 1000
    with xr.open_dataset(tmp_path / "c.nc", engine="h5netcdf") as c:
        value, err = c.attrs["scaling_omega_c_inf"], c.attrs["scaling_omega_c_inf_err"]
    assert 0 < err < 1.0 and abs(value - 185.0) < 3 * err
    plot = tmp_path / "mine.png"
    args = ["critical", str(path), "--bootstrap", "20", "--scaling", "free", "--no-plot"]
    assert main(args) == 0
    assert "beta/nu = " in capsys.readouterr().out
    assert not (tmp_path / "s_critical.png").with_name("mine.png").exists()
    assert main(["critical", str(path), "--collapse-plot", str(plot)]) == 2
    assert "`--collapse-plot` needs `--scaling" in capsys.readouterr().err
    args = ["critical", str(path), "--scaling", "free", "--no-plot", "--collapse-plot", str(plot)]
    assert main(args) == 2
    assert "`--collapse-plot` and `--no-plot` exclude each other" in capsys.readouterr().err


def test_critical_scaling_needs_two_sizes(tmp_path, capsys):
    path = tmp_path / "one.nc"
    _scaling_sweep(path, sizes=(64,))
    assert main(["critical", str(path), "--bootstrap", "20", "--scaling", "kuramoto"]) == 2
    assert "at least 2 sizes N" in capsys.readouterr().err

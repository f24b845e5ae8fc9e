"""`metrosync analyze` and `metrosync simulate --lightgate-dir`."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from metrosync.cli import main

DATA = Path(__file__).parent.parent / "data"


def test_analyze_writes_dataset_and_plot(tmp_path, capsys):
    out, png = tmp_path / "r.nc", tmp_path / "r.png"
    assert main(["analyze", str(DATA / "messy.log"), "--out", str(out), "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "sigma =" in text and "equilibrium r" in text and "skipped 10 lines" in text
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert set(ds.r.dims) == {"time"} and ds.frequency_bpm.dims == ("metronome",)
        assert "r_eq" in ds.attrs and "sigma_bpm" in ds.attrs
        assert [name for name in ds.variables if "long_name" not in ds[name].attrs] == []
        assert ds.counter_wraps.values.tolist() == [5]  # as the report says
        assert ds.interrupted_level.values.tolist() == [[0, 0, 0]]
    assert png.stat().st_size > 1000


def test_analyze_reports_bad_logs_as_errors(tmp_path, capsys):
    bad = tmp_path / "bad.log"
    bad.write_text("hello\n")
    assert main(["analyze", str(bad)]) == 2
    assert "error" in capsys.readouterr().err


def test_simulate_writes_one_log_per_run(tmp_path, capsys):
    logs, out = tmp_path / "logs", tmp_path / "s.nc"
    argv = ["simulate", "--n", "3", "--runs", "2", "--duration", "20", "--sigma", "0.5",
            "--lightgate-dir", str(logs), "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert sorted(p.name for p in logs.iterdir()) == ["run000.log", "run001.log"]
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert "theta" not in ds and abs(float(ds.time[1]) - 0.1) < 1e-9
    assert main(["analyze", *map(str, sorted(logs.iterdir()))]) == 0


def test_analyze_options_are_checked_with_their_names(capsys):
    log = str(DATA / "clean.log")
    with pytest.raises(SystemExit):
        main(["analyze", log, "--channels", "a"])
    assert "argument --channels: expected comma-separated whole numbers" in (
        capsys.readouterr().err
    )
    assert main(["analyze", log, "--window", "1000"]) == 2
    assert "`equilibrium_window` (--window) must be in (0, 19.2] s" in capsys.readouterr().err

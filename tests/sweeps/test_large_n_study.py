"""The large-N study's grid files, and its quick form run end to end (machinery only)."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from metrosync.cli import main
from metrosync.sweeps import Grid

STUDY = Path(__file__).resolve().parents[2] / "studies" / "large_n"


@pytest.mark.parametrize(("name", "sigma"), [("sigma_0.75.toml", 0.75), ("sigma_star.toml", 1.01)])
def test_full_grids_sweep_the_large_sizes_around_the_onset(name, sigma):
    grid = Grid.from_toml(STUDY / name)
    assert grid.integrator == "located"
    assert grid.axes["n"] == (64, 256, 1024, 4096)
    assert grid.fixed["sigma_bpm"] == sigma
    assert grid.target_error <= 0.01 and grid.max_runs >= 336  # a spread of 0.18 near the onset
    assert grid.fixed["dt"] <= 0.02  # located at 0.04 loses the onset (REPORT.md)
    bpm = np.array(grid.axes["bpm"])
    assert bpm.size >= 7 and np.ptp(bpm) >= 20


def test_quick_form_runs_the_machinery_end_to_end(tmp_path, capsys, monkeypatch):
    out = tmp_path / "quick.nc"
    args = ["sweep", str(STUDY / "quick.toml"), "--out", str(out), "--no-progress"]
    assert main(args) == 0
    first = capsys.readouterr().out
    assert "batches computed, 0 reused" in first and "standard error of mean r_eq" in first
    assert main(args) == 0  # resumable: a second run reuses every stored batch
    assert " 0 batches computed" in capsys.readouterr().out
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.r_eq.dims == ("n", "bpm", "run") and ds.sizes["run"] == 18
        assert ds.n_runs.values.min() == 6 and ds.n_runs.values.max() == 18
        assert ds.attrs["integrator"] == "located"
    result = tmp_path / "c.nc"
    args = ["critical", str(out), "--scaling", "kuramoto", "--bootstrap", "20",
            "--out", str(result)]  # fmt: skip
    monkeypatch.chdir(tmp_path)
    assert main(args) == 0
    assert "omega_c(inf) = " in capsys.readouterr().out
    assert (tmp_path / "quick_collapse.png").stat().st_size > 1000
    with xr.open_dataset(result, engine="h5netcdf") as c:
        assert np.isfinite(c.attrs["scaling_omega_c_inf"])
        assert c.attrs["scaling_exponents"] == "kuramoto"

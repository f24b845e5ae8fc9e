"""Point store and merge: atomic files, failed and missing points, sweeps reusing points."""

import numpy as np
import pytest
import xarray as xr

from metrosync import sweep
from metrosync.status import STATUS_ABSENT, STATUS_FAILED
from metrosync.sweeps import Grid, PointStore, merge

TINY = {"runs": 3, "duration": 5.0, "sigma": 0.5}


def test_points_are_complete_files_named_by_key(tmp_path):
    result = sweep({"bpm": [185, 190], "n": [2, 3]}, tmp_path, fixed=TINY)
    store = PointStore(tmp_path)
    names = sorted(p.name for p in store.points.iterdir())
    assert names == sorted(f"{p.key}.nc" for p in result.grid.points())  # no partial files left
    assert sorted(store.logged_keys()) == sorted(p.key for p in result.grid.points())
    ds = result.dataset
    assert ds.r_eq.dims == ("bpm", "n", "run") and ds.r_eq_mean.dims == ("bpm", "n")
    assert ds.bpm.attrs["units"] == "BPM" and ds.attrs["fixed_runs"] == 3
    assert ds.attrs["model_c_phi"] == 1e-5 and ds.attrs["metrosync_version"]
    assert np.all(ds.status == 0) and np.all(ds.error == "")
    assert np.all(np.isfinite(ds.r_eq)) and np.all((ds.r_eq >= 0) & (ds.r_eq <= 1))
    # the stored per-run values are exactly what simulate gives for that point
    from metrosync import simulate

    spec = next(result.grid.points())
    direct = simulate(**spec.kwargs, progress=False)
    one = ds.isel(bpm=0, n=0)
    np.testing.assert_array_equal(one.r_eq.values, direct.r_eq.values)
    assert float(one.r_eq_std) == direct.attrs["r_eq_std"]


def test_a_failing_point_is_recorded_and_the_sweep_goes_on(tmp_path):
    # at 236 BPM, a spread of 5 BPM draws frequencies beyond the tunable range
    result = sweep({"bpm": [190, 236]}, tmp_path, fixed={**TINY, "sigma": 5.0})
    ds = result.dataset
    assert ds.error.sel(bpm=190).item() == ""
    assert "tunable range" in ds.error.sel(bpm=236).item()
    assert np.all(ds.status.sel(bpm=236) == STATUS_FAILED)
    assert np.all(np.isfinite(ds.r_eq.sel(bpm=190)))
    assert "1 point without a result" in result.summary()
    assert "bpm=236.0" in result.summary()
    again = sweep({"bpm": [190, 236]}, tmp_path, fixed={**TINY, "sigma": 5.0})
    assert again.execution.computed == []
    retried = sweep({"bpm": [190, 236]}, tmp_path, fixed={**TINY, "sigma": 5.0}, retry_failed=True)
    assert len(retried.execution.computed) == 1


def test_missing_points_are_marked_and_shorter_runs_padded(tmp_path):
    grid = Grid(axes={"runs": [2, 3]}, fixed={"duration": 5.0})
    sweep(grid, tmp_path)
    store = PointStore(tmp_path)
    ds = merge(grid, store)
    assert ds.sizes["run"] == 3
    assert ds.status.sel(runs=2, run=2).item() == STATUS_ABSENT
    assert np.isnan(ds.r_eq.sel(runs=2, run=2).item())
    first = next(grid.points())
    store.path(first.key).unlink()
    assert merge(grid, store).error.sel(runs=2).item() == "missing"


def test_keep_r_and_netcdf_round_trip(tmp_path):
    out = tmp_path / "sweep.nc"
    result = sweep({"bpm": [185, 190]}, tmp_path / "store", fixed=TINY, keep_r=True, out=out)
    ds = result.dataset
    assert ds.r.dims == ("bpm", "time", "run") and ds.time.attrs["units"] == "s"
    assert [name for name in ds.variables if "long_name" not in ds[name].attrs] == []
    assert ds.bpm.attrs == {"long_name": "nominal beat frequency", "units": "BPM"}
    with xr.open_dataset(out, engine="h5netcdf") as back:
        xr.testing.assert_identical(back.load(), ds)


def test_a_finer_grid_reuses_the_points_it_shares(tmp_path):
    coarse = sweep({"bpm": "185:195:5"}, tmp_path, fixed=TINY)
    fine = sweep({"bpm": "185:195:2.5"}, tmp_path, fixed=TINY)
    assert fine.reused == 3 and len(fine.execution.computed) == 2
    xr.testing.assert_identical(fine.dataset.r_eq.sel(bpm=[185, 190, 195]), coarse.dataset.r_eq)


def test_bad_scheduler_is_refused(tmp_path):
    from metrosync import ParameterError

    with pytest.raises(ParameterError, match="tcp://HOST:PORT"):
        sweep({"bpm": [190]}, tmp_path, fixed=TINY, scheduler="http://x")

"""Runs until the error is small enough (`Grid.target_error`): each point grows in
batches until the standard error of its mean r_eq reaches the target or `max_runs`,
resumably, and the bootstrap resamples each point among its own runs."""

import math

import numpy as np
import pytest
import xarray as xr

from metrosync import sweep
from metrosync.cli import main
from metrosync.errors import ParameterError
from metrosync.sweeps import Grid, PointStore
from metrosync.sweeps.adaptive import precision
from metrosync.sweeps.critical import critical_frequency
from metrosync.sweeps.resample import resample_runs

#: Short runs of 8 metronomes: identical ones at 200 BPM all lock (r_eq spreads by 0.01
#: runs), spread ones do not (0.1-0.2).
AXES = {"sigma_bpm": [0.0, 3.0], "bpm": [192.0, 200.0, 208.0]}
FIXED = {"n": 8, "runs": 4, "duration": 60.0, "dt": 0.02}


def grid(**options):
    return Grid(axes=AXES, fixed=FIXED, integrator="located", **options)


def test_precision_is_the_standard_error_and_the_runs_it_needs():
    values = np.array([0.1, 0.3, np.nan, 0.5, 0.7])
    p = precision(values, target=0.05)
    spread = np.std([0.1, 0.3, 0.5, 0.7], ddof=1)
    assert p.runs == 4
    assert p.error == pytest.approx(spread / 2)
    assert p.needed == pytest.approx((spread / 0.05) ** 2)
    assert math.isnan(precision(np.array([0.2, np.nan]), 0.05).error)


@pytest.fixture(scope="module")
def grown(tmp_path_factory):
    store = tmp_path_factory.mktemp("adaptive") / "store"
    result = sweep(grid(target_error=0.02, max_runs=24), store, progress=False)
    return result, store


def test_every_point_reaches_the_target_or_max_runs(grown):
    result, _ = grown
    ds = result.dataset
    runs, error = ds.n_runs.values, ds.r_eq_error.values
    assert np.all(runs % 4 == 0) and np.all((runs >= 4) & (runs <= 24))
    assert np.all((error <= 0.02) | (runs == 24))
    assert runs.min() < runs.max()  # spread metronomes need more runs
    for i in np.ndindex(runs.shape):
        n, r = runs[i], ds.r_eq.values[i]
        assert np.isfinite(r[:n]).all() and np.isnan(r[n:]).all()
        assert ds.status.values[i][n:].tolist() == [-1] * (ds.sizes["run"] - n)
        assert ds.r_eq_mean.values[i] == pytest.approx(r[:n].mean())
        assert ds.r_eq_std.values[i] == pytest.approx(r[:n].std(ddof=1))
        assert error[i] == pytest.approx(r[:n].std(ddof=1) / math.sqrt(n))
    assert ds.attrs["target_error"] == 0.02 and ds.attrs["max_runs"] == 24
    assert "runs until the standard error of mean r_eq is <= 0.02" in result.summary()


def test_batches_draw_new_frequencies_and_the_first_is_the_plain_point(grown):
    result, store = grown
    ds = result.dataset
    widest = np.unravel_index(np.argmax(ds.n_runs.values), ds.n_runs.shape)
    n = ds.n_runs.values[widest]
    assert len(set(np.round(ds.r_eq.values[widest][:n], 12))) == n
    plain = sweep(grid(), store, progress=False)  # the same grid, fixed runs: all reused
    assert plain.reused == 6 and not plain.execution.computed
    np.testing.assert_array_equal(plain.dataset.r_eq.values, ds.r_eq.values[..., :4])


def test_a_lost_batch_is_computed_again_and_the_result_is_the_same(grown):
    result, store = grown
    points = PointStore(store)
    files = sorted(points.points.glob("*.nc"))
    first = {s.key for s in grid().points()}
    later = [f for f in files if f.stem not in first]
    later[0].unlink()
    again = sweep(grid(target_error=0.02, max_runs=24), store, progress=False)
    assert len(again.execution.computed) == 1
    xr.testing.assert_identical(again.dataset, result.dataset)


def test_a_looser_target_reuses_the_stored_batches(grown):
    result, store = grown
    looser = sweep(grid(target_error=0.05, max_runs=24), store, progress=False)
    assert not looser.execution.computed
    assert np.all(looser.dataset.n_runs.values <= result.dataset.n_runs.values)


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"target_error": 0.0}, "`target_error` is the standard error"),
        ({"target_error": float("nan")}, "`target_error` is the standard error"),
        ({"target_error": 0.01, "max_runs": 3}, "`max_runs` must be a whole number >= `runs`"),
        ({"max_runs": 40}, "give `target_error` too"),
    ],
)
def test_bad_targets_name_the_argument(options, words):
    with pytest.raises(ParameterError, match=words):
        grid(**options)


def test_runs_cannot_be_swept_with_a_target():
    with pytest.raises(ParameterError, match="instead of sweeping it"):
        Grid(axes={"bpm": "160:170:5", "runs": [4, 8]}, fixed={"n": 3}, target_error=0.01)


def test_the_command_line_grows_points_and_turns_a_files_target_off(tmp_path, capsys):
    toml = tmp_path / "g.toml"
    toml.write_text(
        'integrator = "located"\ntarget_error = 0.02\nmax_runs = 12\n[grid]\nsigma = [0, 3]\n'
        "[fixed]\nn = 8\nbpm = 200\nruns = 4\nduration = 60\ndt = 0.02\n"
    )
    out = tmp_path / "g.nc"
    assert main(["sweep", str(toml), "--out", str(out), "--no-progress"]) == 0
    assert "batches computed" in capsys.readouterr().out
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.n_runs.values.max() > 4
    fixed = tmp_path / "f.nc"
    args = ["sweep", str(toml), "--target-error", "none", "--out", str(fixed), "--no-progress"]
    assert main(args) == 0
    with xr.open_dataset(fixed, engine="h5netcdf") as ds:
        assert ds.sizes["run"] == 4 and "n_runs" not in ds


def test_resampling_keeps_each_rows_own_count_and_values():
    rng = np.random.default_rng(1)
    values = np.array([[0.1, 0.2, 0.3, 0.4], [0.5, 0.6, np.nan, np.nan]])
    replicas = resample_runs(values, rng, (2000, *values.shape))
    assert replicas.shape == (2000, 2, 4)
    assert np.isfinite(replicas[:, 0]).all()
    assert np.isnan(replicas[:, 1, 2:]).all() and np.isfinite(replicas[:, 1, :2]).all()
    assert set(np.unique(replicas[:, 1, :2])) == {0.5, 0.6}
    assert np.mean(replicas[:, 1, :2]) == pytest.approx(0.55, abs=0.01)


def test_resampling_full_rows_draws_as_plain_integer_indices():
    values = np.random.default_rng(2).random((3, 5))
    got = resample_runs(values, np.random.default_rng(7), (10, 3, 5))
    idx = np.random.default_rng(7).integers(0, 5, size=(10, 3, 5))
    np.testing.assert_array_equal(
        got, np.take_along_axis(np.broadcast_to(values, idx.shape), idx, -1)
    )


def test_critical_frequency_reads_a_grown_sweep(grown):
    result, _ = grown
    ds = result.dataset.sel(sigma_bpm=0.0)
    assert ds.n_runs.values.min() < ds.sizes["run"]  # ragged: some points padded with NaN
    c = critical_frequency(ds, n_boot=50)
    assert np.isfinite(c.omega_c_peak.values).all()

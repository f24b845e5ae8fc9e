"""What a sweep refuses up front, what it accepts, and how its summary counts."""

import re

import numpy as np
import pytest
import xarray as xr

from metrosync import ParameterError, simulate, sweep
from metrosync.cli import main
from metrosync.status import STATUS_FAILED
from metrosync.sweeps import Grid

BASE = ["sweep", "--bpm", "186,190", "--runs", "2", "--duration", "2", "--no-progress"]


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--workers", "2"], "`n_workers` (--workers) = 2 applies to scheduler='local' only"),
        (["--scheduler", "foo"], "`scheduler` (--scheduler) must be None (in process), 'local'"),
        (["--scheduler", "local", "--workers", "0"], "`n_workers` (--workers) must be an integer"),
    ],
)
def test_executor_settings_are_refused_before_the_grid_is_announced(tmp_path, capsys, extra,
                                                                    expected):  # fmt: skip
    assert main([*BASE, *extra, "--out", str(tmp_path / "s.nc")]) == 2
    captured = capsys.readouterr()
    assert expected in captured.err
    assert captured.out == ""  # no "metrosync sweep: N points, grid ..." first
    assert not (tmp_path / "s.points").exists()


def test_zero_drive_without_a_start_amplitude_is_refused_up_front(tmp_path, capsys):
    argv = [*BASE, "--drive", "0,1e-4", "--out", str(tmp_path / "s.nc")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "steady swing 2M/(pi c_theta) = 0 rad at {'drive': 0.0}" in err
    assert "`amplitude` (--amplitude 0.5, or amplitude = 0.5 under [fixed]" in err
    assert "--theta0" not in err  # sweep has no such option
    assert not (tmp_path / "s.points").exists()
    # The fix it names works, and every point has a result.
    assert main([*argv, "--amplitude", "0.5"]) == 0
    with xr.open_dataset(tmp_path / "s.nc", engine="h5netcdf") as ds:
        assert np.all(ds.error == "") and ds.attrs["fixed_amplitude"] == 0.5


def test_a_swept_amplitude_is_passed_to_each_point(tmp_path):
    result = sweep({"amplitude": [0.3, 0.6]}, tmp_path, fixed={"n": 2, "runs": 2, "duration": 2})
    spec = list(result.grid.points())[1]
    assert spec.kwargs["amplitude"] == 0.6
    direct = simulate(**spec.kwargs, progress=False)
    np.testing.assert_array_equal(result.dataset.r_eq.sel(amplitude=0.6), direct.r_eq)
    assert result.dataset.amplitude.attrs["units"] == "rad"


def test_no_amplitude_leaves_earlier_point_keys_and_seeds_alone():
    spec = next(Grid(axes={"bpm": [190]}).points())
    assert "amplitude" not in spec.kwargs
    with pytest.raises(ParameterError, match="`amplitude` must be >= 0 rad"):
        Grid(axes={"bpm": [190]}, fixed={"amplitude": -1})


def test_failed_points_are_counted_apart_from_flagged_runs(tmp_path):
    # At 236 BPM a spread of 5 BPM draws untunable frequencies: that point fails;
    # amplitude 2 overturns every run of the points that do run.
    with pytest.warns(UserWarning, match="`amplitude` = 2 rad starts the pendulums past pi/2"):
        result = sweep({"bpm": [190, 236]}, tmp_path,
                       fixed={"runs": 3, "duration": 2, "sigma": 5, "amplitude": 2.0})  # fmt: skip
    ds = result.dataset
    assert np.all(ds.status.sel(bpm=236) == STATUS_FAILED)
    assert int(ds.n_flagged.sel(bpm=190)) == 3 and int(ds.n_flagged.sel(bpm=236)) == 0
    text = result.summary()
    assert "runs flagged (overturned/diverged/stopped): 3 of 3 runs simulated" in text
    assert "1 point without a result: 1 failed (the simulation raised" in text
    assert "metrosync.status" in text


def test_status_bits_are_documented_in_one_public_place():
    import metrosync.status as status

    for bit, name in status.SWEEP_FLAG_MEANINGS.items():
        assert f"{bit}      {name}" in status.__doc__
    docs = __import__("pathlib").Path(__file__).parents[2] / "docs"
    for page in ("getting-started.md", "sweeps.md"):  # the dataset's and the sweep's pages
        text = (docs / page).read_text()
        assert "every bit" in text and "`metrosync.status`" in text


def test_a_value_just_past_the_tunable_range_reads_as_outside_it(tmp_path, capsys):
    # 236.72 lies 3e-5 BPM above the top of the range; two decimals printed both as 236.72.
    argv = ["sweep", "--bpm", "100:250:0.01", "--out", str(tmp_path / "q.nc")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    found = re.search(r"= ([\d.]+) is outside the tunable range \[([\d.]+), ([\d.]+)\]", err)
    assert found, err
    value, low, high = (float(x) for x in found.groups())
    assert value > high > low
    assert not (tmp_path / "q.points").exists()

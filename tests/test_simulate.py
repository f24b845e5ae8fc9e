"""`simulate`: the dataset it returns, its validation, and the paper's first claim."""

import math

import numpy as np
import pytest
import xarray as xr

from metrosync import OverturnWarning, ParameterError, simulate


def test_dataset_layout_units_and_attrs():
    ds = simulate(3, 192, sigma_bpm=0.5, runs=2, duration=5, trajectories=True, record_every=5)
    assert ds.r.dims == ("time", "run") and ds.r_crossing.dims == ("time", "run")
    assert ds.theta.dims == ("time", "run", "metronome") and ds.phi.dims == ("time", "run")
    assert ds.r_eq.dims == ("run",) and ds.status.dims == ("run",)
    assert ds.time.attrs["units"] == "s"
    np.testing.assert_allclose(ds.time.values, np.arange(0, 5.0001, 0.05))
    for key in (
        "n",
        "bpm",
        "sigma_bpm",
        "runs",
        "dt",
        "seed",
        "drive",
        "c_theta",
        "c_phi",
        "radius",
    ):
        assert key in ds.attrs
    assert ds.attrs["drive"] == 6e-5


def test_memory_does_not_grow_with_duration_without_trajectories():
    ds = simulate(3, 192, runs=2, duration=50, record_every=100)
    assert "theta" not in ds and ds.sizes["time"] == 51


def test_netcdf_round_trip(tmp_path):
    ds = simulate(2, 192, runs=2, duration=5, trajectories=True)
    path = tmp_path / "run.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    back = xr.load_dataset(path, engine="h5netcdf")
    xr.testing.assert_identical(back.drop_attrs(), ds.drop_attrs())
    assert back.attrs["preset"] == "default"


@pytest.mark.parametrize("n", [2, 7, 64])
def test_identical_metronomes_synchronize_completely(n):
    ds = simulate(n, 192, sigma_bpm=0.0, runs=3, duration=300, seed=3)
    assert np.all(ds.r.isel(time=-1).values > 0.99)
    assert np.all(ds.r_eq.values > 0.99)


def test_explicit_frequencies_and_initial_conditions():
    ds = simulate(None, None, frequencies_bpm=[180, 190, 200], theta0=[0.1, 0.0, -0.1], duration=2)
    np.testing.assert_allclose(ds.frequency_bpm.values[0], [180, 190, 200])
    assert ds.attrs["bpm"] == "explicit"


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n": 0}, r"`n` must be an integer >= 1, got 0"),
        ({"runs": -2}, r"`runs` must be an integer >= 1"),
        ({"bpm": 400.0}, r"`bpm` = 400 is outside the tunable range"),
        ({"bpm": float("nan")}, r"`bpm` must be a finite number"),
        ({"sigma_bpm": -1.0}, r"`sigma_bpm` must be >= 0"),
        ({"sigma_bpm": 60.0}, r"drawn natural frequency .* outside the tunable range"),
        ({"dt": 0.1}, r"`dt` = 0.1 s does not resolve the shortest period"),
        ({"dt": -0.01}, r"`dt`"),
        ({"duration": float("nan")}, r"`duration` must be a finite time"),
        ({"theta0": [0.1, 0.2]}, r"`theta0` must have shape \(7,\)"),
        ({"theta0": [float("nan")] * 7}, r"`theta0` must be finite"),
        ({"theta_dot0": [0.0] * 7}, r"`theta_dot0` was given without `theta0`"),
        ({"integrator": "rk4"}, r"unknown `integrator` 'rk4'.*verlet"),
        ({"backend": "cuda"}, r"unknown `backend`"),
        ({"preset": "nope"}, r"unknown preset"),
        ({"changes": {"w1": -1.0}}, r"`w1` must be > 0"),
        ({"changes": {"c_theta": -1e-5}}, r"`c_theta` must be >= 0"),
        ({"changes": {"inertia": -1.0}}, r"`inertia` must be > 0"),
        ({"changes": {"l2_bounds": (0.0, 0.5)}}, r"inverted"),
        ({"record_every": 0}, r"`record_every` must be an integer >= 1"),
        ({"equilibrium_window": 1e6}, r"`equilibrium_window`"),
        ({"seed": -1}, r"`seed`"),
        ({"amplitude": float("inf")}, r"`amplitude`"),
    ],
)
def test_bad_input_names_the_argument_and_the_value(kwargs, match):
    args = {"n": 7, "bpm": 192.0, "duration": 1.0}
    args.update(kwargs)
    with pytest.raises(ParameterError, match=match):
        simulate(args.pop("n"), args.pop("bpm"), **args)


def test_undriven_default_amplitude_needs_an_explicit_start():
    with pytest.raises(ParameterError, match=r"without drive .*Give `amplitude`"):
        simulate(2, 192, duration=1, changes={"drive": 0.0})
    ds = simulate(2, 192, duration=1, changes={"drive": 0.0}, amplitude=0.3)
    assert float(ds.r.isel(time=0, run=0)) > 0


def test_frictionless_default_amplitude_needs_an_explicit_start():
    # Drive without friction: the energy balance has no finite amplitude.
    with pytest.warns(OverturnWarning), pytest.raises(ParameterError, match="no friction"):
        simulate(2, 192, duration=1, changes={"c_theta": 0.0})
    with pytest.warns(OverturnWarning):
        ds = simulate(2, 192, duration=1, changes={"c_theta": 0.0}, amplitude=0.3)
    assert math.isfinite(float(ds.r.isel(time=-1, run=0)))

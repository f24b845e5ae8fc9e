"""Groups of metronomes at different frequencies: construction, records, behaviour."""

import numpy as np
import pytest
import xarray as xr

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.groups import Group, as_groups, group_bounds, parse_group
from metrosync.model import bpm_to_omega
from metrosync.observables.order import analytic_phase, order_parameter


def test_two_groups_20_bpm_apart_each_synchronize_while_the_global_r_stays_lower():
    ds = simulate(None, None, groups=[(7, 184.0), (7, 204.0)], sigma_bpm=0.25, runs=8,
                  duration=300, seed=3)  # fmt: skip
    assert (ds.status == 0).all()
    r_eq_group = ds.r_eq_group.values  # (run, group)
    assert np.all(r_eq_group.mean(axis=0) > 0.85), r_eq_group
    # Two synchronized clusters drifting past each other: |e^{iψ1} + e^{iψ2}|/2 averages
    # 2/π ≈ 0.64 over a uniformly turning phase difference, well below either group.
    assert 0.5 < ds.r_eq.mean() < 0.7, ds.r_eq.values
    assert np.all(ds.r_eq.values < r_eq_group.min(axis=1) - 0.05)
    # ... and in the final window the global r beats between near 0 and near 1.
    tail = ds.r.sel(time=slice(225, None))
    assert np.all(tail.min("time") < 0.3) and np.all(tail.max("time") > 0.85)


def test_two_groups_at_the_same_bpm_are_one_group_of_2n():
    one = simulate(14, 192.0, sigma_bpm=0.75, runs=3, duration=60, seed=11)
    two = simulate(None, None, groups=[(7, 192.0), (7, 192.0)], sigma_bpm=0.75, runs=3,
                   duration=60, seed=11)  # fmt: skip
    np.testing.assert_array_equal(two.frequency_bpm, one.frequency_bpm)
    np.testing.assert_array_equal(two.r, one.r)  # the same dynamics, bit for bit
    # The crossing sums are kept per group and added: the same to rounding.
    np.testing.assert_allclose(two.r_crossing, one.r_crossing, rtol=0, atol=1e-12)
    np.testing.assert_allclose(two.r_eq, one.r_eq, rtol=0, atol=1e-12)
    assert two.attrs["r_eq_mean"] == pytest.approx(one.attrs["r_eq_mean"], abs=1e-12)


def test_group_records_are_each_groups_own_order_parameter():
    ds = simulate(None, None, groups=[(2, 186.0), (3, 198.0, 1.0)], sigma_bpm=0.5, runs=2,
                  duration=20, seed=4, trajectories=True)  # fmt: skip
    assert ds.group.values.tolist() == [0, 0, 1, 1, 1]
    assert ds.group_n.values.tolist() == [2, 3]
    assert ds.group_bpm.values.tolist() == [186.0, 198.0]
    assert ds.group_sigma_bpm.values.tolist() == [0.5, 1.0]
    assert ds.attrs["groups"] == "2@186:0.5 3@198:1" and ds.attrs["bpm"] == "groups"
    assert ds.attrs["n"] == 5
    omega = bpm_to_omega(ds.frequency_bpm.values)
    phase = analytic_phase(ds.theta.values, ds.theta_dot.values, omega)  # (time, run, metronome)
    for g in range(2):
        mine = phase[:, :, ds.group.values == g]
        np.testing.assert_allclose(ds.r_group[:, :, g], order_parameter(mine), atol=1e-12)
    np.testing.assert_allclose(ds.attrs["r_eq_group_mean"], ds.r_eq_group.mean("run"))


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_every_backend_records_the_groups(backend):
    options = dict(groups=[(2, 186.0), (3, 198.0)], sigma_bpm=0.5, runs=2, duration=8, seed=4)
    ref = simulate(None, None, backend="numpy", **options)
    got = simulate(None, None, backend=backend, **options)
    for name in ("r_group", "r_crossing_group", "r_eq_group"):
        np.testing.assert_allclose(got[name], ref[name], rtol=0, atol=1e-10)


def test_exact_integrator_records_the_groups_too():
    options = dict(groups=[(2, 186.0), (1, 198.0)], sigma_bpm=0.5, runs=1, duration=6, seed=4)
    exact = simulate(None, None, integrator="exact", **options)
    fine = simulate(None, None, dt=0.0005, **options)
    np.testing.assert_allclose(exact.r_group.isel(group=1), 1.0)  # one metronome: r = 1
    np.testing.assert_allclose(exact.r_group, fine.r_group, atol=0.02)
    np.testing.assert_allclose(exact.r_crossing_group, fine.r_crossing_group, atol=0.02)


def test_a_grouped_dataset_survives_netcdf(tmp_path):
    ds = simulate(None, None, groups=[(2, 186.0), (2, 198.0)], runs=2, duration=5, seed=1)
    ds.to_netcdf(tmp_path / "g.nc", engine="h5netcdf")
    with xr.open_dataset(tmp_path / "g.nc", engine="h5netcdf") as back:
        xr.testing.assert_identical(back.load(), ds)


def test_ungrouped_runs_have_no_group_variables():
    ds = simulate(3, 192.0, runs=1, duration=2)
    assert "r_group" not in ds and "group" not in ds.coords and "groups" not in ds.attrs


@pytest.mark.parametrize(
    "groups, match",
    [
        ([], r"`groups` must be a non-empty list"),
        ("7@184", r"`groups` must be a non-empty list"),
        ([(7,)], r"`groups` entry 0 must be \(n, bpm\)"),
        ([(7, 184.0), (0, 200.0)], r"`groups` entry 1: the count n must be an integer >= 1, got 0"),
        ([(7.5, 184.0)], r"`groups` entry 0: the count n must be an integer"),
        ([(7, "fast")], r"`groups` entry 0: `bpm` must be a finite number, got 'fast'"),
        ([(7, 184.0, -1.0)], r"`groups` entry 0: `sigma_bpm` must be >= 0 BPM, got -1.0"),
        (
            [(7, 900.0)],
            r"`groups` entry 0 \(7@900:0\) has BPM 900, which is outside .* Move that",
        ),
        ([(7, 184.0, 400.0)], r"with `groups` entry 0 \(7@184:400\), a drawn natural frequency"),
    ],
)
def test_bad_groups_name_the_entry_and_the_fix(groups, match):
    with pytest.raises(ParameterError, match=match):
        simulate(None, None, groups=groups, runs=2, duration=1)


def test_groups_do_not_combine_with_explicit_frequencies():
    with pytest.raises(ParameterError, match=r"give `groups` or `frequencies_bpm`, not both"):
        simulate(None, None, groups=[(2, 190.0)], frequencies_bpm=[190.0, 191.0], duration=1)


def test_sigma_bpm_is_the_spread_of_groups_without_their_own():
    groups = as_groups([(2, 184.0), Group(3, 200.0, 0.1), (1, 190.0, None)], 0.6)
    assert [g.sigma_bpm for g in groups] == [0.6, 0.1, 0.6]
    assert group_bounds(groups).tolist() == [0, 2, 5, 6]
    ens = build_ensemble(None, None, params=get_preset("default"), groups=groups, runs=400,
                         sigma_bpm=0.6, seed=2)  # fmt: skip
    spread = ens.frequency_bpm[:, 2:5].std()
    assert spread == pytest.approx(0.1, rel=0.1)


@pytest.mark.parametrize(
    "text, group",
    [
        ("7@184", Group(7, 184.0)),
        ("7@200:0.5", Group(7, 200.0, 0.5)),
        (" 3@1.9e2:0", Group(3, 190.0, 0.0)),
    ],
)
def test_parse_group(text, group):
    assert parse_group(text) == group


@pytest.mark.parametrize(
    "text, match",
    [
        ("7", "expected N@BPM or N@BPM:SIGMA"),
        ("7@", "expected N@BPM"),
        ("7@200:", "expected N@BPM"),
        ("seven@200", "the count N must be a whole number"),
        ("0@200", "the count N must be >= 1"),
        ("7@fast", "BPM and SIGMA must be numbers"),
        ("7@nan", "must be finite"),
        ("7@200:-1", "SIGMA must be >= 0 BPM"),
    ],
)
def test_parse_group_says_what_is_wrong(text, match):
    with pytest.raises(ValueError, match=match):
        parse_group(text)

"""The model's switches beyond the paper (an applied torque on the disk, the
escapement's placement and reaction): off by default, and reachable from
``simulate(changes=)``, ``metrosync simulate --set``, a sweep axis, and the attrs."""

import math

import numpy as np
import pytest
import xarray as xr

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.cli import main
from metrosync.model import Metronome, MetronomeDesign, Platform, bpm_to_omega
from metrosync.sweeps import Grid, sweep

ON = {
    "forcing_amplitude": 0.01,
    "forcing_bpm": 185.0,
    "escapement_offset": 0.04,
    "escapement_reaction": 0,
}


def test_every_switch_is_off_by_default():
    sys = build_ensemble(3, 192, params=get_preset("default"), runs=2).system
    assert np.all(sys.forcing_amplitude == 0) and np.all(sys.escapement_offset == 0)
    assert np.all(sys.escapement_reaction == 1)
    attrs = simulate(2, 192, duration=1.0).attrs
    assert attrs["forcing_amplitude"] == 0 and attrs["escapement_offset"] == 0
    assert attrs["escapement_reaction"] == 1


def test_changes_reach_the_system_and_the_attrs():
    params = get_preset("default").with_changes(**ON)
    sys = build_ensemble(2, 192, params=params, runs=3).system
    np.testing.assert_array_equal(sys.forcing_amplitude, 0.01)
    np.testing.assert_allclose(sys.forcing_omega, bpm_to_omega(185.0))
    np.testing.assert_array_equal(sys.escapement_offset, np.full((3, 2), 0.04))
    np.testing.assert_array_equal(sys.escapement_reaction, 0.0)
    ds = simulate(2, 192, duration=1.0, changes=ON)
    assert {k: ds.attrs[k] for k in ON} == ON


def test_each_metronome_may_be_out_of_beat_by_its_own_offset():
    design = MetronomeDesign()
    metronomes = [
        Metronome(MetronomeDesign(escapement_offset=d), design.l2_for_bpm(192))
        for d in (0.0, 0.02, -0.03)
    ]
    sys = build_ensemble(None, None, params=get_preset("default"), metronomes=metronomes).system
    np.testing.assert_array_equal(sys.escapement_offset, [[0.0, 0.02, -0.03]])


def test_the_cli_sets_them_and_stores_them(tmp_path, capsys):
    out = tmp_path / "forced.nc"
    args = ["simulate", "--n", "1", "--runs", "1", "--duration", "2", "--out", str(out)]
    for name, value in ON.items():
        args += ["--set", f"{name}={value}"]
    assert main(args) == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert {k: ds.attrs[k] for k in ON} == ON


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"forcing_amplitude": 0.01}, r"needs a frequency: set `forcing_bpm` > 0"),
        ({"forcing_amplitude": -0.01, "forcing_bpm": 180}, r"`forcing_amplitude` must be >= 0"),
        ({"forcing_bpm": math.nan}, r"`forcing_bpm` must be a finite number"),
        ({"escapement_offset": 1.6}, r"`escapement_offset` must lie in \(-pi/2, pi/2\)"),
        ({"escapement_reaction": 0.5}, r"`escapement_reaction` must be true or false"),
    ],
)
def test_bad_values_name_the_parameter(changes, match):
    with pytest.raises(ParameterError, match=match):
        get_preset("default").with_changes(**changes)


def test_a_switch_takes_bools_and_zero_or_one():
    assert Platform(escapement_reaction=0).escapement_reaction is False
    assert Platform(escapement_reaction=1.0).escapement_reaction is True
    assert Platform(escapement_reaction=np.bool_(False)).escapement_reaction is False


def test_they_are_sweep_axes(tmp_path):
    grid = Grid(
        axes={"forcing_bpm": "180,190", "escapement_reaction": "true,false"},
        fixed={"n": 1, "runs": 1, "duration": 2.0, "forcing_amplitude": 0.01,
               "escapement_offset": 0.02},
    )  # fmt: skip
    points = list(grid.points())
    assert [p.kwargs["changes"]["forcing_bpm"] for p in points] == [180.0, 180.0, 190.0, 190.0]
    assert [p.kwargs["changes"]["escapement_reaction"] for p in points] == [1, 0, 1, 0]
    assert len({p.key for p in points}) == 4
    result = sweep(grid, tmp_path / "store")
    ds = result.dataset
    assert list(ds.forcing_bpm.values) == [180.0, 190.0]
    assert list(ds.escapement_reaction.values) == [1, 0]
    assert ds.forcing_bpm.attrs["units"] == "BPM"
    assert ds.attrs["model_forcing_amplitude"] == 0.01
    assert ds.attrs["model_escapement_offset"] == 0.02
    assert result.complete

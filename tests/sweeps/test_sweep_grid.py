"""Grid specs: parsing, validation, per-point seeds and content hashes."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from metrosync import ParameterError
from metrosync.sweeps import points as points_module
from metrosync.sweeps.grid import Grid, parse_values


def test_range_is_inclusive_and_free_of_float_drift():
    assert parse_values("bpm", "150:160:2.5") == (150.0, 152.5, 155.0, 157.5, 160.0)
    assert parse_values("c_phi", "0:0.3:0.1") == (0.0, 0.1, 0.2, 0.3)
    assert parse_values("n", "7,16,32") == (7, 16, 32)
    assert parse_values("n", 7) == (7,)
    assert parse_values("inertia", "inf") == (math.inf,)


@given(
    start=st.integers(-1000, 1000),
    count=st.integers(1, 200),
    step=st.sampled_from([0.1, 0.25, 1.0, 2.5, 3.0]),
)
def test_range_has_the_stated_count_and_ends(start, count, step):
    stop = start + (count - 1) * step
    values = parse_values("bpm", f"{start}:{stop:.12g}:{step}")
    assert len(values) == count
    assert values[0] == start and math.isclose(values[-1], stop, abs_tol=1e-9)


@pytest.mark.parametrize(
    ("name", "spec", "match"),
    [
        ("bpm", "150:220", "START:STOP:STEP"),
        ("bpm", "220:150:2", "START <= STOP"),
        ("bpm", "150:220:0", "STEP > 0"),
        ("bpm", "a,b", "not a number"),
        ("n", "7.5", "whole numbers"),
        ("n", "0,7", ">= 1"),
        ("runs", "1,1", "twice"),
        ("duration", "-1", "> 0 s"),
        ("sigma_bpm", "-0.5", ">= 0 BPM"),
        ("bpm", "nan", "finite"),
        ("bpm", "0:1e9:1", "check STEP"),
    ],
)
def test_bad_values_name_the_parameter(name, spec, match):
    with pytest.raises(ParameterError, match=match):
        parse_values(name, spec)


def test_grid_rejects_unknown_swept_twice_and_untunable():
    with pytest.raises(ParameterError, match="unknown sweep parameter 'frequency'"):
        Grid(axes={"frequency": [1, 2]})
    with pytest.raises(ParameterError, match="both swept and fixed"):
        Grid(axes={"bpm": [180, 190]}, fixed={"omega0": 185})
    with pytest.raises(ParameterError, match="tunable range"):
        Grid(axes={"bpm": "60:100:10"})
    with pytest.raises(ParameterError, match="`drive` must be >= 0"):
        Grid(axes={"bpm": [190]}, fixed={"M": -1})
    with pytest.raises(ParameterError, match="unknown preset"):
        Grid(axes={"bpm": [190]}, preset="nope")


def test_aliases_and_axis_order():
    grid = Grid(axes={"omega0": "180:190:5", "N": [3, 5], "M": [6e-5]})
    assert list(grid.axes) == ["bpm", "n", "drive"]
    assert grid.shape == (3, 2, 1) and grid.size == 6
    point = next(grid.points())
    assert point.kwargs["changes"] == {"drive": 6e-5}
    assert point.work == point.kwargs["runs"] * 3 * 60000


def test_toml_with_command_line_overrides(tmp_path):
    path = tmp_path / "grid.toml"
    path.write_text(
        'seed = 3\npreset = "default"\n[grid]\nbpm = "180:190:5"\nn = [3, 5]\n'
        "[fixed]\nruns = 4\nduration = 30\nc_phi = 2e-5\n"
    )
    grid = Grid.from_toml(path, axes={"runs": "2,4"}, fixed={"n": 7})
    assert grid.axes == {"bpm": (180.0, 185.0, 190.0), "runs": (2, 4)}
    assert grid.fixed["n"] == 7 and grid.fixed["c_phi"] == 2e-5 and grid.fixed["seed"] == 3
    path.write_text("[grid]\nbpm = [180\n")
    with pytest.raises(ParameterError, match="not valid TOML"):
        Grid.from_toml(path)
    path.write_text("colour = 1\n[grid]\nbpm = [180]\n")
    with pytest.raises(ParameterError, match="unknown key"):
        Grid.from_toml(path)


def keys(grid):
    return {tuple(p.coords.values()): p.key for p in grid.points()}


def test_every_input_changes_the_key_and_nothing_else_does():
    base = keys(Grid(axes={"bpm": [185, 190]}, fixed={"runs": 4}))
    assert base == keys(Grid(axes={"bpm": "185:190:5"}, fixed={"runs": "4"}))
    for change in ({"c_phi": 2e-5}, {"runs": 5}, {"dt": 0.005}, {"sigma": 0.5}, {"seed": 1}):
        other = keys(Grid(axes={"bpm": [185, 190]}, fixed={"runs": 4, **change}))
        assert set(other.values()).isdisjoint(base.values()), change
    kept = keys(Grid(axes={"bpm": [185, 190]}, fixed={"runs": 4}, keep_r=True))
    assert set(kept.values()).isdisjoint(base.values())


def test_key_includes_the_package_version(monkeypatch):
    before = keys(Grid(axes={"bpm": [185]}))
    monkeypatch.setattr(points_module, "__version__", "999.0")
    assert keys(Grid(axes={"bpm": [185]})) != before


def test_point_seeds_do_not_depend_on_grid_extent():
    small = {
        p.coords["bpm"]: (p.kwargs["seed"], p.key) for p in Grid(axes={"bpm": [185, 190]}).points()
    }
    big = {
        p.coords["bpm"]: (p.kwargs["seed"], p.key) for p in Grid(axes={"bpm": "180:195:5"}).points()
    }
    assert all(big[b] == small[b] for b in small)
    seeds = [s for s, _ in big.values()]
    assert len(set(seeds)) == len(seeds)


def test_groups_replace_n_and_bpm_and_the_offset_moves_every_group_after_the_first():
    grid = Grid(axes={"group_offset_bpm": "0:20:10"}, fixed={"runs": 2, "sigma": 0.5},
                groups=["7@184", (3, 190.0, 0.1)])  # fmt: skip
    points = list(grid.points())
    assert [p.kwargs["groups"] for p in points] == [
        [[7, 184.0, None], [3, 190.0 + offset, 0.1]] for offset in (0.0, 10.0, 20.0)
    ]
    assert all(p.kwargs["n"] is None and p.kwargs["bpm"] is None for p in points)
    assert points[0].work == 2 * 10 * 60000 and grid.describe()["groups"] == "7@184 3@190:0.1"
    assert len({p.kwargs["seed"] for p in points}) == 3
    # Other groups are other points: another key and another seed.
    other = next(Grid(axes={"group_offset_bpm": [0]}, fixed={"runs": 2, "sigma": 0.5},
                      groups=["7@184", (3, 191.0, 0.1)]).points())  # fmt: skip
    assert other.key != points[0].key and other.kwargs["seed"] != points[0].kwargs["seed"]


def test_grouped_grids_refuse_conflicts_clearly():
    with pytest.raises(ParameterError, match=r"`groups` sets the number and BPM .* drop `n`"):
        Grid(axes={"n": [3, 5]}, groups=["2@184", "2@200"])
    with pytest.raises(ParameterError, match="`group_offset_bpm` shifts the groups after the"):
        Grid(axes={"group_offset_bpm": [0, 10]})
    with pytest.raises(ParameterError, match=r"tunable range.*Narrow the `group_offset_bpm`"):
        Grid(axes={"group_offset_bpm": [0, 100]}, groups=["2@184", "2@200"])
    with pytest.raises(ParameterError, match=r"`groups` entry 1: expected N@BPM"):
        Grid(axes={"group_offset_bpm": [0]}, groups=["2@184", "2x"])

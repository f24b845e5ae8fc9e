"""Reading tables as instruments write them, and choosing each pendulum's columns."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from metrosync.angles import AngleColumns, AngleTableError, parse_table, swings

TRACKER_MULTI = (
    "#multi:\n"
    "\tmass A\t\tmass B\t\t\n"
    "t\tx\ty\tx\ty\t\n"
    "0,000\t0,10\t-0,20\t1,5\t-0,25\t\n"
    "0,033\t0,11\t\t1,6\t-0,24\t\n"
    "\n"
    "0,067\t0,12\t-0,19\t1,7\t-0,23\t\n"
)


def test_trackers_multi_export_is_read_with_its_groups_and_decimal_commas():
    table = parse_table(TRACKER_MULTI, source="tracker.txt")
    assert (table.delimiter, table.decimal) == ("\t", ",")
    assert [(c.header, c.group) for c in table.columns] == [
        ("t", ""), ("x", "mass A"), ("y", "mass A"), ("x", "mass B"), ("y", "mass B"),
    ]  # fmt: skip
    assert table.groups == ["mass A", "mass B"]
    assert table.columns[0].values.tolist() == [0.0, 0.033, 0.067]
    assert math.isnan(table.columns[2].values[1])  # a frame not marked
    assert table.lines.tolist() == [4, 5, 7] and table.skipped == ((6, "blank line"),)
    found = swings(table)
    assert [s.name for s in found] == ["mass A", "mass B"]
    assert all(s.unit == "length" and "along the swing" in s.source for s in found)
    assert found[0].time.tolist() == [0.0, 0.033, 0.067]  # the shared t


def test_one_tracker_track_and_an_encoders_csv():
    one = parse_table("mass A\nt\tx\ty\n0.0\t0.1\t-0.2\n0.1\t0.2\t-0.21\n")
    assert [(c.header, c.group) for c in one.columns] == [
        ("t", "mass A"),
        ("x", "mass A"),
        ("y", "mass A"),
    ]
    assert [s.name for s in swings(one)] == ["mass A"]
    encoder = parse_table("millis,Angle (deg)\n56000,7.20\n56010,7.56\n")
    (swing,) = swings(encoder)
    assert swing.time.tolist() == [56.0, 56.01] and swing.unit == "deg"
    bare = parse_table("0,00;1,5\n0,01;1,6\n")  # no header: time, angle
    assert (bare.delimiter, bare.decimal) == (";", ",")
    (swing,) = swings(bare)
    assert swing.value.tolist() == [1.5, 1.6] and swing.unit == ""


def test_angle_columns_by_name_unit_and_number():
    table = parse_table("t [s],theta1 [rad],θ_{v},theta 2 (°)\n0,0.1,3,5\n0.1,0.2,3,6\n")
    found = swings(table)
    assert [(s.name, s.unit) for s in found] == [("theta1 [rad]", "rad"), ("theta 2 (°)", "deg")]
    chosen = swings(table, AngleColumns(time="1", angle=("3",)))
    assert [s.value.tolist() for s in chosen] == [[3.0, 3.0]]


def test_an_angle_that_wraps_at_a_full_turn_is_unwrapped_across_blank_cells():
    table = parse_table("t,angle (deg)\n0,358\n0.1,\n0.2,2\n0.3,6\n")
    (swing,) = swings(table)
    assert swing.value[[0, 2, 3]].tolist() == [358.0, 362.0, 366.0]


def test_x_and_y_are_preferred_to_trackers_polar_angle_about_its_origin():
    table = parse_table("t,x,y,θ_{r}\n0,0,-1,-90\n0.1,0.1,-1,-84\n")
    (swing,) = swings(table)
    assert "along the swing" in swing.source
    pivoted = swings(table, AngleColumns(x="x", y="y", pivot=((0.0, 0.0),)))
    assert pivoted[0].unit == "rad" and abs(pivoted[0].value[1] - math.atan(0.1)) < 1e-12


def test_a_column_asked_for_that_is_not_there_lists_the_columns():
    table = parse_table(TRACKER_MULTI, source="tracker.txt")
    with pytest.raises(AngleTableError, match=r"no column 'theta' in 'mass A', asked for as the "
                       r"angle column; its columns are 't', 'x' \(mass A\), 'y' \(mass A\), "
                       r"'x' \(mass B\)"):  # fmt: skip
        swings(table, AngleColumns(angle=("theta",)))
    with pytest.raises(AngleTableError, match="no pendulum found.*'speed'"):
        swings(parse_table("t,speed\n0,1\n0.1,2\n"))
    with pytest.raises(AngleTableError, match="no time column"):
        swings(parse_table("when,theta\n0,1\n0.1,2\n"))


def test_a_time_without_unit_a_second_apart_or_more_warns():
    with pytest.warns(UserWarning, match="states no unit .* 10 s apart.*`time_unit` 'ms'"):
        swings(parse_table("t,theta\n0,1\n10,2\n20,3\n"))
    (swing,) = swings(parse_table("t,theta\n0,1\n10,2\n"), AngleColumns(time_unit="ms"))
    assert swing.time.tolist() == [0.0, 0.01]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("hello\nworld\n", "no row of numbers in 2 lines"),
        ("t\n0\n1\n", "one column of numbers only"),
    ],
)
def test_what_is_not_a_table_is_refused(text, message):
    with pytest.raises(AngleTableError, match=message):
        parse_table(text)


def test_settings_check_themselves():
    with pytest.raises(ValueError, match="`time_unit` must be"):
        AngleColumns(time_unit="min")
    with pytest.raises(ValueError, match="give both `x` and `y`"):
        AngleColumns(x="x")
    with pytest.raises(ValueError, match="`pivot` is for x and y"):
        AngleColumns(angle=("theta",), pivot=((0.0, 0.0),))


finite = st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: round(v, 6))


@settings(max_examples=60, deadline=None)
@given(
    data=st.lists(st.lists(finite, min_size=2, max_size=4), min_size=1, max_size=12).filter(
        lambda rows: len({len(r) for r in rows}) == 1
    ),
    delimiter=st.sampled_from(["\t", ",", ";", " "]),
    comma=st.booleans(),
    header=st.booleans(),
)
def test_any_table_of_numbers_reads_back(data, delimiter, comma, header):
    """Whatever the delimiter and decimal mark, the numbers read are the numbers written."""
    comma = comma and delimiter != ","
    width = len(data[0])
    lines = [delimiter.join(f"c{j}" for j in range(width))] if header else []
    for row in data:
        cells = [repr(v) for v in row]
        lines.append(delimiter.join(c.replace(".", ",") if comma else c for c in cells))
    table = parse_table("\n".join(lines) + "\n")
    values = np.column_stack([c.values for c in table.columns])
    assert values.tolist() == data
    assert [c.header for c in table.columns] == ([f"c{j}" for j in range(width)] if header
                                                 else [""] * width)  # fmt: skip

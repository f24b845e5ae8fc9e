"""``metrosync analyze`` on angle tables, end to end: an encoder's CSV, Tracker's export.

The pendulums are driven at known periods (`pendulums.driven`), so the tempo the
analysis finds, 120/T BPM, is known; the tables are written here as the instruments
write them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from metrosync.cli import main

from .pendulums import bob_positions, encoder_csv, tracker_table

ENCODER_PERIOD = 1.137  # s
PERIODS = {"mass A": 1.25, "mass B": 1.13}
PIVOTS = {"mass A": (0.0, 0.30), "mass B": (0.40, 0.30)}  # m, y up
FPS = 30.0


def bpm(period):
    return 120.0 / period


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def frames():
    """Tracker's frame times and each mass's marks: 60 s at 30 fps."""
    times = np.arange(0, 60, 1 / FPS)
    marks = {name: bob_positions(PERIODS[name], times, pivot=PIVOTS[name], seed=k, phase=k)
             for k, name in enumerate(PERIODS)}  # fmt: skip
    return times, marks


@pytest.mark.parametrize(
    ("header", "millis"), [("time_s,angle_deg", False), ("millis,angle", True), (None, False)]
)
def test_an_encoders_csv_gives_its_pendulums_tempo(capsys, tmp_path, header, millis):
    """100 Hz from 56 to 264 s, 0.36-degree steps, the zero 7.1 degrees off the vertical."""
    path = encoder_csv(tmp_path / "encoder.csv", ENCODER_PERIOD, header=header, millis=millis)
    nc, png = tmp_path / "e.nc", tmp_path / "e.png"
    code, out, err = run(capsys, "analyze", path, "--out", nc, "--plot", png)
    assert code == 0, err
    assert "sigma =" in out and "equilibrium r" in out and "angle table, 20800 rows" in out
    assert "t = 56 .. 263.99 s" in out and "a sample every 10 ms" in out
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert abs(float(ds.frequency_bpm[0]) - bpm(ENCODER_PERIOD)) < 0.01
        assert float(ds.period_jitter[0, 0]) < 4e-3  # the encoder's steps, 0.36 degree
        assert float(ds.time_origin[0]) == 56.0 and float(ds.time[-1]) < 208
        assert int(ds.passes_bridged.sum()) == 0
        assert [n for n in ds.variables if "long_name" not in ds[n].attrs] == []
        if header == "time_s,angle_deg":  # a unit in the header: the rest angle in rad
            assert str(ds.unit.values[0, 0]) == "rad"
            assert abs(float(ds.rest_value[0, 0]) - math.radians(7.1)) < math.radians(0.36)
        else:
            assert str(ds.unit.values[0, 0]) == "not stated"
    assert png.stat().st_size > 1000


@pytest.mark.parametrize("decimal", [".", ","])
def test_a_tracker_table_of_two_masses_is_two_metronomes(capsys, tmp_path, frames, decimal):
    times, marks = frames
    path = tracker_table(tmp_path / "tracker.txt", marks, times, decimal=decimal)
    nc = tmp_path / "t.nc"
    code, out, err = run(capsys, "analyze", path, "--out", nc)
    assert code == 0, err
    assert "metronome 0 = mass A" in out and "metronome 1 = mass B" in out
    assert "along the swing (no pivot given)" in out
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds.name.values.tolist() == ["mass A", "mass B"]
        found = ds.frequency_bpm.values
        r_eq = ds.attrs["r_eq"]
    assert np.abs(found - [bpm(p) for p in PERIODS.values()]).max() < 0.02
    # About the pivots, the angles (rad) give the same passes, up to the marks' noise.
    pivots = [a for name in PERIODS for a in ("--pivot", "{},{}".format(*PIVOTS[name]))]
    code, out, err = run(capsys, "analyze", path, *pivots, "--out", nc)
    assert code == 0, err
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert np.abs(ds.frequency_bpm.values - found).max() < 0.01
        assert abs(ds.attrs["r_eq"] - r_eq) < 0.01
        assert ds.unit.values.tolist() == [["rad", "rad"]]
        assert np.all((ds.swing.values > 0.1) & (ds.swing.values < 0.5))


def test_frames_not_marked_across_a_pass_are_bridged_with_a_warning(capsys, tmp_path, frames):
    times, marks = frames
    # mass B unmarked for 0.4 s around the middle of the video: a pass goes missing
    blank = {(1, i) for i in range(885, 897)}
    path = tracker_table(tmp_path / "gaps.txt", marks, times, blank=blank)
    nc = tmp_path / "g.nc"
    code, out, err = run(capsys, "analyze", path, "--out", nc)
    assert code == 0, err
    assert "passes missed and bridged (mass B: 1 pass)" in err
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds.passes_bridged.values.tolist() == [[0, 1]]
        assert abs(float(ds.frequency_bpm[1]) - bpm(PERIODS["mass B"])) < 0.02


def test_several_tables_are_repeated_runs(capsys, tmp_path, frames):
    times, marks = frames
    a = tracker_table(tmp_path / "a.txt", marks, times)
    b = tracker_table(tmp_path / "b.txt", marks, times, decimal=",")
    nc = tmp_path / "ab.nc"
    code, out, err = run(capsys, "analyze", a, b, "--out", nc, "--channels", "1")
    assert code == 0, err
    assert out.startswith("metrosync analyze: 2 logs, 1 metronome")
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds.sizes["log"] == 2 and ds.metronome.values.tolist() == [1]
        assert ds.name.values.tolist() == ["mass B"]


def test_the_pivots_track_is_refused_and_can_be_left_out(capsys, tmp_path, frames):
    times, marks = frames
    rng = np.random.default_rng(5)
    still = (0.2 + rng.normal(0, 3e-4, times.size), 0.3 + rng.normal(0, 3e-4, times.size))
    path = tracker_table(tmp_path / "pivot.txt", {**marks, "pivot": still}, times)
    code, _, err = run(capsys, "analyze", path)
    assert code == 2 and "pivot (x, y 'x' (pivot)" in err and "keeps no period" in err
    assert "--channels" in err
    code, out, err = run(capsys, "analyze", path, "--channels", "0,1")
    assert code == 0, err


def one_line(err):
    return len(err.strip().splitlines()) == 1 and "Traceback" not in err


@pytest.mark.parametrize(
    ("setup", "options", "message"),
    [
        ("junk", [], "'junk.txt' is neither a light-gate log (no record such as '0-1-0-0 1450'"),
        ("tracker", ["--angle-column", "theta"], "no column 'theta' in 'mass A', asked for as "
         "the angle column; its columns are 't', 'x' (mass A), 'y' (mass A)"),
        ("tracker", ["--pivot", "0,0.3"], "`pivot` (--pivot) gives 1 pivot but"),
        ("short", [], "theta has 3 samples with a time and a value, too few for a swing"),
        ("back", [], "line 4: time 0.1 s follows 0.2 s (line 3): the time column must increase"),
        ("mixed", [], "not both: run.log is a light-gate log, tracker.txt is not"),
    ],
)  # fmt: skip
def test_bad_tables_are_one_line_and_exit_2(capsys, tmp_path, monkeypatch, frames, setup,
                                            options, message):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    times, marks = frames
    tracker_table(tmp_path / "tracker.txt", marks, times)
    files = {"junk": ["junk.txt"], "tracker": ["tracker.txt"], "short": ["short.csv"],
             "back": ["back.csv"], "mixed": ["run.log", "tracker.txt"]}[setup]  # fmt: skip
    (tmp_path / "junk.txt").write_text("Dear diary,\nthe metronomes ticked.\n")
    (tmp_path / "short.csv").write_text("t,theta\n0,1\n0.1,2\n0.2,3\n")
    swapped = [0.0, 0.2, 0.1, *np.arange(0.3, 5, 0.1)]
    (tmp_path / "back.csv").write_text(
        "t,theta\n" + "".join(f"{t:g},{math.sin(7 * t):.4f}\n" for t in swapped)
    )
    (tmp_path / "run.log").write_text("0-0 0\n1-0 100\n0-0 200\n0-1 300\n0-0 400\n")
    code, out, err = run(capsys, "analyze", *files, *options)
    assert code == 2, out
    assert message in err, err
    assert one_line(err)


def test_options_of_other_inputs_warn(capsys, tmp_path, frames):
    times, marks = frames
    path = tracker_table(tmp_path / "tracker.txt", marks, times)
    code, _, err = run(capsys, "analyze", path, "--glitch", "0.01", "--bpm", "100")
    assert code == 0
    assert "an angle table ignores --glitch" in err and "angle tables ignore --bpm" in err
    log = tmp_path / "run.log"
    log.write_text("0 0\n1 100\n0 200\n")
    code, _, err = run(capsys, "analyze", log, "--time-column", "t")
    assert "light-gate logs ignore --time-column (options for angle tables)" in err

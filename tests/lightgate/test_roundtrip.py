"""Round trip: simulate → virtual gate → analyze agrees with the simulation's own r(t)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from metrosync import analyze, simulate
from metrosync.errors import AnalysisError, ChannelCountError
from metrosync.lightgate import LightGate, write_logs

DATA = Path(__file__).parent.parent / "data"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    ds = simulate(7, 192.0, sigma_bpm=0.75, runs=2, duration=90.0, seed=11, record_every=1,
                  trajectories=True, progress=False)  # fmt: skip
    gate = LightGate(offset=0.1, width=0.05, tick=64e-6, counter_bits=16, start_tick=50000)
    paths = write_logs(ds, tmp_path_factory.mktemp("logs"), gate)
    return ds, paths


def crossing_frequencies(ds, b):
    """Mean frequency (BPM) of each metronome from the simulation's upward zero crossings."""
    t, th = ds.time.values, ds.theta.values[:, b, :]
    out = []
    for x in th.T:
        k = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
        tc = t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
        out.append(120 * (tc.size - 1) / (tc[-1] - tc[0]))
    return np.array(out)


def test_recovers_r_and_frequencies_of_each_run(run):
    ds, paths = run
    for b, path in enumerate(paths):
        res = analyze([path])
        assert res.sizes["time"] > 800
        sim = ds.r_crossing.isel(run=b).sel(time=res.time.values, method="nearest")
        assert np.allclose(sim.time.values, res.time.values, atol=1e-9)
        assert np.nanmax(np.abs(res.r.values - sim.values)) < 0.02
        assert np.max(np.abs(res.frequency_bpm.values - crossing_frequencies(ds, b))) < 0.05
        assert abs(res.attrs["r_eq"] - float(ds.r_eq[b])) < 0.02


def test_several_logs_are_averaged(run):
    _, paths = run
    both = analyze(paths)
    assert both.r_runs.shape[0] == 2
    assert np.allclose(both.r.values, both.r_runs.mean("log").values)
    single = analyze([paths[0]])
    assert np.allclose(both.r_runs.isel(log=0).sel(time=single.time[5:-5]),
                       single.r.isel(time=slice(5, -5)))  # fmt: skip
    assert both.attrs["sigma_bpm"] > 0 and np.isfinite(both.attrs["r_eq"])


def test_messy_sample_log_measures_like_the_clean_one():
    clean = analyze([DATA / "clean.log"])
    messy = analyze([DATA / "messy.log"])
    assert np.allclose(clean.frequency_bpm, messy.frequency_bpm, atol=0.05)
    common = np.intersect1d(np.round(clean.time.values, 6), np.round(messy.time.values, 6))
    a = clean.r.sel(time=common, method="nearest").values
    b = messy.r.sel(time=common, method="nearest").values
    assert np.max(np.abs(a - b)) < 0.05
    assert int(messy.lines_skipped[0]) == 10


def test_refusals(tmp_path):
    two = tmp_path / "two.log"
    two.write_text("0-0 1\n1-0 5\n0-0 9\n")
    with pytest.raises(ChannelCountError):
        analyze([DATA / "clean.log", two])
    # Gate 1 never changes: it is left out, with a warning; gate 0 has too few passes.
    with pytest.warns(UserWarning, match="gate 1 never changed"):
        with pytest.raises(AnalysisError, match="gate 0"):
            analyze([two])

"""The predicted ω_c(σ), its cache, and `metrosync theory`."""

import json
import math
import re

import numpy as np
import pytest
import xarray as xr
from scipy.interpolate import PchipInterpolator

from metrosync import ParameterError
from metrosync.cli import main
from metrosync.theory import coupling as cp
from metrosync.theory.predict import reduced_theory
from metrosync.theory.sakaguchi import critical_coupling


@pytest.fixture(scope="module")
def prediction(tmp_path_factory):
    cache = tmp_path_factory.mktemp("theory-cache")
    ds = reduced_theory(
        bpms=(160.0, 180.0, 200.0), sigmas=(0.75, 1.0, 3.0), cache=cache, simulate_n=None
    )
    return ds, cache


def test_predicted_onset_sits_where_k_meets_the_threshold(prediction):
    ds, _ = prediction
    wc = ds.omega_c.values
    assert 160 < wc[0] < wc[1] < 200  # a wider spread needs more coupling
    assert np.isnan(wc[2])  # σ = 3 BPM: beyond the grid, reported as NaN
    assert ds.omega_c_low[0] < wc[0] < ds.omega_c_high[0]
    # At ω_c the interpolated K equals K_c(α, σ_ω).
    k = PchipInterpolator(ds.bpm, ds.k)(wc[0])
    alpha = np.interp(wc[0], ds.bpm, ds.alpha)
    factor = np.interp(wc[0], ds.bpm, ds.spread_factor)
    assert k == pytest.approx(critical_coupling(alpha, math.pi / 60 * 0.75 * factor), rel=0.01)
    # A metronome ticks at ≈ 0.96 of its nominal rate, and so does the spread.
    assert 0.94 < float(ds.spread_factor[1]) < 0.98


def test_measurements_are_cached_and_a_damaged_entry_is_measured_again(prediction, monkeypatch):
    ds, cache = prediction
    files = sorted(cache.glob("growth-*.json"))
    assert len(files) == 3
    files[0].write_text("{not json")

    calls = []
    real = cp.measure_by_growth

    def counting(*args, **kwargs):
        calls.append(args[0])
        return real(*args, **kwargs)

    monkeypatch.setattr(cp, "measure_by_growth", counting)
    again = reduced_theory(
        bpms=(160.0, 180.0, 200.0), sigmas=(0.75, 1.0, 3.0), cache=cache, simulate_n=None
    )
    assert calls == [160.0]
    xr.testing.assert_allclose(again.k, ds.k)
    assert json.loads(files[0].read_text())["coupling"]["bpm"] == 160.0


def test_overturning_preset_is_refused():
    with pytest.raises(ParameterError, match=r"'boda2013' overturns"):
        reduced_theory("boda2013", bpms=(160.0, 200.0))


def test_cli_prints_writes_and_plots(prediction, tmp_path, capsys):
    _, cache = prediction
    out, plot = tmp_path / "theory.nc", tmp_path / "theory.png"
    argv = [
        "theory",
        "--bpm",
        "160:200:20",
        "--sigma",
        "0.75,1",
        "--cache",
        str(cache),
        "--out",
        str(out),
        "--plot",
        str(plot),
        "--no-progress",
    ]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "sigma =  0.75 BPM: omega_c =" in text and "K (rad/s)" in text
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert set(ds.sigma.values) == {0.75, 1.0} and ds.attrs["n"] == "inf"
    # The reduced model's r reaches 1/2 above the linear threshold, and r rises with ω₀.
    assert np.all(ds.omega_half > ds.omega_c)
    assert np.all(np.diff(ds.r_reduced.sel(sigma=0.75)) > 0)
    ds.close()
    assert plot.stat().st_size > 10_000


def test_cli_refuses_an_unwritable_cache_before_measuring(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["theory", "--cache", str(blocker / "sub"), "--bpm", "160,170"]) == 2
    assert "`--cache`" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--bpm", "190"], "`--bpm` needs at least 2 values"),
        (["--sigma", "0"], "`sigmas` (--sigma) must be spreads > 0"),
        (["--n", "many"], "`--n` must be a whole number >= 1 or 'inf'"),
        (["--sigma", "-1"], "`sigma_bpm` (--sigma) must be >= 0"),
        (["--out", "x.txt"], "must end in .nc"),
        (["--preset", "nope"], "unknown preset 'nope'"),
        (["--bpm", "400,410"], "outside the tunable range"),
        (["--bpm", "150:300:10"], "`bpm` (--bpm) = 240 is outside the tunable range"),
        (["--measure-n", "5000"], "`measure_n` (--measure-n) must be an integer in [16, 256]"),
    ],
)
def test_cli_errors_name_the_option(argv, message, capsys, tmp_path):
    assert main(["theory", "--cache", str(tmp_path), *argv]) == 2
    assert message in capsys.readouterr().err


def test_a_long_theory_run_warns_with_its_estimate_before_measuring(monkeypatch, capsys):
    import metrosync.theory.predict as predict

    def measure(*args, **kwargs):
        raise KeyboardInterrupt  # the user, once the warning is out: stop here

    monkeypatch.setattr(predict, "_measure_cached", measure)
    argv = ["theory", "--bpm", "150:230:0.01", "--no-cache", "--no-progress"]
    assert main(argv) == 130
    err = capsys.readouterr().err.splitlines()
    assert err[-1] == "metrosync theory: interrupted: nothing was written"
    (warning,) = err[:-1]
    found = re.search(r"theory is estimated to take about ([\d.]+) h \(8001 measurements", warning)
    assert found and 1 < float(found[1]) < 4, warning
    assert "coarser `bpms` (--bpm) grid" in warning and "(--no-simulate)" in warning


def test_cached_measurements_cost_nothing_in_the_estimate(tmp_path):
    from metrosync.model import get_preset
    from metrosync.theory.predict import _cache_path, theory_budget

    params, bpms = get_preset("default"), np.arange(150.0, 230.0, 0.5)
    full = theory_budget(bpms, params=params, cache=tmp_path)
    for bpm in bpms[:80]:
        path, _ = _cache_path(bpm, "growth", params, 32, tmp_path)
        path.write_text("{}")
    half = theory_budget(bpms, params=params, cache=tmp_path)
    assert half.seconds == pytest.approx(full.seconds / 2)
    assert "80 measurements" in half.work and "160 measurements" in full.work

"""`critical` refuses to print an N → ∞ value the sweep does not support, and says why."""

import numpy as np
import pytest
import xarray as xr
from test_sweep_critical import synthetic_sweep

from metrosync.cli import main
from metrosync.sweeps.critical import Extrapolation, critical_frequency, judge

BPM = np.arange(160.0, 210.5, 1.0)


def _write(tmp_path, sweep):
    path = tmp_path / "sweep.nc"
    sweep.to_netcdf(path, engine="h5netcdf")
    return str(path)


def test_two_sizes_say_why_instead_of_nan(tmp_path, capsys):
    path = _write(tmp_path, synthetic_sweep(sizes=(16, 64), runs=40))
    assert main(["critical", path, "--bootstrap", "30", "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out
    assert out.count("not extrapolated: needs at least 3 sizes N with an estimate, got 2") == 2


def test_an_extrapolation_outside_the_grid_is_not_printed_as_a_result(tmp_path, capsys):
    # ω_c(N) = 150 + 240/N: every size inside 160 .. 210 BPM, the limit below it.
    rng = np.random.default_rng(0)
    sizes = np.array([6, 8, 12, 16])
    omega = 150 + 240 / sizes
    r = np.empty((sizes.size, BPM.size, 60))
    for i, w in enumerate(omega):
        p = 1 / (1 + np.exp(-(BPM - w) / 2.0))
        r[i] = np.where(rng.random((BPM.size, 60)) < p[:, None], 0.9, 0.2)
    sweep = xr.Dataset({"r_eq": (("n", "bpm", "run"), r)}, coords={"n": sizes, "bpm": BPM})
    res = critical_frequency(sweep, n_boot=30)
    for m in ("peak", "rise"):
        assert res.attrs[f"omega_c_inf_{m}"] < 160  # the fit itself leaves the grid ...
        assert "outside the swept grid 160 .. 210 BPM" in res.attrs[f"fit_note_{m}"]
    assert main(["critical", _write(tmp_path, sweep), "--bootstrap", "30", "--no-plot"]) == 0
    out = capsys.readouterr().out  # ... and the command does not report it as ω_c∞
    assert "N -> inf (peak): not extrapolated: the fit gives" in out
    assert "N -> inf (peak): omega_c =" not in out


def test_a_supported_extrapolation_is_printed(tmp_path, capsys):
    path = _write(tmp_path, synthetic_sweep(runs=60))
    assert main(["critical", path, "--bootstrap", "30", "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "N -> inf (peak): omega_c = 18" in out and "not extrapolated" not in out


@pytest.mark.parametrize(
    ("fit", "expected"),
    [
        (Extrapolation(185.0, 2.0, 40.0, 0.8, "omega_inf + a*N**-nu"), ""),
        (Extrapolation(255.0, 103.0, -9.0, 4.2, "omega_inf + a*N**-nu"), "outside the swept"),
        (Extrapolation(185.0, 40.0, 40.0, 0.8, "omega_inf + a*N**-nu"), "more than half"),
        (Extrapolation(185.0, 2.0, 40.0, 5.0, "omega_inf + a*N**-nu"), "at the fit's bound"),
        (Extrapolation(185.0, 2.0, 40.0, 1.0, "omega_inf + a/N"), ""),
    ],
)
def test_judge_names_the_reason(fit, expected):
    note = judge(fit, np.arange(150.0, 220.5, 2.5), 4)
    assert (expected in note) if expected else note == ""

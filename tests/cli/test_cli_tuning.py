"""The tuning has one source in every command that takes `--tuning` or `--set tuning=`:
what is computed, printed, stored and cached is the same tuning, however it is spelled."""

import json
import re

import numpy as np
import pytest
import xarray as xr

from metrosync.cli import main

THEORY = ["theory", "--bpm", "180,190", "--sigma", "0.75", "--no-simulate", "--no-progress"]
SPELLINGS = {
    "option": ["--tuning", "steady-swing"],
    "set": ["--set", "tuning=steady-swing"],
}


def _theory(tmp_path, capsys, name, extra, cache):
    out = tmp_path / f"{name}.nc"
    assert main([*THEORY, *extra, "--cache", str(cache), "--out", str(out)]) == 0
    return xr.load_dataset(out, engine="h5netcdf"), capsys.readouterr().out


def test_theory_both_spellings_give_the_same_numbers_and_label(tmp_path, capsys):
    cache = tmp_path / "cache"
    # The small-amplitude curve first, into the same cache: a key without the tuning
    # would hand its numbers to the steady-swing runs below.
    small, small_text = _theory(tmp_path, capsys, "small", [], cache)
    assert small.attrs["tuning"] == "small-amplitude"
    assert "small-amplitude tuning" in small_text
    # Small-amplitude tuning: a metronome marked 180 ticks about 7 BPM slower.
    assert np.all(small.free_bpm.values < small.bpm.values - 3)
    results = {
        name: _theory(tmp_path, capsys, name, extra, cache) for name, extra in SPELLINGS.items()
    }
    for ds, text in results.values():
        assert ds.attrs["tuning"] == "steady-swing"
        assert "steady-swing tuning" in text and "small-amplitude" not in text
        # Steady-swing tuning: it ticks at its marking.
        np.testing.assert_allclose(ds.free_bpm.values, ds.bpm.values, atol=0.1)
        assert not np.allclose(ds.k.values, small.k.values)
    (a, a_text), (b, b_text) = results.values()
    for name in ("k", "alpha", "free_bpm", "k_estimate", "spread_factor", "omega_c"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert a_text.replace("option.nc", "set.nc") == b_text


def test_theory_refuses_two_different_tunings(capsys):
    argv = [*THEORY, "--no-cache", "--tuning", "small-amplitude", "--set", "tuning=steady-swing"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "`--tuning small-amplitude` and `--set tuning=steady-swing` disagree" in err


def test_simulate_set_tuning_labels_and_computes_the_same_tuning(tmp_path, capsys):
    out = tmp_path / "s.nc"
    argv = ["simulate", "--n", "1", "--duration", "20", "--bpm", "180", "--out", str(out)]
    assert main([*argv, "--set", "tuning=steady-swing"]) == 0
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert ds.attrs["tuning"] == "steady-swing"
    # Measured on a moving disk, so within 1 BPM; the small-amplitude tuning is 7 away.
    np.testing.assert_allclose(ds.tick_rate_bpm.values, 180.0, atol=1.0)
    assert main(argv) == 0
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert ds.attrs["tuning"] == "small-amplitude"
    assert float(ds.tick_rate_bpm.max()) < 176


@pytest.mark.parametrize("spec", ["steady-swing", "small-amplitude"])
def test_sweep_set_tuning_reaches_the_model(tmp_path, capsys, spec):
    out = tmp_path / "w.nc"
    argv = ["sweep", "--bpm", "180,190", "--n", "2", "--runs", "1", "--duration", "2",
            "--set", f"tuning={spec}", "--no-progress", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert xr.load_dataset(out, engine="h5netcdf").attrs["model_tuning"] == spec


def test_playground_takes_the_steady_swing_tuning(tmp_path, capsys):
    # The page inverts the steady-swing tuning with the package's own spline (the
    # browser test compares its L2 with `l2_for_bpm`), so the label is what it computes.
    out = tmp_path / "p.html"
    assert main(["playground", "--set", "tuning=steady-swing", "--out", str(out)]) == 0
    constants = json.loads(
        re.search(r'id="config">(.*?)</script>', out.read_text(encoding="utf-8"), re.S)[1]
    )["presets"]["default+changes"]["constants"]
    assert constants["tuning"] == "steady-swing" and constants["steady_swing"]["knots"]
    assert main(["playground", "--set", "tuning=small-amplitude", "--out", str(out)]) == 0

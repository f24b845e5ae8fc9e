"""Verdicts follow from the numbers: checked on constructed data with known answers."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from metrosync.paper import claims


def _cases(x, means, name, runs=10, sigma=0.05):
    r_eq = np.array([[m + sigma * s for s in np.linspace(-1.5, 1.5, runs)] for m in means])
    ds = xr.Dataset(
        {"r_eq": (("case", "run"), r_eq)},
        coords={"case": [f"c{i}" for i in range(len(x))], name: ("case", list(x))},
        attrs={"study": "test"},
    )
    ds["r_eq_mean"] = ds.r_eq.mean("run")
    ds["sigma_r"] = ds.r_eq.std("run", ddof=1)
    return ds


def test_weighted_slope_recovers_a_line():
    x = np.array([1.0, 2.0, 3.0, 4.0])
    slope, se = claims.weighted_slope(x, 0.3 + 0.1 * x, np.full(4, 0.05), runs=10)
    assert slope == pytest.approx(0.1)
    assert se == pytest.approx(0.05 / np.sqrt(10) / np.sqrt(np.sum((x - x.mean()) ** 2)))


@pytest.mark.parametrize(
    ("means", "verdict"),
    [
        ([0.4, 0.6, 0.8], "reproduced"),
        ([0.6, 0.6, 0.6], "inconclusive"),
        ([0.8, 0.6, 0.4], "not reproduced"),
    ],
)
def test_frequency_trend_verdict(means, verdict):
    assert claims.claim_frequency_trend(_cases([160, 184, 208], means, "bpm")).verdict == verdict


def test_size_trend_wants_a_decrease():
    assert claims.claim_size_trend(_cases([2, 4, 7], [0.9, 0.8, 0.7], "n")).verdict == "reproduced"
    assert (
        claims.claim_size_trend(_cases([2, 4, 7], [0.7, 0.8, 0.9], "n")).verdict == "not reproduced"
    )


def _sweep(centre=185.0):
    bpm = np.arange(150.0, 221.0, 5.0)
    ns = [7, 256]
    mean = np.stack([0.5 + 0.5 * np.tanh((bpm - centre) / w) for w in (25.0, 4.0)])
    sig = np.stack([0.05 + 0.1 * np.exp(-(((bpm - centre) / w) ** 2)) for w in (40.0, 6.0)])
    return xr.Dataset(
        {"r_eq_mean": (("n", "bpm"), mean), "sigma_r": (("n", "bpm"), sig)},
        coords={"n": ns, "bpm": bpm},
    )


def test_sweep_features_find_the_transition():
    feats = claims.sweep_features(_sweep())
    assert feats[256]["omega_half"] == pytest.approx(185.0)
    assert feats[256]["peak_bpm"] == 185.0 and feats[256]["peak_interior"]
    assert feats[256]["max_slope"] > feats[7]["max_slope"]
    assert feats[256]["peak_width"] < feats[7]["peak_width"]
    assert claims.claim_transition(_sweep()).verdict == "reproduced"


def test_transition_elsewhere_is_only_partly_reproduced():
    verdict = claims.claim_transition(_sweep(centre=170.0))
    assert verdict.verdict == "partly reproduced"
    assert "170" in verdict.numbers


def test_identical_needs_every_run_complete():
    time = np.linspace(0, 100, 101)
    r_mean = np.minimum(1.0, time / 50)
    ds = xr.Dataset(
        {
            "r_eq": (("case", "run"), [[1.0, 1.0, 1.0], [1.0, 1.0, 0.02]]),
            "r_mean": (("case", "time"), [r_mean, r_mean]),
            "status": (("case", "run"), np.zeros((2, 3), dtype=np.int8)),
        },
        coords={"case": ["a", "b"], "n": ("case", [2, 4]), "time": time},
    )
    ds["r_eq_mean"] = ds.r_eq.mean("run")
    ds["sigma_r"] = ds.r_eq.std("run", ddof=1)
    partial = claims.claim_identical(ds)
    assert partial.verdict == "partly reproduced"
    assert "N = 4: 1 of 3 runs end at r_eq = 0.02" in partial.numbers
    ds["r_eq"] = ds.r_eq.where(ds.r_eq > 0.5, 0.3)
    assert claims.claim_identical(ds).verdict == "partly reproduced"
    ds["r_eq"] = ds.r_eq * 0 + [[1.0, 1.0, 1.0], [1.0, 0.3, 0.3]]
    assert claims.claim_identical(ds).verdict == "not reproduced"
    ds["r_eq"] = ds.r_eq.where(False, 1.0)
    verdict = claims.claim_identical(ds)
    assert verdict.verdict == "reproduced" and "50 s" in verdict.numbers


def test_every_claim_gets_a_verdict_even_without_studies():
    verdicts = claims.all_verdicts({})
    assert [v.claim for v in verdicts] == [1, 2, 3, 4, 5, 6]
    assert all(v.verdict in claims.VERDICTS for v in verdicts)
    assert all(v.verdict == "not assessed" for v in verdicts)

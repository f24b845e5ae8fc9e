"""A reduced reproduction (well under 2 minutes) shows each claim's direction.

Statistics are cut to the least that still separates the effects at fixed seeds:
identical metronomes reach r = 1; at N = 7, r rises with ω₀; for N = 256, σ_r peaks
inside the swept ω₀ range.
"""

from __future__ import annotations

import pytest

from metrosync.paper.claims import sweep_features
from metrosync.paper.pipeline import reproduce
from metrosync.paper.studies import FIG8_TOP, FIG10, FIG11, Statistics, reduced


@pytest.mark.slow
def test_reduced_reproduction_shows_the_papers_directions(tmp_path):
    studies = [
        reduced(FIG11, runs=4, duration=300.0),
        reduced(FIG8_TOP, runs=12, duration=400.0),
        reduced(FIG10, ns=(7, 256), bpms=(150.0, 165.0, 175.0, 185.0, 200.0, 220.0),
                stats=Statistics(8, 250.0)),
    ]  # fmt: skip
    rep = reproduce(tmp_path, studies=studies)
    verdicts = {v.claim: v for v in rep.verdicts}

    # claim 1: identical metronomes synchronize completely: most runs of every N reach
    # r = 1 (a small-N run may lock in anti-phase, which the report states)
    assert verdicts[1].verdict in ("reproduced", "partly reproduced")
    assert min(verdicts[1].values["r_eq_median"]) > 0.99

    # claim 2: at N = 7, equilibrium r rises with ω₀ (slope > 2 standard errors)
    assert verdicts[2].verdict == "reproduced"
    r = verdicts[2].values["r_eq_mean"]
    assert r[-1] > r[0] + 0.2

    # claim 4: σ_r peaks inside the swept range for the largest N, and the rise is
    # steeper there than for N = 7
    feats = sweep_features(rep.datasets["fig10"])
    assert feats[256]["peak_interior"]
    assert 150.0 < feats[256]["peak_bpm"] < 220.0
    assert feats[256]["max_slope"] > feats[7]["max_slope"]

    # the cost bound that keeps this test under 2 minutes even at 1e7 oscillator-steps/s
    # (a deterministic count, unlike wall time on a shared machine)
    assert sum(r.total_work for r in rep.results) < 1.0e9

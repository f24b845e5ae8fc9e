"""The studies are declared as the paper states them, in both modes."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync import ParameterError
from metrosync.paper.catalogue import STUDIES, get_studies
from metrosync.paper.studies import (
    FIG8_BOTTOM,
    FIG8_TOP,
    FIG10,
    FIG11,
    TABLE1_SIGMA,
    TABLE2_SIGMA,
    Z_STUDY,
    Statistics,
    paper_sigma_to_bpm,
)


def test_sigma_conversion_matches_model_notes():
    # docs/model.md §6.4: 8e-7 beats per 64 µs tick is 0.75 BPM.
    assert paper_sigma_to_bpm(8.0) == pytest.approx(0.75, rel=1e-12)
    assert paper_sigma_to_bpm(8.5) == pytest.approx(8.5e-7 / 64e-6 * 60)
    np.testing.assert_allclose(paper_sigma_to_bpm([0.0, 16.0]), [0.0, 1.5])


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf")])
def test_sigma_conversion_rejects_non_table_values(bad):
    with pytest.raises(ParameterError, match="`value`"):
        paper_sigma_to_bpm(bad)


def test_fig8_uses_the_tables():
    assert [c.bpm for c in FIG8_TOP.cases] == [float(b) for b in TABLE1_SIGMA]
    assert all(c.n == 7 for c in FIG8_TOP.cases)
    for case, value in zip(FIG8_TOP.cases, TABLE1_SIGMA.values(), strict=True):
        assert case.sigma_bpm == pytest.approx(paper_sigma_to_bpm(value))
    assert [c.n for c in FIG8_BOTTOM.cases] == list(TABLE2_SIGMA)
    assert all(c.bpm == 192.0 for c in FIG8_BOTTOM.cases)
    assert FIG8_BOTTOM.cases[0].sigma_bpm == pytest.approx(paper_sigma_to_bpm(5.1))


@pytest.mark.parametrize("mode", ["quick", "full"])
def test_fig10_spans_the_papers_range(mode):
    grid = FIG10.grid(mode)
    assert min(grid.bpms) <= 150 and max(grid.bpms) >= 220
    assert min(grid.ns) == 7 and max(grid.ns) >= 256
    assert FIG10.sigma_bpm == pytest.approx(0.75)


def test_fig11_is_identical_metronomes_up_to_64():
    assert all(c.sigma_bpm == 0 and c.bpm == 192 for c in FIG11.cases)
    assert min(c.n for c in FIG11.cases) == 2 and max(c.n for c in FIG11.cases) == 64


def test_full_mode_has_the_papers_statistics():
    for study in (FIG8_TOP, FIG8_BOTTOM, FIG11):
        assert study.full.runs == 100
    assert FIG10.full.stats.runs == 100
    assert Z_STUDY.full.duration == 4000.0 and Z_STUDY.dt == 0.01
    theta2 = np.array(Z_STUDY.full.theta2)
    assert theta2.min() == -0.1 and theta2.max() == 0.1 and Z_STUDY.theta1 == 0.1


def test_z_regimes_are_the_papers_three_plus_ours():
    drives = []
    for regime in Z_STUDY.regimes:
        changes = dict(regime.changes)
        drives.append(changes.get("drive", {"default": 6e-5, "boda2013": 6e-4}[regime.preset]))
    assert drives[:3] == [0.0, 6e-5, 6e-4]
    assert dict(Z_STUDY.regimes[0].changes) == {"c_theta": 0.0, "c_phi": 0.0, "drive": 0.0}
    assert [r.from_paper for r in Z_STUDY.regimes] == [True, True, True, False]


def test_quick_is_much_cheaper_than_full():
    from metrosync.paper.runner import points_of

    def work(mode):
        return sum(p.work for study in STUDIES for p in points_of(study, mode))

    assert work("quick") < work("full") / 10
    for study in STUDIES:  # no study asks more of quick than of full
        quick = sum(p.work for p in points_of(study, "quick"))
        assert quick <= sum(p.work for p in points_of(study, "full")), study.name


def test_lookup_errors_name_the_valid_choices():
    assert get_studies(["fig10"]) == (FIG10,)
    with pytest.raises(ParameterError, match="fig8_top"):
        get_studies(["fig99"])
    with pytest.raises(ParameterError, match="quick"):
        FIG10.grid("medium")
    with pytest.raises(ParameterError, match="`runs`"):
        Statistics(runs=0, duration=1.0)


def test_each_study_runs_its_points_with_its_own_declared_stepping():
    from metrosync.paper.claims_map import CLAIMS_MAP, _plan
    from metrosync.paper.readings import SCREEN, Reading
    from metrosync.paper.runner import points_of

    own = {s.name: s.stepping for s in STUDIES if hasattr(s, "stepping")}
    # every study with points declares one, except the claims map (below)
    assert set(own) == {s.name for s in STUDIES if points_of(s, "quick")} - {CLAIMS_MAP.name}
    for study in STUDIES:
        if study.name not in own:
            continue
        for spec in points_of(study, "quick"):
            stepping = study.stepping
            assert spec.kwargs["integrator"] == stepping.integrator, study.name
            assert spec.kwargs["dt"] == stepping.dt, study.name
    # the claims map runs each claim with the step of the study that checks it
    for reading in (Reading(), *CLAIMS_MAP.readings[1:3]):
        for _, _, study, specs in _plan([reading], SCREEN):
            for spec in specs:
                assert spec.kwargs["integrator"] == own[study.name].integrator
                assert spec.kwargs["dt"] == own[study.name].dt


def test_a_stepping_refuses_an_unknown_scheme_or_step():
    from metrosync.paper.runner import PAPER_STEPPING, Stepping

    assert PAPER_STEPPING.kwargs() == {"dt": 0.01, "integrator": "verlet"}
    assert Stepping("located", 0.02).describe() == "located, dt = 0.02 s"
    with pytest.raises(ParameterError, match="verlet"):
        Stepping("exact", 0.01)  # not a fixed-step scheme
    with pytest.raises(ParameterError, match="`dt`"):
        Stepping("located", 0.0)

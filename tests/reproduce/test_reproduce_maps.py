"""The σ map and the claims map: readings, shared points, verdicts, resumption, tables."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from metrosync import ParameterError
from metrosync.paper.claims import Verdict
from metrosync.paper.claims_map import CLAIMS_MAP, rank
from metrosync.paper.map_report import theory_half_note, which_reading
from metrosync.paper.readings import (
    BEST,
    READINGS,
    SCREEN,
    TODAY,
    Reading,
    reading_studies,
)
from metrosync.paper.runner import points_of, run_study
from metrosync.paper.sigma_map import SIGMA_MAP, sigma_at
from metrosync.sweeps import PointStore


def test_the_readings_are_every_combination_of_the_axes_once():
    # σ × tuning × drive × inertia with the reaction on, and today's reading without it
    assert len(READINGS) == 2 * 2 * 3 * 2 + 1 and len(set(READINGS)) == len(READINGS)
    assert [r for r in READINGS if r.reaction == "off"] == [Reading(reaction="off")]
    assert READINGS[0] == TODAY and TODAY.changes() == {}
    quick = CLAIMS_MAP.readings_of("quick")
    assert quick[0] == TODAY and len(quick) == 7
    # quick mode: today's reading and one change of one axis at a time
    axes = ("sigma", "tuning", "drive", "inertia", "reaction")
    assert all(sum(getattr(r, a) != getattr(TODAY, a) for a in axes) <= 1 for r in quick)


def test_each_reading_changes_what_it_names():
    assert Reading(drive="published").changes() == {"drive": 6e-4}
    assert Reading(drive="c_theta*10").changes() == {"c_theta": 5e-4, "drive": 6e-4}
    assert Reading(inertia="constant").changes() == {"inertia": 0.25515}
    assert Reading(tuning="steady-swing").changes() == {"tuning": "steady-swing"}
    assert Reading(reaction="off").changes() == {"escapement_reaction": False}
    assert Reading(reaction="off").name.endswith("/no-reaction")
    assert Reading(drive="published").overturns and not Reading(drive="c_theta*10").overturns
    with pytest.raises(ParameterError, match="`drive`"):
        Reading(drive="M/100")


def test_a_period_reading_doubles_every_spread_and_keeps_seeds():
    beat = reading_studies(TODAY, SCREEN)
    period = reading_studies(Reading(sigma="period"), SCREEN)
    for claim in (2, 3):
        for a, b in zip(beat[claim].cases, period[claim].cases, strict=True):
            assert b.sigma_bpm == pytest.approx(2 * a.sigma_bpm)
    assert period[4].sigma_bpm == pytest.approx(1.5)
    seeds = [p.kwargs["seed"] for p in points_of(beat[2], "quick")]
    assert seeds == [p.kwargs["seed"] for p in points_of(period[2], "quick")]
    # claims 1 and 5 do not depend on σ: the same points, simulated once
    for claim in (1, 5):
        keys = [p.key for p in points_of(beat[claim], "quick")]
        assert keys == [p.key for p in points_of(period[claim], "quick")]


def test_todays_reading_at_full_statistics_reuses_the_reproductions_points():
    from metrosync.paper.readings import BEST
    from metrosync.paper.studies import FIG8_BOTTOM, FIG8_TOP, FIG10, FIG11

    studies = reading_studies(TODAY, BEST)
    for claim, own in ((1, FIG11), (2, FIG8_TOP), (3, FIG8_BOTTOM), (4, FIG10)):
        keys = {p.key for p in points_of(studies[claim], "quick")}
        assert keys <= {p.key for p in points_of(own, "full")}, claim


def test_the_z_study_reads_both_drives_through_the_reading():
    regimes = reading_studies(Reading(drive="c_theta*10"), SCREEN)[5].regimes
    free, small, large = (dict(r.changes) for r in regimes)
    assert free["drive"] == free["c_theta"] == free["c_phi"] == 0.0
    assert small == {"c_theta": 5e-4, "drive": 6e-5} and large == {"c_theta": 5e-4, "drive": 6e-4}
    today = [dict(r.changes) for r in reading_studies(TODAY, SCREEN)[5].regimes]
    assert today[1] == {"drive": 6e-6} and today[2] == {}


def _verdicts(scores: dict[Reading, list[str]], peak: dict[Reading, float]):
    out = {}
    for reading, row in scores.items():
        for claim, v in enumerate(row, start=1):
            values = {"features": {64: {"peak_bpm": peak[reading]}}} if claim == 4 else {}
            out[(reading, claim)] = Verdict(claim, v, "", None, values)
    return out


def test_readings_rank_by_score_then_by_distance_to_185_bpm():
    a, b, c = TODAY, Reading(sigma="period"), Reading(inertia="constant")
    rep, part, no = "reproduced", "partly reproduced", "not reproduced"
    verdicts = _verdicts(
        {
            a: [rep, rep, part, part, no],
            b: [rep, rep, rep, part, no],
            c: [rep, rep, part, part, no],
        },
        {a: 170.0, b: 200.0, c: 186.0},
    )
    assert rank([a, b, c], verdicts) == [b, c, a]


def test_sigma_at_interpolates_and_propagates_the_errors():
    sigmas = [0.5, 1.0, 1.5]
    value, err = sigma_at(sigmas, [160.0, 180.0, 200.0], [0.0, 0.0, 0.0], 185.0)
    assert value == pytest.approx(1.125) and err == 0.0 or math.isnan(err)
    value, err = sigma_at(sigmas, [160.0, 180.0, 200.0], [1.0, 1.0, 1.0], 185.0)
    # σ* = 1 + (185 - w1)/(w2 - w1) / 2: dσ*/dw ≈ 1/40 per BPM at each end
    assert value == pytest.approx(1.125) and err == pytest.approx(math.hypot(0.75, 0.25) / 40,
                                                                  rel=0.1)  # fmt: skip
    assert all(math.isnan(v) for v in sigma_at(sigmas, [150.0, 160.0, 170.0], [1, 1, 1], 185.0))


def test_the_theory_half_column_is_explained_only_when_empty():
    import xarray as xr

    empty = xr.Dataset({"theory_omega_half": (("tuning", "sigma"), np.full((2, 3), np.nan))})
    assert "quick mode leaves that simulation out" in theory_half_note(empty)
    filled = empty.copy(deep=True)
    filled.theory_omega_half[0, 1] = 183.2
    assert theory_half_note(filled) is None


def test_which_reading_names_the_reading_or_neither():
    assert which_reading(0.76, 0.05) == "beats per tick"
    assert which_reading(1.45, 0.05) == "periods per tick"
    assert which_reading(1.1, 0.05).startswith("neither: 1.47 ×")
    assert which_reading(math.nan, math.nan) == "outside the σ swept"


def test_the_sigma_map_declares_windows_around_each_onset():
    for mode in ("quick", "full"):
        g = SIGMA_MAP.grid(mode)
        for tuning in SIGMA_MAP.tunings:
            for sigma in SIGMA_MAP.sigmas:
                window = SIGMA_MAP.window(tuning, sigma, mode)
                assert len(window) >= 5 and np.allclose(np.diff(window), g.step)
    assert max(SIGMA_MAP.full.ns) >= 256
    assert SIGMA_MAP.sigmas == (0.5, 0.75, 1.0, 1.25, 1.5)
    # the same draws for every σ and tuning at one (N, ω₀)
    seeds = {}
    for p in points_of(SIGMA_MAP, "quick"):
        seeds.setdefault((p.kwargs["n"], p.kwargs["bpm"]), set()).add(p.kwargs["seed"])
    assert all(len(s) == 1 for s in seeds.values())


def test_a_claims_map_interrupted_midway_resumes_and_equals_an_uninterrupted_one(
    tmp_path, monkeypatch, maps
):
    _, study = maps
    clean = run_study(study, "quick", tmp_path / "clean")
    real_write = PointStore.write
    written = []

    def write_then_interrupt(self, ds, **kw):
        out = real_write(self, ds, **kw)
        written.append(ds.attrs["key"])
        if len(written) == 9:
            raise KeyboardInterrupt  # as Ctrl-C would, after 9 stored points
        return out

    monkeypatch.setattr(PointStore, "write", write_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        run_study(study, "quick", tmp_path / "cut")
    monkeypatch.setattr(PointStore, "write", real_write)
    store = PointStore(tmp_path / "cut")
    assert len(list(store.points.glob("*.nc"))) == 9
    resumed = run_study(study, "quick", tmp_path / "cut")
    logged = store.logged_keys()
    assert len(logged) == len(set(logged))  # nothing was computed twice
    assert resumed.cached_points == 9 and resumed.points == clean.points
    for name in ("verdict", "numbers", "score", "rank"):
        xr.testing.assert_identical(resumed.dataset[name], clean.dataset[name])


def test_a_steady_swing_reading_whose_drive_overturns_is_not_tuned_to_a_missing_swing():
    """No steady swing exists under the published drive, so the steady-swing tuning has
    nothing to tune to: claims 1–4 are not simulated, and the z-study's large regime keeps
    the small-amplitude tuning (every point is buildable)."""
    from metrosync.paper.claims_map import _judge, _plan

    reading = Reading(tuning="steady-swing", drive="published")
    assert reading.overturns and not reading.tunable
    assert Reading(drive="published").tunable and Reading(tuning="steady-swing").tunable
    plan = _plan([reading], SCREEN)
    assert [claim for _, claim, _, specs in plan if specs] == [5]
    for _, claim, study, specs in plan:
        if claim < 5:
            verdict = _judge(reading, claim, study, specs, {})
            assert verdict.verdict == "not reproduced"
            assert "no steady swing" in verdict.numbers
    large = reading_studies(reading, SCREEN)[5].regimes[-1]
    assert "tuning" not in dict(large.changes) and dict(large.changes)["drive"] == 6e-4


def test_the_claims_map_guards_overturning_readings(tiny):
    ds = tiny.datasets["claims_map"]
    published = ds.sel(reading=Reading(drive="published").name, level="screen")
    assert str(published.verdict.sel(claim=2).item()) == "not reproduced"
    assert "overturn" in str(published.numbers.sel(claim=2).item())
    assert str(published.numbers.sel(claim=4).item()).startswith("not simulated")
    # the best reading was run again; the others were not
    assert int((ds.verdict.sel(level="best") != "").any("claim").sum()) == 1


def test_quick_maps_produce_their_tables_and_the_report_ends_with_a_conclusion(tiny):
    text = tiny.report.read_text()
    smap = tiny.datasets["sigma_map"]
    section = text[text.index("## The σ map") : text.index("## The claims map")]
    for sigma in smap.sigma.values:
        assert f"| small-amplitude | {sigma:g} |" in section
    assert "σ* from ω_c(∞), peak" in section and "Agreement of theory and simulation" in section
    assert set(smap.estimator.values) == {"peak", "rise", "rise, largest N", "theory"}
    assert np.isfinite(smap.theory_omega_c).all()
    # Quick mode does not simulate the phase model: its column is empty, and says why.
    assert np.isnan(smap.theory_omega_half).all()
    assert "quick mode leaves that simulation out" in section
    assert "`metrosync reproduce --full` runs it" in section
    assert {"omega_c_rise", "omega_inf_peak", "sigma_at_target"} <= set(smap.data_vars)
    cmap = tiny.datasets["claims_map"]
    table = text[text.index("## The claims map") : text.index("## Parameter consistency")]
    for name in cmap.reading.values:
        assert f"| {name} |" in table
    assert text.rstrip().splitlines()[0].startswith("#")
    last = text[text.rindex("\n## ") :]
    assert last.startswith("\n## Conclusion") and "reproduces most of the paper" in last
    for name in ("sigma_map", "claims_map"):
        assert (tiny.out / "figures" / f"{name}.png").stat().st_size > 1000


def test_every_point_of_the_full_claims_map_can_be_built():
    """Each reading's points, at both levels, build an ensemble: no ω₀ (or frequency
    draw within 5 σ) outside the reading's tunable range, no tuning without a swing.
    A point that cannot be built would otherwise fail minutes into `reproduce --full`."""
    from metrosync import build_ensemble, get_preset
    from metrosync.paper.claims_map import _plan

    built = set()
    for level in (SCREEN, BEST):
        for *_, specs in _plan(CLAIMS_MAP.readings_of("full"), level):
            for spec in specs:
                if spec.key in built:
                    continue
                kw = dict(spec.kwargs)
                changes = kw.pop("changes", None) or {}
                params = get_preset(kw.pop("preset"), warn=False).with_changes(**changes)
                names = ("n", "bpm", "sigma_bpm", "runs", "seed", "theta0", "theta_dot0")
                build_ensemble(params=params, **{k: kw[k] for k in names if k in kw})
                built.add(spec.key)
    assert len(built) > 1000
    # The steady-swing tuning with c_θ × 10 reaches only 212.7 BPM: its Fig. 10 stops short.
    narrow = Reading(tuning="steady-swing", drive="c_theta*10")
    assert max(reading_studies(narrow, BEST)[4].quick.bpms) < 212.7 - 5 * 0.75

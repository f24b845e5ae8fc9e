"""The large-N study's report section: read from a merged study sweep, its numbers
and figures, and the check it adds to claim 4."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from metrosync.cli import main
from metrosync.errors import ParameterError
from metrosync.paper.claims import Verdict
from metrosync.paper.large_n import (
    amend_claim_4,
    claim_4_check,
    large_n_lines,
    onset,
    read_large_n,
    rise_span,
    scaling_words,
    settled_lines,
    sigma_at_paper_onset,
)

QUICK = Path(__file__).resolve().parents[2] / "studies" / "large_n" / "quick.toml"


def test_rise_span_interpolates_between_grid_points():
    bpm = np.array([160.0, 165.0, 170.0, 175.0, 180.0])
    r = np.array([0.1, 0.1, 0.3, 0.9, 1.1])  # rise 1.0: 10 % at 0.2, 90 % at 1.0
    assert rise_span(bpm, r) == pytest.approx((167.5, 177.5))


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    folder = tmp_path_factory.mktemp("large_n")
    out = folder / "quick.nc"
    assert main(["sweep", str(QUICK), "--out", str(out), "--no-progress"]) == 0
    return read_large_n(out, n_boot=20), folder


def test_the_section_reports_every_estimate_and_draws_both_figures(quick):
    study, folder = quick
    assert study.sizes == (8, 16, 32) and study.sigma_bpm == 0.75
    assert study.runs == (6, 18) and 0 < study.largest_error <= 0.06
    assert study.work == pytest.approx(
        float((study.r.notnull().sum("run") * study.r.n).sum()) * 6000
    )
    lines = large_n_lines([study], folder / "figures", folder)
    text = "\n".join(lines)
    assert "| 0.75 | 8, 16, 32 | 6–18 |" in text
    assert (folder / "figures" / "large_n_sigma_0.75_collapse.png").stat().st_size > 1000
    assert (folder / "figures" / "large_n_sigma_0.75_critical.png").stat().st_size > 1000
    value, error, why = onset(study)
    assert f"{value:.1f} ± {error:.1f} BPM" in text and why in text
    words, holds = claim_4_check([study])
    assert f"Claim 4 from this study: {words}: {'yes' if holds else 'no'}." in text


def test_a_file_without_several_sizes_is_refused(tmp_path):
    out = tmp_path / "one.nc"
    args = ["sweep", "--n", "8", "--bpm", "170:180:5", "--runs", "3", "--duration", "60",
            "--dt", "0.02", "--out", str(out), "--no-progress"]  # fmt: skip
    assert main(args) == 0
    with pytest.raises(ParameterError, match="is not a large-N study"):
        read_large_n(out)


def test_claim_4_takes_where_the_transition_sits_from_the_study(quick):
    study, _ = quick
    fig10 = Verdict(
        4,
        "partly reproduced",
        "Fig. 10's numbers.",
        "fig10",
        {"checks": {"the rise sharpens with N": True, "the transition sits within 5 BPM": False}},
    )
    amended = amend_claim_4(fig10, [study])
    words, holds = claim_4_check([study])
    assert amended.values["checks"] == {"the rise sharpens with N": True, words: holds}
    assert amended.verdict == ("reproduced" if holds else "partly reproduced")
    assert amended.numbers.startswith("Fig. 10's numbers. From the large-N study")
    unassessed = Verdict(4, "not assessed", "Fig. 10 did not run.")
    assert amend_claim_4(unassessed, [study]) is unassessed


@pytest.mark.parametrize(
    ("name", "words"), [("nope.nc", "does not exist"), ("junk.nc", "not a NetCDF")]
)
def test_reproduce_refuses_a_bad_large_n_file_before_any_work(tmp_path, capsys, name, words):
    (tmp_path / "junk.nc").write_text("not a sweep")
    out = tmp_path / "out"
    code = main(["reproduce", "--large-n", str(tmp_path / name), "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert "`large_n` (--large-n)" in err and words in err
    assert not (out / "REPORT.md").exists()


def _shifted(study, sigma, by):
    """``study`` at another σ with every onset estimate moved by ``by`` BPM."""
    k, f, (v, stat, syst) = study.kuramoto, study.free, study.rise_inf
    return replace(
        study,
        sigma_bpm=sigma,
        kuramoto=replace(k, x_c=k.x_c + by),
        free=replace(f, x_c=f.x_c + by),
        rise_inf=(v + by, stat, syst),
    )


def test_the_sigma_of_the_paper_onset_lies_on_the_line_through_two_studies(quick):
    study, _ = quick
    assert sigma_at_paper_onset([study]) is None
    w, e, _ = onset(study)
    other = _shifted(study, 1.5, 185.0 - w + 2.0)  # the onset 2 BPM past 185 at σ = 1.5
    sigma, error, between = sigma_at_paper_onset([study, other])
    w2 = onset(other)[0]
    assert w + (sigma - 0.75) * (w2 - w) / 0.75 == pytest.approx(185.0)
    assert between and 0 < error < 1
    # Both onsets below 185: the σ is extrapolated and said to be.
    lower = _shifted(study, 1.5, 185.0 - w - 2.0)
    assert sigma_at_paper_onset([study, lower])[2] is False
    text = settled_lines([study, lower])[0]
    assert "extrapolated from the study's σ" in text and "σ = 1.5 BPM" in text


def test_the_scaling_is_called_kuramoto_only_when_his_exponents_collapse(quick):
    study, _ = quick
    good = replace(study.kuramoto, best=replace(study.kuramoto.best, chi2_dof=1.0))
    bad = replace(study.kuramoto, best=replace(study.kuramoto.best, chi2_dof=50.0))
    assert scaling_words(replace(study, kuramoto=good)).endswith("the scaling is Kuramoto's")
    assert "do not collapse" in scaling_words(replace(study, kuramoto=bad))


def test_the_sigma_map_and_theory_are_compared_at_the_study_sigma(quick):
    study, _ = quick
    cells = {
        "omega_inf_rise": [170.0, 180.0],
        "omega_inf_rise_err": [1.0, 3.0],
        "theory_omega_c": [160.0, 170.0],
        "theory_omega_c_low": [159.0, 169.0],
        "theory_omega_c_high": [161.0, 171.0],
    }
    sigma_map = xr.Dataset(
        {k: (("tuning", "sigma"), [v]) for k, v in cells.items()},
        coords={"tuning": [study.tuning], "sigma": [0.5, 1.0], "n": [4, 8, 16]},
        attrs={"runs": 3, "duration": 60.0},
    )
    text = settled_lines([study], sigma_map)[0]
    # σ = 0.75 halfway: the map's values interpolated in σ.
    assert "(N ≤ 16, 3 runs × 60 s a point) extrapolates to 175.0 ± 2.0 BPM" in text
    assert "threshold is 165.0 BPM [164.0, 166.0]" in text
    other = sigma_map.assign_coords(tuning=["another tuning"])
    assert "σ map" not in settled_lines([study], other)[0]
    assert "σ map" not in settled_lines([study], sigma_map.assign_coords(sigma=[1.0, 2.0]))[0]


def test_the_kept_study_results_reach_their_target_error():
    """The study's merged sweeps that `make run` reads: every point's mean r_eq to the
    grid file's target error, or the point stopped at its cap of draws."""
    results = QUICK.parent / "results"
    kept = sorted(results.glob("*.nc"))
    assert kept, f"no study results in {results}"
    for path in kept:
        ds = xr.load_dataset(path, engine="h5netcdf")
        assert ds.n.values.tolist() == [64, 256, 1024, 4096]
        target, cap = ds.attrs["target_error"], ds.attrs["max_runs"]
        reached = (ds.r_eq_error <= target) | (ds.n_runs >= cap)
        assert bool(reached.all()), f"{path.name}: points short of the target"
        assert int(ds.n_runs.min()) >= 48 and ds.attrs["fixed_duration"] == 3000

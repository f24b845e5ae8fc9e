"""`reproduce` writes every file it promises, with figures and an honest report."""

from __future__ import annotations

import re
import shutil

import pytest
import xarray as xr

from metrosync import reproduce as exported
from metrosync.paper.pipeline import kept_points, plan, reproduce


def test_the_package_exports_the_entry_point():
    assert exported is reproduce


def test_every_study_leaves_data_figures_and_a_report(tiny):
    out = tiny.out
    for name in ("fig8_top", "fig8_bottom", "fig10", "fig11", "z"):
        assert xr.load_dataset(out / f"{name}.nc", engine="h5netcdf").attrs["study"] == name
        for ext in ("png", "pdf"):
            assert (out / "figures" / f"{name}.{ext}").stat().st_size > 1000
    assert (out / "consistency.nc").exists()
    assert not list(out.rglob("*.partial"))


def test_report_lists_every_claim_discrepancy_and_timing(tiny):
    text = tiny.report.read_text()
    for claim in range(1, 7):
        assert f"### Claim {claim}:" in text
    for topic in ("σ units", "Drive M", "L2 range", "Disk inertia J(N)", "Wall time"):
        assert topic in text
    assert "](figures/fig10.png)" in text
    assert "Fig. 9" in text and "Skipped: no light-gate data" in text
    assert "Estimated `--full` total" in text
    for result in tiny.results:
        assert f"| {result.study.name} |" in text


def full_estimate_hours(text: str) -> float:
    match = re.search(r"Estimated `--full` total: about ([\d.]+) (s|min|h)\b", text)
    assert match, text
    return float(match[1]) / {"s": 3600, "min": 60, "h": 1}[match[2]]


def test_a_cached_rerun_reports_the_cost_of_its_points_and_names_them(tiny, studies, tmp_path):
    out = tmp_path / "again"
    shutil.copytree(tiny.out, out)
    again = reproduce(out, studies=studies)
    assert all(r.cached_points == r.points for r in again.results)
    text = again.report.read_text()
    timing = text[text.index("## Wall time") : text.index("## Figures")]
    assert "nan" not in timing.lower()
    for r in again.results:
        if r.points:
            assert f"- `{r.study.name}`: all {r.points} points" in timing
            assert r.throughput == pytest.approx(
                next(t for t in tiny.results if t.study.name == r.study.name).throughput
            )
    first = full_estimate_hours(tiny.report.read_text())
    assert first > 0 and full_estimate_hours(text) == pytest.approx(first, rel=0.2)
    assert "No point was reused" in tiny.report.read_text()


def test_plan_and_kept_points_count_what_an_interrupted_run_left(tiny, studies):
    kept, total = kept_points(tiny.out, "quick", studies)
    assert kept == total == len(plan("quick", studies)) > 0
    assert kept_points(tiny.out, "full", studies)[0] == 0  # other statistics, other keys


def test_the_report_says_how_long_compiling_took_and_that_it_is_left_out():
    from types import SimpleNamespace

    from metrosync.paper.report import _compile_lines

    (line, _) = _compile_lines(SimpleNamespace(compile_s=41.6))
    assert line.startswith("Compiling the kernels took 42 s of this invocation's wall time")
    assert "metrosync/numba" in line
    assert _compile_lines(SimpleNamespace(compile_s=0.3)) == []  # loaded from the cache

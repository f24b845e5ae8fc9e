"""``metrosync reproduce`` on the command line."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from metrosync.cli import build_parser, main


def test_modes_are_exclusive_and_quick_is_the_default():
    parser = build_parser()
    assert parser.parse_args(["reproduce"]).mode == "quick"
    assert parser.parse_args(["reproduce", "--full"]).mode == "full"
    with pytest.raises(SystemExit):
        parser.parse_args(["reproduce", "--quick", "--full"])
    with pytest.raises(SystemExit):
        parser.parse_args(["reproduce", "--only", "fig99"])


def test_bad_experiment_folder_fails_before_any_work(tmp_path, capsys):
    code = main(
        ["reproduce", "--out", str(tmp_path / "out"), "--experiment", str(tmp_path / "nope")]
    )
    assert code == 2
    assert "metrosync reproduce: error: `--experiment`" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_one_study_end_to_end(tmp_path, capsys):
    code = main(
        ["reproduce", "--quick", "--only", "fig8_bottom", "--out", str(tmp_path), "--no-progress"]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "claim 3:" in printed and "claim 2: not assessed" in printed
    assert (tmp_path / "REPORT.md").exists() and (tmp_path / "figures" / "fig8_bottom.png").exists()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--scheduler", "foo"], "`scheduler` must be None"),
        (["--workers", "2"], "`n_workers` (--workers) = 2 applies to scheduler='local' only"),
        (["--scheduler", "local", "--workers", "0"], "`n_workers` (--workers) must be"),
    ],
)
def test_executor_options_are_checked_before_any_work(tmp_path, capsys, options, message):
    code = main(["reproduce", "--out", str(tmp_path / "out"), *options])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_local_cluster_gives_the_in_process_numbers(tmp_path):
    from metrosync.paper.runner import run_study
    from metrosync.paper.studies import FIG8_BOTTOM, reduced

    study = reduced(FIG8_BOTTOM, runs=2, duration=20.0)
    here = run_study(study, "quick", tmp_path / "here")
    there = run_study(study, "quick", tmp_path / "there", scheduler="local", n_workers=2)
    xr.testing.assert_identical(here.dataset.r_eq, there.dataset.r_eq)
    assert there.cached_points == 0 and there.points == 6


DOCS = Path(__file__).resolve().parents[2] / "docs"


def flat(text: str) -> str:
    return " ".join(text.split())


def test_help_docs_and_report_quote_the_same_measured_cost(tiny, capsys):
    from metrosync.paper.names import MEASURED_COST

    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    shown = flat(capsys.readouterr().out)
    readme = flat((DOCS / "reproducing.md").read_text())
    report = flat(tiny.report.read_text())
    for mode, cost in MEASURED_COST.items():
        assert flat(cost) in shown, mode
        assert flat(cost) in readme, mode
        assert flat(cost) in report, mode
    for stale in ("a few minutes", "hours"):
        assert stale not in shown


def test_the_docs_name_the_sweep_store_that_is_written(tmp_path, capsys):
    out = tmp_path / "sw.nc"
    args = ["sweep", "--bpm", "185,190", "--runs", "1", "--duration", "5", "--no-progress"]
    assert main([*args, "--out", str(out)]) == 0
    assert len(list((tmp_path / "sw.points" / "points").glob("*.nc"))) == 2
    assert "`sw.points/points/<hash>.nc`" in flat((DOCS / "sweeps.md").read_text())

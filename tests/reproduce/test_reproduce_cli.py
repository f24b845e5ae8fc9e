"""``metrosync reproduce`` on the command line."""

from __future__ import annotations

import pytest

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

"""Messages name the option that caused them; outputs are checked before any work."""

from pathlib import Path

import pytest

from metrosync import ParameterError
from metrosync.cli import main
from metrosync.paper.experiment import find_experiment

DATA = Path(__file__).parents[1] / "data"


def test_page_blames_max_rate_when_thinning_leaves_too_few_records(tmp_path, capsys):
    out = str(tmp_path / "p.html")
    assert main(["page", "--n", "2", "--duration", "5", "--max-rate", "0.001", "--out", out]) == 2
    err = capsys.readouterr().err
    assert "`max_rate` (--max-rate) = 0.001 records/s keeps fewer than two records" in err
    assert "give `max_rate` (--max-rate) >= 0.2." in err and "widen" not in err
    assert main(["page", "--n", "2", "--duration", "5", "--max-rate", "0.2", "--out", out]) == 0


def test_analyze_blames_grid_dt_with_rounded_numbers(capsys):
    assert main(["analyze", str(DATA / "clean.log"), "--grid-dt", "1e6"]) == 2
    err = capsys.readouterr().err
    assert "`grid_dt` (--grid-dt) = 1e+06 s leaves fewer than two grid times" in err
    assert "common span 0.461 .. 19.774 s; give `grid_dt` (--grid-dt) <= 9.66 s." in err
    assert "0.461408" not in err
    assert main(["analyze", str(DATA / "clean.log"), "--grid-dt", "9.66"]) == 0


def test_reproduce_checks_its_output_folder_before_any_study(tmp_path, capsys, monkeypatch):
    import metrosync.paper as paper

    def must_not_run(*args, **kwargs):
        raise AssertionError("reproduce started work")

    monkeypatch.setattr(paper, "reproduce", must_not_run)
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["reproduce", "--out", str(blocker)]) == 2
    assert "`--out` " in capsys.readouterr().err
    assert main(["reproduce", "--out", str(blocker / "res")]) == 2
    assert "is not a directory" in capsys.readouterr().err


def test_experiment_folders_take_simulated_logs_and_refuse_stray_files(tmp_path, capsys):
    folder = tmp_path / "exp" / "192"
    argv = ["simulate", "--n", "3", "--runs", "2", "--duration", "20", "--lightgate-dir",
            str(folder)]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()
    found = find_experiment(tmp_path / "exp")
    assert [p.name for p in found[192.0]] == ["run000.log", "run001.log"]
    (folder / "capture").write_bytes((DATA / "clean.log").read_bytes())  # no suffix at all
    (folder / ".hidden").write_text("ignored")
    assert [p.name for p in find_experiment(tmp_path / "exp")[192.0]] == [
        "capture", "run000.log", "run001.log"
    ]  # fmt: skip
    (folder / "notes.md").write_text("# what we did\n")
    with pytest.raises(ParameterError, match=r"notes.md' is not a light-gate capture"):
        find_experiment(tmp_path / "exp")


def test_a_virtual_gate_beyond_the_swing_warns_naming_the_option(tmp_path, capsys):
    argv = ["simulate", "--n", "2", "--runs", "1", "--duration", "10",
            "--lightgate-dir", str(tmp_path), "--gate-offset", "5"]  # fmt: skip
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "warning: the light gate at `offset` (--gate-offset) = 5 rad" in err
    assert "(2 never)" in err
    assert main(["analyze", str(DATA / "clean.log")]) == 0
    header = capsys.readouterr().out.splitlines()[1]
    assert header.endswith("passes bridged")

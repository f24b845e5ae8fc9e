"""What a new user met at the command line: each case refused or said as it is."""

import numpy as np
import pytest

from metrosync.cli import main


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "--bpm", "0"],
        ["simulate", "--bpm", "-5"],
        ["listen", "--bpm", "0"],
        ["theory", "--bpm", "0:10:1", "--no-simulate"],
    ],
)
def test_a_tempo_at_or_below_zero_is_refused_in_one_line(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "BPM: a tempo must be positive" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "argv",
    [
        ["critical", "x.nc", "--seed", "-1"],
        ["simulate", "--seed", "-1"],
        ["animate", "--phone-seed", "-2"],
        ["playground", "--seed", "-3"],
    ],
)
def test_every_seed_is_a_whole_number_from_zero_up(argv, capsys):
    with pytest.raises(SystemExit) as stopped:
        main(argv)
    assert stopped.value.code == 2
    assert f"a seed is a whole number from 0 up, got {argv[-1]}" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [["pantaleone", "--out", ""], ["simulate", "--out", " "], ["critical", ""]],
)
def test_an_empty_path_is_refused_not_read_as_the_current_folder(argv, capsys):
    with pytest.raises(SystemExit):
        main(argv)
    assert "expected a path, got" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ([], "small-amplitude tuning: the nominal BPM tunes the small-swing frequency"),
        (["--preset", "pantaleone2002"], "steady-swing tuning: the nominal BPM is the tick rate"),
        (["--set", "tuning=steady-swing"], "steady-swing tuning: the nominal BPM is the tick rate"),
    ],
)
def test_the_summary_says_what_the_chosen_tuning_means(extra, words, capsys):
    assert main(["simulate", "--n", "2", "--runs", "1", "--duration", "20", *extra]) == 0
    out = capsys.readouterr().out
    assert words in out
    if "steady-swing" in words:
        assert "a wider swing ticks slower" not in out


def test_the_growth_method_failing_names_the_pair_method(capsys):
    argv = ["theory", "--platform", "board", "--bpm", "180,200", "--no-simulate"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "the growth method does not apply; measure K with `method` (--method) = 'pair'" in err
    assert main([*argv, "--method", "pair", "--n", "2"]) == 0


def test_pantaleone_stopped_before_its_first_file_leaves_no_folder(tmp_path, monkeypatch, capsys):
    from metrosync.pantaleone import observations

    def stopped(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(observations, "pair_starts", stopped)
    out = tmp_path / "pint"
    assert main(["pantaleone", "--out", str(out)]) == 130
    assert "nothing was written" in capsys.readouterr().err
    assert not out.exists()


def test_a_range_of_equal_rounded_ends_is_one_number():
    from metrosync.pantaleone.report import _range

    assert _range(np.array([167.8, 168.3])) == "168"
    assert _range(np.array([160.2, 168.3])) == "160–168"
    assert _range(np.array([])) == "–"

"""What ``metrosync simulate`` prints about runs whose r means nothing or is missing."""

import re

import xarray as xr

from metrosync.cli import main


def test_dead_metronomes_are_counted_explained_and_not_reported_as_synchrony(capsys):
    # The reproduction, shortened: the swing (0.76 rad) never reaches 1 rad.
    assert main(["simulate", "--runs", "2", "--duration", "60",
                 "--set", "escapement_offset=1.0"]) == 0  # fmt: skip
    out, err = capsys.readouterr()
    assert "`escapement_offset` = 1 rad lies beyond the start swing (0.764 rad)" in err
    assert "runs flagged: 2 of 2 (0 overturned, 0 diverged, 2 stopped)" in out
    assert "stopped: in 2 runs some metronome's escapement gave no impulse" in out
    assert '"metronome death", Goldsztein et al., Chaos 32, 043119 (2022)' in out
    assert "final r" not in out and "not meaningful, every run is flagged" in out


def test_a_run_too_short_for_r_eq_says_why_and_what_duration_would_do(capsys):
    assert main(["simulate", "--runs", "3", "--duration", "1"]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out
    assert "equilibrium r (last 0.25 s, crossing phases): not measured." in out
    assert "two of its upward zero crossings" in out
    needed = re.search(r"Give `--duration` of at least (\d+) s", out)
    assert needed, out
    # ... and that duration does give every run an r_eq.
    assert main(["simulate", "--runs", "3", "--duration", needed[1]]) == 0
    out = capsys.readouterr().out
    assert re.search(r"crossing phases\): 0\.\d{4} \+- 0\.\d{4} \(sigma_r over runs\)", out), out


def test_dry_friction_says_how_long_the_disk_was_held(tmp_path, capsys):
    path = tmp_path / "dry.nc"
    argv = ["simulate", "--n", "3", "--runs", "2", "--duration", "20",
            "--set", "disk_dry_friction=0.03", "--out", str(path)]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out
    held = re.search(r"disk held at rest by dry friction: (\d+) % of the final 5 s", out)
    assert held, out
    with xr.open_dataset(path) as ds:
        rest = ds.disk_at_rest.values
    assert ((rest > 0) & (rest <= 1)).all()
    assert int(held[1]) == round(100 * rest.mean())
    # Without dry friction the dataset has no such variable and the summary no line.
    argv = ["simulate", "--n", "3", "--runs", "2", "--duration", "20", "--out", str(path)]
    assert main(argv) == 0
    assert "disk held" not in capsys.readouterr().out
    with xr.open_dataset(path) as ds:
        assert "disk_at_rest" not in ds

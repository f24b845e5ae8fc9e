"""`metrosync animate --phone`: a run filmed as a phone would, with its truth beside it."""

from __future__ import annotations

import json

import av
import numpy as np
import pytest

from metrosync.cli import main

SMALL = ["--n", "2", "--duration", "4", "--sigma", "0.5", "--size", "320x240"]


def test_phone_video_and_its_truth(tmp_path, capsys):
    out = tmp_path / "run.mov"
    assert main(["animate", "--phone", *SMALL, "--fps", "30", "--out", str(out)]) == 0
    truth = json.loads((tmp_path / "run.truth.json").read_text())
    assert "run.truth.json" in capsys.readouterr().out
    with av.open(str(out)) as container:
        assert container.streams.audio[0].codec_context.name == "aac"
        times = [float(f.pts * f.time_base) for f in container.decode(video=0)]
    assert np.allclose(times, truth["frame_times"], atol=1e-9)
    assert truth["n"] == 2 and truth["fps"] == 30.0
    assert len(truth["crossings"]) == 2 and len(truth["crossings"][0]) >= 4
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mov", "run.truth.json"]


def test_phone_refuses_a_negative_seed_as_it_parses(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["animate", "--phone", "--phone-seed", "-1", "--out", str(tmp_path / "a.mp4")])
    assert "argument --phone-seed: a seed is a whole number from 0 up" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--size", "321x240"], "`--size`"),
        (["--size", "big"], "`--size`"),
        (["--speedup", "2"], "`--speedup` does not apply"),
        (["--out", "{tmp}/a.gif"], "must end in .mp4, .mov, .mkv"),
        (["--n", "9"], "`--n` must be at most 8"),
        (["--fps", "0"], "`fps`"),
    ],
)
def test_phone_refuses_what_it_cannot_film(tmp_path, capsys, argv, message):
    argv = [a.format(tmp=tmp_path) for a in argv]
    if "--out" not in argv:
        argv += ["--out", str(tmp_path / "a.mp4")]
    assert main(["animate", "--phone", "--duration", "2", *argv]) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []

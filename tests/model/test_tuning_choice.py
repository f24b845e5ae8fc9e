"""The tuning is a model parameter: simulate, sweeps, presets and --set all honour it."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from metrosync import ParameterError, simulate
from metrosync.cli._options import parse_changes
from metrosync.model import TUNINGS, MetronomeDesign, get_preset
from metrosync.model.steady_swing import steady_swing_bpm_range
from metrosync.sweeps import Grid

#: Nominal BPMs across the steady-swing tunable range (81.4 to 227.9 BPM by default).
ACROSS = (85.0, 120.0, 160.0, 192.0, 225.0)


def tick_rates(ds, settle: float) -> np.ndarray:
    """Ticks per minute of each run's one pendulum after ``settle`` s: zero crossings of
    θ, located by linear interpolation between steps."""
    out = []
    keep = ds.time.values >= settle
    t = ds.time.values[keep]
    for run in ds.run.values:
        theta = ds.theta.sel(run=run).isel(metronome=0).values[keep]
        i = np.nonzero(np.sign(theta[:-1]) != np.sign(theta[1:]))[0]
        crossings = t[i] - theta[i] * (t[i + 1] - t[i]) / (theta[i + 1] - theta[i])
        out.append(60.0 * (crossings.size - 1) / (crossings[-1] - crossings[0]))
    return np.array(out)


def test_steady_swing_tuning_ticks_at_the_nominal_rate_across_the_range():
    # Pendulums on a pinned disk, one per run, through the public simulate. The step is
    # small because the paper's dt = 0.01 s itself slows the tick by ~0.13 BPM.
    design = get_preset("default").metronome
    low, high = steady_swing_bpm_range(design)
    assert low < min(ACROSS) and max(ACROSS) < high
    ds = simulate(
        None, None, frequencies_bpm=[[b] for b in ACROSS], runs=len(ACROSS), duration=40.0,
        dt=0.001, changes={"tuning": "steady-swing", "inertia": math.inf}, trajectories=True,
        record_every=1, progress=False,
    )  # fmt: skip
    assert ds.attrs["tuning"] == "steady-swing"
    np.testing.assert_allclose(tick_rates(ds, settle=15.0), ACROSS, atol=0.1)
    # the default tuning ticks slower than it is marked, by ~4 % at this swing
    small = simulate(
        None, None, frequencies_bpm=[[192.0]], duration=40.0, dt=0.001,
        changes={"inertia": math.inf}, trajectories=True, record_every=1, progress=False,
    )  # fmt: skip
    assert small.attrs["tuning"] == "small-amplitude"
    assert tick_rates(small, settle=15.0)[0] == pytest.approx(184.7, abs=0.3)


def test_an_unknown_tuning_or_one_without_a_steady_swing_is_refused_by_name():
    with pytest.raises(ParameterError, match="unknown `tuning` 'steady'"):
        MetronomeDesign(tuning="steady")
    with pytest.raises(ParameterError, match="needs both friction and drive"):
        simulate(2, 192.0, duration=1.0, changes={"tuning": "steady-swing", "drive": 0.0})
    with pytest.raises(ParameterError, match=r"outside the tunable range \[81.41, 227.85\]"):
        simulate(2, 230.0, duration=1.0, changes={"tuning": "steady-swing"})


def test_tuning_is_a_sweep_axis_and_a_set_option():
    grid = Grid(axes={"tuning": "small-amplitude,steady-swing", "bpm": [192.0]},
                fixed={"n": 2, "runs": 1, "duration": 1.0})  # fmt: skip
    points = list(grid.points())
    assert [p.kwargs["changes"] for p in points] == [
        {"tuning": "small-amplitude"},
        {"tuning": "steady-swing"},
    ]
    assert len({p.key for p in points}) == 2
    with pytest.raises(ParameterError, match="`tuning` takes one of"):
        Grid(axes={"tuning": ["steady"], "bpm": [192.0]})
    assert parse_changes(["tuning=steady-swing", "drive=1e-4"]) == {
        "tuning": "steady-swing",
        "drive": 1e-4,
    }
    with pytest.raises(ParameterError, match="`--set tuning` takes one of"):
        parse_changes(["tuning=fast"])
    assert TUNINGS == ("small-amplitude", "steady-swing")


def test_presets_show_the_tuning_and_what_192_bpm_ticks_at(capsys):
    from metrosync.cli import main

    assert main(["presets"]) == 0
    text = capsys.readouterr().out
    assert re.search(r"^    tuning +small-amplitude$", text, re.M)
    assert "184.7 BPM (small-amplitude), 192.0 BPM (steady-swing)" in text


def test_the_model_page_quotes_the_steady_swing_numbers():
    from dataclasses import replace
    from pathlib import Path

    from metrosync.model.steady_swing import steady_swing

    text = " ".join((Path(__file__).parents[2] / "docs" / "model.md").read_text().split())
    design = get_preset("default").metronome
    steady = replace(design, tuning="steady-swing")
    low, high = steady.bpm_range()
    assert f"its tunable range is {low:.1f}–{high:.1f} BPM" in text
    ticks = [steady_swing(d.with_l2(d.l2_for_bpm(192.0))).tick_bpm for d in (steady, design)]
    assert f"ticks at {ticks[0]:.1f} instead of {ticks[1]:.1f} per minute" in text
    l2 = [d.l2_for_bpm(192.0) for d in (steady, design)]
    assert f"slider sits at {l2[0]:.4f} m instead of {l2[1]:.4f} m" in text

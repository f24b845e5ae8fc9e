"""A gate near the end of the swing misses passes; one beyond it sees none. Both say so."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync import analyze, simulate
from metrosync.lightgate import LightGate, clean_channel, write_logs

from .test_cleaning import alternating, edges_for


def test_runs_of_missed_passes_are_bridged_against_the_median_period():
    up, down = alternating(60)
    # A stretch of 5 periods without any pass (the swing fell short of the gate), and
    # two single misses: the local intervals there are mostly gaps.
    gone = [*range(20, 25), 40, 47]
    passes = np.sort(np.concatenate([np.delete(up, gone), np.delete(down, range(20, 25))]))
    res = clean_channel(*edges_for(passes))
    assert res.bridged == len(gone) and res.irregular == 0
    assert res.cycles.sum() == up.size - 1
    assert "7 missed passes bridged" in res.summary()
    assert 120 * res.cycles.sum() / (res.kept[-1] - res.kept[0]) == pytest.approx(200.0)


@pytest.fixture(scope="module")
def near_the_end(tmp_path_factory):
    """One run logged by a gate well inside the swing and by one near its end."""
    ds = simulate(7, 192.0, sigma_bpm=0.75, duration=120.0, record_every=1, trajectories=True,
                  progress=False)  # fmt: skip
    inside = write_logs(ds, tmp_path_factory.mktemp("inside"), LightGate(offset=0.1))
    edge = write_logs(ds, tmp_path_factory.mktemp("edge"), LightGate(offset=0.7))
    return inside, edge


def test_analyze_warns_bridges_and_recovers_the_frequency(near_the_end):
    inside, edge = near_the_end
    truth = analyze(inside)
    assert int(truth.passes_bridged.sum()) == 0
    with pytest.warns(UserWarning, match=r"run000.log: gate \d+: \d+ missed passes bridged"):
        ds = analyze(edge)
    bridged = ds.passes_bridged.values[0]
    assert bridged.sum() > 10 and ds.passes_bridged.dims == ("log", "metronome")
    # Before bridging against the median period, such a gate read 10-25 BPM slow.
    np.testing.assert_allclose(ds.frequency_bpm, truth.frequency_bpm, atol=1.5)


def test_a_gate_beyond_the_swing_warns_when_the_logs_are_written(tmp_path):
    ds = simulate(2, 192.0, duration=10.0, record_every=1, trajectories=True)
    with pytest.warns(UserWarning, match=r"reached rarely or never in 2 of 2 metronome runs "
                      r"\(2 never\).*swinging up to 0.8\d+ rad"):  # fmt: skip
        paths = write_logs(ds, tmp_path, LightGate(offset=5.0))
    assert paths[0].read_text().count("\n") == 1  # the level line, no pass at all
    write_logs(ds, tmp_path, LightGate(offset=0.1))  # inside the swing: no warning

"""The acoustic order parameter: 1 when together, its floor when independent, clusters."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.audio.order import acoustic_order, no_common_beat, ticks_per_beat_heard
from metrosync.synthetic import clicks


def ensemble(offsets, bpms, duration=120.0, jitter=0.0, rng=None):
    trains = [clicks.metronome_train(b, duration, phase=o, jitter=jitter, rng=rng)
              for o, b in zip(offsets, bpms, strict=True)]  # fmt: skip
    return np.sort(np.concatenate(trains)), trains


def test_metronomes_ticking_together_give_one(rng):
    times, _ = ensemble([0.2] * 5, [180.0] * 5, jitter=3e-4, rng=rng)
    o = acoustic_order(times, 60 / 180, metronomes=5)
    assert np.all(o.r > 0.99)
    assert np.all(o.excess > 0.99)


def test_anti_phase_pendulums_tick_together_and_give_one():
    """θ₂ = −θ₁: both cross zero at the same instants, so the sound cannot tell."""
    t = np.arange(0.0, 60.0, 0.5) + 0.1
    times = np.sort(np.concatenate([t, t + 1e-4]))
    assert acoustic_order(times, 0.5, metronomes=2).r.min() > 0.999


@pytest.mark.parametrize("n", [2, 4, 8])
def test_floor_for_independent_metronomes_is_one_over_root_n(rng, n):
    """E[R²] = 1/N for N metronomes at random phases and slightly different tempi."""
    r2 = []
    for _ in range(150):
        bpms = 180 * (1 + rng.uniform(-0.004, 0.004, n))
        times, _ = ensemble(rng.uniform(0, 1, n), bpms, duration=60.0)
        o = acoustic_order(times, 60 / 180, metronomes=n, centres=np.array([30.0]))
        r2.append(o.r[0] ** 2)  # one window per realisation: independent draws
    assert o.floor[0] == pytest.approx(1 / np.sqrt(n))
    # mean of 150 exponential-like draws: relative standard error about 8 %
    assert np.mean(r2) * n == pytest.approx(1.0, abs=0.25)


def test_ticks_independent_from_one_to_the_next_give_one_over_root_m(rng):
    """The other extreme, ticks at random times: E[R²] = 1/M, M ticks in the window."""
    values = []
    for _ in range(300):
        times = np.sort(rng.uniform(0, 20, 60))
        o = acoustic_order(times, 0.33, window=20.0, centres=np.array([10.0]))
        m = np.sum(np.abs(times - 10) < 10)
        values.append(o.r[0] ** 2 * m)
    assert np.mean(values) == pytest.approx(1.0, abs=0.15)


def test_excess_is_zero_on_average_for_independent_and_one_for_synchronized(rng):
    excess = []
    for _ in range(60):
        times, _ = ensemble(rng.uniform(0, 1, 4), 180 * (1 + rng.uniform(-3e-3, 3e-3, 4)))
        excess.append(acoustic_order(times, 1 / 3, metronomes=4).excess.mean())
    assert np.mean(excess) < 0.35  # the excess is clipped at 0, so its mean is above 0


@pytest.mark.parametrize(
    ("offsets", "clusters"),
    [([0.1, 0.1, 0.1], 1), ([0.1, 0.1, 0.6], 2), ([0.1, 0.43, 0.76], 3), ([0.1, 0.115], 1)],
)
def test_clusters_count_the_distinct_ticks_per_beat(offsets, clusters):
    times, _ = ensemble(offsets, [150.0] * len(offsets), duration=30)
    _, counts = ticks_per_beat_heard(times, 0.4, 1 / 16)
    assert np.median(counts) == clusters
    o = acoustic_order(times, 0.4)
    assert np.all(o.clusters == clusters)


def test_a_common_beat_needs_tempi_closer_than_a_beat_per_window():
    # 16 beats a window: 6.25 % apart gains one beat in each.
    assert no_common_beat([184.0], 16) == ""
    assert no_common_beat([184.0, 190.0, 186.0], 16) == ""  # 3.2 %: half a beat
    apart = no_common_beat([183.99, 207.92], 16)
    assert "12 % apart" in apart and "gains 2.0 beats" in apart
    assert no_common_beat([183.99, 207.92], 8) == ""  # a window of 8 beats: 0.98 of a beat
    assert no_common_beat([100.0, 104.0], 16) == ""


def test_metronomes_at_distant_tempi_get_no_common_beat_and_no_r(tmp_path):
    """Two metronomes at 184 and 208 BPM: R and the ticks per beat are not invented."""
    from test_audio_analysis import _analysed, _trains

    from metrosync.audio.summary import summary_text
    from metrosync.synthetic import Impairments

    def recording(seed, bpms):
        return _analysed(tmp_path, _trains(2, seed, bpms=bpms), seed, Impairments())

    ds, _ = recording(3, [184.0, 208.0])
    assert sorted(np.round(ds.bpm.values)) == [184, 208]
    assert "12 % apart" in ds.attrs["no_common_beat"]
    assert np.isnan(ds.r_acoustic.values).all() and np.isnan(ds.clusters.values).all()
    text = summary_text(ds)
    assert "no common beat" in text.splitlines()[1] and "BPM" not in text.splitlines()[1]
    assert "R and distinct ticks per beat: not computed: the metronomes keep tempi" in text
    assert "sound alike and keep the same tempo" not in text
    near, _ = recording(4, [184.0, 186.0])
    assert near.attrs["no_common_beat"] == ""
    assert np.isfinite(near.r_acoustic.values).any()
    assert "beat " in summary_text(near).splitlines()[1]

"""Size before work: requests too big for memory are refused at once, without
allocating; long ones warn before they start; r(t) stays bounded at any duration."""

from __future__ import annotations

import importlib
import time
import tracemalloc
import warnings

import numpy as np
import pytest
import xarray as xr

from metrosync import budget, simulate
from metrosync.budget import Budget, LongRunWarning, ResourceError, simulation_budget
from metrosync.pacing import Pacer

REQUEST = importlib.import_module("metrosync.simulation.request")
GiB = 1024.0**3


@pytest.fixture
def sixteen_gib(monkeypatch):
    """A machine with 16 GiB available, wherever the tests run."""
    monkeypatch.setattr(budget, "available_memory", lambda: 16 * GiB)


def refused_quickly(call, match):
    """Run ``call``; assert it raises `ResourceError` matching ``match`` in < 1 s and
    allocates next to nothing meanwhile."""
    tracemalloc.start()
    started = time.perf_counter()
    try:
        with pytest.raises(ResourceError, match=match) as refusal:
            call()
        elapsed = time.perf_counter() - started
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2e6, f"allocated {peak / 1e6:.1f} MB before refusing"
    assert elapsed < 1.0
    return str(refusal.value)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        # simulate --n 100000 --runs 1000 --save-every 1: trajectories of 131 TiB
        ({"n": 100_000, "runs": 1000, "record_every": 1, "trajectories": True},
         r"about 131 TiB .*trajectories 131 TiB.*`record_every`"),
        # the same without trajectories: the ensemble alone needs 30 GiB
        ({"n": 100_000, "runs": 1000}, r"ensemble and state 29.8 GiB.*fewer `runs`"),
        ({"n": 7, "runs": 20, "duration": 600, "record_every": 1, "trajectories": True,
          "frequencies_bpm": None, "dt": 1e-5}, r"trajectories .*GiB"),
    ],
)  # fmt: skip
def test_too_big_is_refused_at_once_without_allocating(sixteen_gib, kwargs, match):
    message = refused_quickly(lambda: simulate(**kwargs), match)
    assert "more than the 12.8 GiB it may use (80% of the 16 GiB available)" in message


def test_explicit_frequencies_and_metronome_count_are_sized_too(sixteen_gib):
    refused_quickly(
        lambda: simulate(None, None, frequencies_bpm=np.full(20_000, 192.0), runs=100_000),
        r"ensemble and state",
    )


def test_long_work_warns_before_it_starts():
    # --dt 1e-9: 6e11 steps of one run; the warning comes before anything is allocated.
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        with pytest.raises(LongRunWarning, match=r"about 42.5 h \(4.2e\+12 oscillator-steps\)"):
            simulate(7, 192.0, dt=1e-9, duration=600)


def test_astronomical_step_counts_are_refused():
    with pytest.raises(Exception, match=r"`duration` / `dt` = .* more than"):
        simulate(7, 192.0, dt=1e-300, duration=1e9)


def test_budget_refuses_with_the_numbers_and_the_fix():
    request = Budget("the thing", {"big": 10 * GiB, "small": 1e3}, fixes="lower `runs`")
    with pytest.raises(ResourceError) as refusal:
        request.check(available=4 * GiB)
    assert str(refusal.value) == (
        "the thing would need about 10 GiB of memory (big 10 GiB, small 1000 B), more than "
        "the 3.2 GiB it may use (80% of the 4 GiB available); lower `runs`."
    )
    assert request.check(available=20 * GiB) is request


def test_estimate_covers_what_a_run_allocates_and_not_far_more():
    kwargs = dict(runs=30, duration=20.0, record_every=1, trajectories=True, seed=1)
    simulate(40, 192.0, **{**kwargs, "duration": 0.1})  # kernels loaded outside the count
    tracemalloc.start()
    try:
        simulate(40, 192.0, **kwargs)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    estimate = simulation_budget(n=40, runs=30, steps=2000, records=2001, trajectories=True)
    assert peak <= estimate.nbytes <= 3 * peak


# -- item 3: r(t) at a stride, bounded at any duration --------------------------------


def test_a_long_run_records_at_a_stride_that_caps_the_records(monkeypatch):
    monkeypatch.setattr(REQUEST, "MAX_RECORDS", 100)
    ds = simulate(3, 192.0, duration=60.0)  # 6000 steps: 601 records at 0.1 s
    assert ds.sizes["time"] <= 100
    assert ds.attrs["record_every"] == 61 and ds.attrs["record_interval"] == pytest.approx(0.61)
    reason = "raised from 0.1 s to keep at most 100 records per run"
    assert ds.attrs["record_every_reason"] == reason
    np.testing.assert_allclose(np.diff(ds.time), 0.61)
    assert np.isfinite(ds.r_eq).all()
    short = simulate(3, 192.0, duration=5.0)
    assert short.attrs["record_every_reason"] == "default 0.1 s" and short.sizes["time"] == 51


def test_memory_of_r_does_not_grow_with_the_duration(monkeypatch):
    seen = []

    def capture(self, **_):
        seen.append(self)
        raise KeyboardInterrupt  # stop before any work

    monkeypatch.setattr(Budget, "check", capture)
    for duration in (1e3, 1e6, 1e9):
        with pytest.raises(KeyboardInterrupt):
            simulate(7, 192.0, runs=20, duration=duration)
    sizes = [b.arrays["r(t) records"] for b in seen]
    cap = 20 * budget.RECORD_BYTES * REQUEST.MAX_RECORDS
    assert sizes[0] < 0.2 * cap and 0.99 * cap <= sizes[1] <= cap and 0.99 * cap <= sizes[2] <= cap


# -- pacing: compiled chunks of bounded wall time, results independent of them -------


def test_chunks_grow_at_most_fourfold():
    now = [0.0]
    pacer = Pacer(10**9, 1.0, target=0.25, clock=lambda: now[0])
    sizes = []
    for _, count in pacer:
        sizes.append(count)
        now[0] += count * 1e-9
        if len(sizes) == 10:
            break
    assert sizes == [4**k for k in range(10)]


def test_chunks_grow_to_the_target_time_and_shrink_when_slow():
    now = [0.0]
    cost = [1e-3]  # seconds per step
    pacer = Pacer(100_000, 1e-4, target=0.25, clock=lambda: now[0])
    sizes = []
    for _, count in pacer:
        sizes.append(count)
        now[0] += count * cost[0]
        if len(sizes) == 12:
            cost[0] = 1e-2  # the machine gets 10 x slower
    assert sizes[0] == 200  # FIRST_SECONDS at the pessimistic guess
    assert sizes[1:13] == [250] * 12  # 0.25 s at 1 ms a step
    assert sizes[13] == 25 and sum(sizes) == 100_000  # right after a chunk that took 2.5 s


def test_results_do_not_depend_on_the_chunking(monkeypatch):
    kwargs = dict(sigma_bpm=1.0, runs=20, duration=30, seed=4, record_every=7, trajectories=True)
    import metrosync.pacing as pacing

    monkeypatch.setattr(pacing, "TARGET_SECONDS", 1e-6)  # a chunk of one step
    monkeypatch.setattr(pacing, "FIRST_SECONDS", 1e-9)
    tiny = simulate(7, 192.0, **kwargs)
    monkeypatch.setattr(pacing, "TARGET_SECONDS", 1e3)  # one or two chunks
    monkeypatch.setattr(pacing, "FIRST_SECONDS", 1e3)
    whole = simulate(7, 192.0, **kwargs)
    xr.testing.assert_identical(tiny, whole)


# -- the other entry points -----------------------------------------------------------


def test_sweep_refuses_before_computing_any_point(sixteen_gib, tmp_path):
    from metrosync.sweeps import sweep

    grid = {"bpm": "150:199:0.5"}  # 99 points x 1000 runs of r(t) over 1e6 s
    fixed = {"runs": 1000, "duration": 1e6}
    message = refused_quickly(
        lambda: sweep(grid, tmp_path / "store", fixed=fixed, keep_r=True), r"merged result"
    )
    assert "drop `keep_r` (--keep-r)" in message
    assert not (tmp_path / "store").exists()


def test_a_long_sweep_warns_with_its_estimate(tmp_path):
    from metrosync.sweeps import sweep

    fixed = {"runs": 100, "duration": 3000}
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        estimate = r"the sweep is estimated to take about .* \(58 points, 6.2e\+10 oscillator-steps"
        with pytest.raises(LongRunWarning, match=estimate):
            sweep({"bpm": "150:220:2.5", "n": [7, 64]}, tmp_path, fixed=fixed)
    assert not (tmp_path / "points").exists()


def test_bootstrap_of_critical_is_sized_before_it_runs(sixteen_gib):
    from metrosync.sweeps.critical import critical_frequency

    bpm = np.arange(150.0, 221.0, 2.5)
    sweep = xr.Dataset(
        {"r_eq": (("n", "bpm", "run"), np.random.default_rng(0).random((2, bpm.size, 100)))},
        coords={"n": [7, 16], "bpm": bpm},
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        with pytest.raises(LongRunWarning, match=r"about 58 min \(10000000 replicas x 2 sizes"):
            critical_frequency(sweep, n_boot=10_000_000)
    refused_quickly(
        lambda: critical_frequency(sweep, n_boot=1_000_000_000), r"replicas 29.8 GiB.*`n_boot`"
    )


def test_page_is_sized_before_it_is_built(monkeypatch):
    from metrosync.show.page import page_data
    from metrosync.show.recording import RecordedRun

    ds = simulate(3, 192.0, duration=5.0, record_every=1, trajectories=True)
    monkeypatch.setattr(budget, "available_memory", lambda: 1e5)
    with pytest.raises(ResourceError, match=r"the page would need .*lower `max_rate`"):
        page_data(RecordedRun.from_dataset(ds))

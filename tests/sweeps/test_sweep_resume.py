"""Resuming: a sweep killed with SIGKILL and started again loses and repeats nothing,
and a changed fixed parameter never reuses stale points."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import xarray as xr

from metrosync import sweep
from metrosync.sweeps import Grid, PointStore

GRID = {"axes": {"bpm": "184:194:2", "n": [2, 3]}, "fixed": {"runs": 3, "duration": 5.0}}

#: Points the child stores before it is killed.
KEPT = 3

# After its KEPT-th stored point the child stops in place (only the child; the results
# are untouched), so the kill lands with exactly KEPT points done, however fast or
# slow the machine: the test waits for the store, never for the clock.
CHILD = textwrap.dedent(
    """
    import sys, threading
    from metrosync.sweeps import Grid, sweep
    from metrosync.sweeps.store import PointStore

    write = PointStore.write
    def write_then_stop(self, ds, **kw):
        path = write(self, ds, **kw)
        if len(list(self.points.glob("*.nc"))) == {kept}:
            threading.Event().wait()  # until killed
        return path
    PointStore.write = write_then_stop
    sweep(Grid(**{grid!r}), sys.argv[1], progress=False)
    """
)


def snapshot(store: PointStore) -> dict[str, tuple[int, int]]:
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in store.points.glob("*.nc")}


def test_sigkill_then_restart_equals_an_uninterrupted_sweep(tmp_path):
    grid = Grid(**GRID)
    store = PointStore(tmp_path / "killed")
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    log = tmp_path / "child.log"
    with open(log, "wb") as sink:
        child = subprocess.Popen(
            [sys.executable, "-c", CHILD.format(grid=GRID, kept=KEPT), str(store.root)],
            env=env, stdout=sink, stderr=subprocess.STDOUT,
        )  # fmt: skip
    deadline = time.monotonic() + 120
    while (len(snapshot(store)) if store.points.exists() else 0) < KEPT:
        assert child.poll() is None, log.read_text()
        assert time.monotonic() < deadline, f"the child stored fewer than {KEPT} points in 120 s"
        time.sleep(0.05)  # polling the store; the child waits for the kill
    child.send_signal(signal.SIGKILL)
    child.wait()
    assert child.returncode == -signal.SIGKILL
    before = snapshot(store)
    assert len(before) == KEPT < grid.size
    logged_before = len(store.logged_keys())

    resumed = sweep(grid, store.root, progress=False)

    after = snapshot(store)
    assert {k: after[k] for k in before} == before  # finished points were not rewritten
    missing = {p.key for p in grid.points()} - {name[:-3] for name in before}
    new_log = store.logged_keys()[logged_before:]
    assert sorted(new_log) == sorted(missing)  # each missing point computed exactly once
    assert sorted(resumed.execution.computed) == sorted(missing)
    assert resumed.reused == len(before) and resumed.complete
    assert not list(store.points.glob(".*partial"))

    uninterrupted = sweep(grid, tmp_path / "clean", progress=False)
    xr.testing.assert_identical(resumed.dataset, uninterrupted.dataset)


def test_changing_a_fixed_parameter_invalidates_the_cache(tmp_path):
    first = sweep(Grid(**GRID), tmp_path)
    changed = Grid(axes=GRID["axes"], fixed={**GRID["fixed"], "c_phi": 5e-5})
    second = sweep(changed, tmp_path)
    assert second.reused == 0 and len(second.execution.computed) == changed.size
    assert second.dataset.attrs["fixed_c_phi"] == 5e-5
    assert not np.array_equal(first.dataset.r_eq.values, second.dataset.r_eq.values)
    back = sweep(Grid(**GRID), tmp_path)  # the original points are still there, and valid
    assert back.reused == first.grid.size and back.execution.computed == []
    xr.testing.assert_identical(back.dataset, first.dataset)

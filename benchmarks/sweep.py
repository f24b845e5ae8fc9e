"""Throughput of a Fig. 10-sized sweep, in process and on a 2-worker Dask LocalCluster.

Fig. 10 of the paper: r(ω₀) and σ_r(ω₀) for several N, 100 runs per point. Here:
N = 7, 16, 32, 64 and ω₀ = 150:220:2.5 BPM (29 values), σ = 0.75 BPM. The full size is
100 runs × 600 s per point; by default runs and duration are cut (to 10 runs × 60 s,
a factor 100 less work) so that both executors finish in a couple of minutes. The
throughput (oscillator-steps per second of wall time) does not depend on the cut.

    python benchmarks/sweep.py [--runs 10] [--duration 60] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from metrosync.sweeps import Grid, sweep

FULL_RUNS, FULL_DURATION = 100, 600.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    grid = Grid(
        axes={"n": [7, 16, 32, 64], "bpm": "150:220:2.5"},
        fixed={"runs": args.runs, "duration": args.duration, "sigma": 0.75},
    )
    factor = FULL_RUNS * FULL_DURATION / (args.runs * args.duration)
    work = sum(p.work for p in grid.points())
    print(
        f"grid {dict(zip(grid.axes, grid.shape, strict=True))} = {grid.size} points, "
        f"{args.runs} runs x {args.duration:g} s each (Fig. 10 size / {factor:g}), "
        f"{work:.3g} oscillator-steps; {os.cpu_count()} cores, "
        f"NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS', 'all')}"
    )
    # Compile (or load) the kernel once so neither timing includes it.
    sweep({"bpm": [190]}, tempfile.mkdtemp(), fixed={"runs": 2, "duration": 1.0}, progress=False)
    for label, options in (
        ("in process", {}),
        (
            f"Dask LocalCluster, {args.workers} workers",
            {"scheduler": "local", "n_workers": args.workers},
        ),
    ):
        with tempfile.TemporaryDirectory() as store:
            started = time.perf_counter()
            result = sweep(grid, store, progress=False, **options)
            wall = time.perf_counter() - started
        ex = result.execution
        print(
            f"{label:>32}: {wall:7.1f} s wall (incl. start-up and merge), "
            f"{ex.throughput:.3g} oscillator-steps/s over the points, "
            f"so the full-size sweep would take ~{work * factor / ex.throughput / 60:.0f} min"
        )


if __name__ == "__main__":
    main()

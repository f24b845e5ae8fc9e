"""Before/after throughput of the fixed-step kernel: two source trees, interleaved.

Each round times the kernel `simulate` would choose, at each (B runs, N metronomes),
once from each tree, in a fresh process (``PYTHONPATH=<tree>/src``), single-threaded,
and in *CPU time* of the process: on a shared, loaded machine wall-clock rates swing by
±30 % from one run to the next, CPU time by about ±2 %. Each figure is the best of
``--repeats`` timings; the summary is the mean over rounds of those, and the ratio.

    git worktree add /tmp/before <commit>        # or: git archive <commit> | tar -x -C DIR
    python benchmarks/kernel_ab.py --before /tmp/before --after .
    python benchmarks/kernel_ab.py --before /tmp/before --after . --sizes 100x7 --rounds 8
    python benchmarks/kernel_ab.py --before /tmp/before --after . --scheme located
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

#: Run in the child process: prints the best and the median rate, oscillator-steps/s.
CHILD = """
import math, sys, time
import numpy as np
from metrosync import build_ensemble, get_preset
import importlib
from metrosync.integrators._state import StepState

b, n, steps, repeats = (int(x) for x in sys.argv[1:5])
scheme = importlib.import_module("metrosync.integrators." + sys.argv[5])
ens = build_ensemble(n, 192.0, params=get_preset("default"), sigma_bpm=0.75, runs=b, seed=1)

def once(k):
    st = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                         n_records=k // 10 + 1, trajectories=False)
    start = time.process_time()
    scheme.advance_state(st, ens.system, dt=0.01, step0=0, n_steps=k, record_every=10,
                         overturn_angle=math.pi / 2)
    return b * n * k / (time.process_time() - start)

once(20)  # compile or load the cache
rates = [once(steps) for _ in range(repeats)]
print(max(rates), float(np.median(rates)))
"""


def rate(tree: Path, b: int, n: int, work: float, repeats: int, scheme: str) -> tuple[float, float]:
    env = {**os.environ, "PYTHONPATH": str(tree / "src"), "NUMBA_NUM_THREADS": "1"}
    steps = max(10, int(work / (b * n)))
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(b), str(n), str(steps), str(repeats), scheme],
        env=env, capture_output=True, text=True, check=False,
    )  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"{tree}: the timing failed:\n{done.stderr[-2000:]}")
    best, median = (float(x) for x in done.stdout.split())
    return best, median


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--before", type=Path, required=True, help="source tree before")
    parser.add_argument("--after", type=Path, required=True, help="source tree after")
    parser.add_argument("--sizes", nargs="+", default=["100x7", "100x64"], help="BxN pairs")
    parser.add_argument("--rounds", type=int, default=6, help="interleaved rounds")
    parser.add_argument("--repeats", type=int, default=12, help="timings per figure")
    parser.add_argument("--work", type=float, default=2e6, help="oscillator-steps per timing")
    parser.add_argument(
        "--scheme", default="verlet", choices=["verlet", "located"], help="fixed-step scheme"
    )
    args = parser.parse_args()
    for tree in (args.before, args.after):
        if not (tree / "src" / "metrosync").is_dir():
            parser.error(f"{tree} has no src/metrosync: give the root of a metrosync tree")
    sizes = [tuple(int(x) for x in size.lower().split("x")) for size in args.sizes]
    for b, n in sizes:  # compile both once, outside the rounds
        for tree in (args.before, args.after):
            rate(tree, b, n, 1e4, 1, args.scheme)
    best = {(tree, size): [] for tree in ("before", "after") for size in sizes}
    for k in range(args.rounds):
        for b, n in sizes:
            for name, tree in (("before", args.before), ("after", args.after)):
                top, median = rate(tree, b, n, args.work, args.repeats, args.scheme)
                best[name, (b, n)].append(top)
                print(f"round {k + 1}  {b:>5}x{n:<5} {name:>6}: best {top:.3e}  "
                      f"median {median:.3e} osc-steps/CPU-s", flush=True)  # fmt: skip
    print("\nmean over rounds of the best timing (oscillator-steps per CPU second)")
    for b, n in sizes:
        before = sum(best["before", (b, n)]) / args.rounds
        after = sum(best["after", (b, n)]) / args.rounds
        print(f"  B={b:>5} N={n:<5} before {before:.3e}  after {after:.3e}  "
              f"after/before {after / before:.3f}")  # fmt: skip


if __name__ == "__main__":
    main()

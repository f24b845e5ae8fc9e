"""Time from a fresh interpreter to the first simulated step, with a warm compile cache.

Runs `metrosync simulate` once to fill the cache, then measures, over several fresh
processes, the wall time of `import metrosync` plus a first tiny simulation (which
loads the cached kernel). That is how long a second `metrosync simulate` takes to
start computing.

    python benchmarks/startup.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys

PROBE = (
    "import time; t0 = time.perf_counter(); import metrosync; t1 = time.perf_counter(); "
    "metrosync.simulate(7, 192, runs=2, duration=0.1); t2 = time.perf_counter(); "
    "print(t1 - t0, t2 - t1)"
)


def main(repeats: int = 5) -> None:
    subprocess.run([sys.executable, "-c", PROBE], check=True, capture_output=True)  # warm cache
    imports, first_runs = [], []
    for _ in range(repeats):
        out = subprocess.run(
            [sys.executable, "-c", PROBE], check=True, capture_output=True, text=True
        )
        a, b = (float(x) for x in out.stdout.split())
        imports.append(a)
        first_runs.append(b)
    imp, run = statistics.median(imports), statistics.median(first_runs)
    print(
        f"import metrosync: {imp:.3f} s, first simulate (cached kernel): {run:.3f} s, "
        f"start of computing after {imp + run:.3f} s (median of {repeats} fresh processes)"
    )


if __name__ == "__main__":
    main()

"""Throughput of the fixed-step kernel, in oscillator-steps per second.

For each (B runs, N metronomes) it times the compiled kernel over the full duration
(default 1000 s at dt = 0.01, i.e. 10⁵ steps) and the plain NumPy implementation of
the same scheme over fewer steps (its rate does not depend on the step count), and
prints both with their ratio. Compilation is excluded (a warm-up call runs first).

    python benchmarks/kernel.py                      # the issue's (100, 7) and (100, 64)
    python benchmarks/kernel.py --sizes 100x7 1000x64 --duration 200
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numba

from metrosync import build_ensemble, get_preset
from metrosync.integrators import reference, verlet
from metrosync.integrators._state import StepState


def throughput(backend, ensemble, steps: int, dt: float, record_every: int = 10) -> float:
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=steps // record_every + 1, trajectories=False,
    )  # fmt: skip
    start = time.perf_counter()
    backend.advance_state(
        state, ensemble.system, dt=dt, step0=0, n_steps=steps, record_every=record_every,
        overturn_angle=math.pi / 2,
    )  # fmt: skip
    elapsed = time.perf_counter() - start
    return ensemble.runs * ensemble.n * steps / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", nargs="+", default=["100x7", "100x64"], help="BxN pairs")
    parser.add_argument("--duration", type=float, default=1000.0, help="simulated seconds (kernel)")
    parser.add_argument("--dt", type=float, default=0.01)
    parser.add_argument(
        "--baseline-steps", type=int, default=300, help="steps for the NumPy baseline"
    )
    parser.add_argument(
        "--repeats", type=int, default=3, help="kernel timings per size (best kept)"
    )
    args = parser.parse_args()

    params = get_preset("default")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"numba {numba.__version__} with {numba.get_num_threads()} threads")  # fmt: skip
    print(f"dt = {args.dt} s, kernel over {args.duration:g} s, "
          f"baseline over {args.baseline_steps} steps")  # fmt: skip
    print(
        f"{'B':>6} {'N':>6} {'kernel (osc-steps/s)':>22} {'numpy (osc-steps/s)':>22} {'ratio':>8}"
    )
    for size in args.sizes:
        b, n = (int(x) for x in size.lower().split("x"))
        ens = build_ensemble(n, 192.0, params=params, sigma_bpm=0.75, runs=b, seed=1)
        throughput(verlet, ens, 20, args.dt)  # compile / load the cache
        steps = int(round(args.duration / args.dt))
        fast = max(throughput(verlet, ens, steps, args.dt) for _ in range(args.repeats))
        slow = throughput(reference, ens, args.baseline_steps, args.dt)
        print(f"{b:>6} {n:>6} {fast:>22.3e} {slow:>22.3e} {fast / slow:>8.1f}")


if __name__ == "__main__":
    main()

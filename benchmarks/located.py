"""Throughput of the ``located`` kernels against ``verlet``'s, in oscillator-steps per second.

For each (B runs, N metronomes) it times both schemes' compiled kernels in the layout
`simulate` picks (or ``--layout``), alternating them ``--repeats`` times so that a
busy machine slows both alike, and prints the best rate of each and their ratio. Rates
are per CPU second of the process (``--clock cpu``, the default: on a shared machine
wall-clock rates swing by tens of per cent) or per wall second (``--clock wall``).
Compilation is excluded (a warm-up call first). The ensembles are the paper's
(192 BPM, σ = 0.75 BPM, default preset), so the escapements fire at the usual rate:
about 2N/0.625 impulses per run and second.

    python benchmarks/located.py                           # (100, 7) and (100, 64)
    python benchmarks/located.py --sizes 1000x7 --layout metronomes --repeats 7
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numba

from metrosync import build_ensemble, get_preset
from metrosync.integrators import layouts, located, verlet
from metrosync.integrators._state import StepState

SCHEMES = {"verlet": verlet, "located": located}
CLOCKS = {"cpu": time.process_time, "wall": time.perf_counter}


def rate(scheme, ensemble, steps: int, dt: float, layout: str, clock=time.process_time) -> float:
    """Oscillator-steps per second of one timed call of ``scheme``'s kernel."""
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=steps // 10 + 1, trajectories=False,
    )  # fmt: skip
    options = dict(dt=dt, step0=0, n_steps=steps, record_every=10, overturn_angle=math.pi / 2)
    start = clock()
    SCHEMES[scheme].advance_state(state, ensemble.system, layout=layout, **options)
    return ensemble.runs * ensemble.n * steps / (clock() - start)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", nargs="+", default=["100x7", "100x64"], help="BxN pairs")
    parser.add_argument("--duration", type=float, default=300.0, help="simulated s per timing")
    parser.add_argument("--dt", type=float, default=0.01)
    parser.add_argument("--repeats", type=int, default=5, help="timings per scheme (best kept)")
    parser.add_argument("--layout", choices=sorted(layouts.ARRANGE), help="default: simulate's")
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="cpu", help="what a rate is per")
    args = parser.parse_args()
    clock = CLOCKS[args.clock]

    print(f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} CPUs, "
          f"numba {numba.__version__}, {numba.get_num_threads()} threads")  # fmt: skip
    print(f"dt = {args.dt} s, {args.duration:g} s simulated per timing, best of "
          f"{args.repeats} alternated timings; rates in oscillator-steps per "
          f"{args.clock} s")  # fmt: skip
    print(f"{'B':>6} {'N':>6} {'layout':>12} {'verlet':>10} {'located':>10} {'located/verlet':>15}")
    steps = int(round(args.duration / args.dt))
    for size in args.sizes:
        b, n = (int(x) for x in size.lower().split("x"))
        ens = build_ensemble(n, 192.0, params=get_preset("default"), sigma_bpm=0.75, runs=b, seed=1)
        layout = args.layout or layouts.choose_layout(n, b)
        best = dict.fromkeys(SCHEMES, 0.0)
        for scheme in SCHEMES:
            rate(scheme, ens, 20, args.dt, layout, clock)  # compile or load the cache
        for _ in range(args.repeats):
            for scheme in SCHEMES:
                best[scheme] = max(best[scheme], rate(scheme, ens, steps, args.dt, layout, clock))
        ratio = best["located"] / best["verlet"]
        print(f"{b:>6} {n:>6} {layout:>12} {best['verlet']:>10.3e} {best['located']:>10.3e} "
              f"{ratio:>15.3f}")  # fmt: skip


if __name__ == "__main__":
    main()

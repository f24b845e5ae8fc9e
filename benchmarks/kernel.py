"""Throughput of the fixed-step kernels, in oscillator-steps per second.

For each (B runs, N metronomes) it times, in one process:
  * the kernel `simulate` uses (layout chosen from N), over the full duration;
  * the previous kernel (scalar loop, libm trig; `kernel_scalar.py` beside this
    script), over the same duration;
  * the plain NumPy implementation of the same scheme, over fewer steps (its rate does
    not depend on the step count);
and prints the rates with the ratios. Compilation is excluded (a warm-up call first);
each compiled figure is the best of ``--repeats`` timings. ``--scaling`` adds the cost
per oscillator-step as N and as B grow at fixed work, which should stay flat.

    python benchmarks/kernel.py                       # the (100, 7) and (100, 64) grid
    python benchmarks/kernel.py --scaling             # plus the N and B scaling curves
    python benchmarks/kernel.py --sizes 100x7 1000x64 --duration 200
    NUMBA_NUM_THREADS=1 python benchmarks/kernel.py --cpu-time   # steadier on a busy machine

``--cpu-time`` times the process's CPU time instead of the wall clock: on a machine
shared with other jobs, time spent waiting for a core then does not count, so two
versions can be compared to about 1 % (with one thread, CPU time is that thread's).
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numba
from kernel_scalar import advance_state as previous_kernel

from metrosync import build_ensemble, get_preset
from metrosync.integrators import layouts, twin, verlet
from metrosync.integrators._state import StepState

#: The clock the rates are timed with (`main` switches it for ``--cpu-time``).
clock = time.perf_counter


def rate(ensemble, steps: int, dt: float, layout: str | None) -> float:
    """Oscillator-steps per second of one timed call (``layout``: a layout of the
    package's kernel, ``"previous"`` for the scalar baseline, or None for NumPy)."""
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=steps // 10 + 1, trajectories=False,
    )  # fmt: skip
    options = dict(dt=dt, step0=0, n_steps=steps, record_every=10, overturn_angle=math.pi / 2)
    start = clock()
    if layout is None:
        twin.VERLET.advance_state(state, ensemble.system, **options)
    elif layout == "previous":
        previous_kernel(state, ensemble.system, **options)
    else:
        verlet.advance_state(state, ensemble.system, layout=layout, **options)
    return ensemble.runs * ensemble.n * steps / (clock() - start)


def best(ensemble, steps, dt, layout, repeats):
    rate(ensemble, 20, dt, layout)  # compile or load the cache
    return max(rate(ensemble, steps, dt, layout) for _ in range(repeats))


def ensemble_of(b: int, n: int):
    return build_ensemble(n, 192.0, params=get_preset("default"), sigma_bpm=0.75, runs=b, seed=1)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", nargs="+", default=["100x7", "100x64"], help="BxN pairs")
    parser.add_argument("--duration", type=float, default=1000.0, help="simulated s (kernels)")
    parser.add_argument("--dt", type=float, default=0.01)
    parser.add_argument("--baseline-steps", type=int, default=300, help="steps for NumPy")
    parser.add_argument("--repeats", type=int, default=3, help="timings per figure (best kept)")
    parser.add_argument("--scaling", action="store_true", help="also the N and B scaling curves")
    parser.add_argument("--cpu-time", action="store_true",
                        help="time CPU time, not wall time (see above)")  # fmt: skip
    args = parser.parse_args()
    if args.cpu_time:
        global clock
        clock = time.process_time

    print(f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} CPUs, "
          f"numba {numba.__version__}, {numba.get_num_threads()} threads")  # fmt: skip
    print(f"rates from {'CPU time' if args.cpu_time else 'wall time'}; "
          f"dt = {args.dt} s; kernels over {args.duration:g} s; NumPy over "
          f"{args.baseline_steps} steps; rates in oscillator-steps/s")  # fmt: skip
    header = f"{'B':>6} {'N':>6} {'layout':>12} {'kernel':>10} {'previous':>10} {'numpy':>10}"
    print(header + f" {'x previous':>11} {'x numpy':>9}")
    steps = int(round(args.duration / args.dt))
    for size in args.sizes:
        b, n = (int(x) for x in size.lower().split("x"))
        ens = ensemble_of(b, n)
        layout = layouts.choose_layout(n, b)
        fast = best(ens, steps, args.dt, layout, args.repeats)
        previous = best(ens, steps, args.dt, "previous", args.repeats)
        slow = rate(ens, args.baseline_steps, args.dt, None)
        print(f"{b:>6} {n:>6} {layout:>12} {fast:>10.3e} {previous:>10.3e} {slow:>10.3e} "
              f"{fast / previous:>11.1f} {fast / slow:>9.0f}")  # fmt: skip

    if args.scaling:
        work = 2e8  # oscillator-steps per timing
        print("\ncost per oscillator-step at fixed work (ns), chosen layout")
        for label, sizes in (
            ("N grows, B = 100", [(100, n) for n in (2, 7, 16, 64, 256, 1024, 4096, 10000)]),
            ("B grows, N = 7", [(b, 7) for b in (10, 100, 1000, 10000)]),
            ("B grows, N = 64", [(b, 64) for b in (10, 100, 1000, 10000)]),
        ):
            print(f"  {label}:")
            for b, n in sizes:
                ens = ensemble_of(b, n)
                count = max(10, int(work / (b * n)))
                r = best(ens, count, args.dt, layouts.choose_layout(n, b), args.repeats)
                print(f"    B = {b:>6}  N = {n:>6}  {1e9 / r:7.2f} ns  ({r:.3e} osc-steps/s)")


if __name__ == "__main__":
    main()

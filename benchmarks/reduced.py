"""Speed of the reduced phase model (`metrosync.theory.simulate_reduced`).

Times one run of N Kuramoto–Sakaguchi oscillators (σ = 0.04 rad/s, K = 0.1 rad/s,
α = −0.45 rad, as near the default preset's onset) for 500 s at dt = 0.25 s (2000
steps), after a warm-up call that compiles the kernels, for N = 10⁴ … 10⁶, on one
thread and split over numba's threads. Prints seconds and ns per oscillator-step.

    python benchmarks/reduced.py
"""

from __future__ import annotations

import time

from metrosync.theory import simulate_reduced

ARGS = dict(k=0.1, alpha=-0.45, sigma=0.04, duration=500.0, dt=0.25)


def main() -> None:
    for threads in (False, True):
        simulate_reduced(10_000, threads=threads, **{**ARGS, "duration": 1.0})  # compile
    print(f"{'N':>9} {'threads':>8} {'seconds':>8} {'ns/osc-step':>12} {'r_eq':>6}")
    for n in (10_000, 100_000, 1_000_000):
        for threads in (False, True):
            start = time.perf_counter()
            ds = simulate_reduced(n, threads=threads, **ARGS)
            took = time.perf_counter() - start
            steps = round(ARGS["duration"] / ARGS["dt"])
            print(
                f"{n:>9} {threads!s:>8} {took:8.2f} {took / (n * steps) * 1e9:12.2f} "
                f"{float(ds.r_eq[0]):6.3f}"
            )


if __name__ == "__main__":
    main()

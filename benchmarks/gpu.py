"""GPU kernel throughput next to the CPU kernel for the same work (oscillator-steps/s).

Needs an NVIDIA GPU (and `pip install -e ".[gpu]"` where numba's CUDA target is not
built in). Without one it says so and exits with status 1.

    python benchmarks/gpu.py                       # B x N = 100x1000 and 1000x100
    python benchmarks/gpu.py --sizes 100x1000 --duration 100
"""

from __future__ import annotations

import argparse
import math
import sys
import time

from metrosync import build_ensemble, get_preset
from metrosync.integrators import kernel_cuda, verlet
from metrosync.integrators._state import StepState


def rate(advance, ensemble, steps, **options) -> float:
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=steps // 10 + 1, trajectories=False,
    )  # fmt: skip
    start = time.perf_counter()
    advance(state, ensemble.system, dt=0.01, step0=0, n_steps=steps, record_every=10,
            overturn_angle=math.pi / 2, **options)  # fmt: skip
    return ensemble.runs * ensemble.n * steps / (time.perf_counter() - start)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", nargs="+", default=["100x1000", "1000x100"])
    parser.add_argument("--duration", type=float, default=100.0, help="simulated seconds")
    args = parser.parse_args()
    if not kernel_cuda.gpu_available():
        print("no CUDA GPU found (numba.cuda.is_available() is False)", file=sys.stderr)
        return 1
    steps = int(round(args.duration / 0.01))
    print(f"{'B':>6} {'N':>6} {'gpu':>11} {'cpu':>11} {'gpu/cpu':>8}   (oscillator-steps/s)")
    for size in args.sizes:
        b, n = (int(x) for x in size.lower().split("x"))
        ens = build_ensemble(n, 192.0, params=get_preset("default"), sigma_bpm=0.75, runs=b, seed=1)
        rate(kernel_cuda.advance_state, ens, 10)  # compile
        gpu = rate(kernel_cuda.advance_state, ens, steps)
        rate(verlet.advance_state, ens, 10)
        cpu = rate(verlet.advance_state, ens, max(10, steps // 10))
        print(f"{b:>6} {n:>6} {gpu:>11.3e} {cpu:>11.3e} {gpu / cpu:>8.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

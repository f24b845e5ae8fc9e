"""What compiling the kernels costs on a first run, and loading them on later runs.

In a fresh interpreter whose NUMBA_CACHE_DIR is an empty temporary folder (cold), then
in another one on the same folder (warm), each CPU kernel (`verlet` and `located`, both
memory layouts) is compiled or loaded for a small ensemble, timed in wall seconds and
CPU seconds of the process (compiling is single-threaded, so on a busy machine the CPU
seconds are the better guide). The user's own cache is not touched.

    python benchmarks/compile.py
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

PROBE = """
import math, time
import metrosync as ms
from metrosync.integrators import located, verlet
from metrosync.integrators._state import StepState
for scheme in (verlet, located):
    for layout in scheme.LAYOUTS:
        runs = 16 if layout == "runs" else 2
        ens = ms.build_ensemble(3, 192.0, params=ms.get_preset("default"), runs=runs, seed=1)
        state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0,
                                ens.phi_dot0, n_records=3, trajectories=False)
        wall, cpu = time.perf_counter(), time.process_time()
        scheme.advance_state(state, ens.system, dt=0.01, step0=0, n_steps=20, record_every=10,
                             overturn_angle=math.pi / 2, layout=layout)
        print(scheme.__name__.rsplit(".", 1)[-1], layout, time.perf_counter() - wall,
              time.process_time() - cpu)
"""


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        env = {"NUMBA_CACHE_DIR": cache}
        for state in ("cold", "warm"):
            out = subprocess.run([sys.executable, "-c", PROBE], check=True, text=True,
                                 capture_output=True, env={**os.environ, **env})  # fmt: skip
            total_wall = total_cpu = 0.0
            for line in out.stdout.splitlines():
                scheme, layout, wall, cpu = line.split()
                total_wall += float(wall)
                total_cpu += float(cpu)
                print(f"{state}: {scheme:8s} {layout:12s} {float(wall):6.2f} s wall "
                      f"{float(cpu):6.2f} s CPU")  # fmt: skip
            print(f"{state}: all four        {total_wall:6.2f} s wall {total_cpu:6.2f} s CPU")


if __name__ == "__main__":
    main()

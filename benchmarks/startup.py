"""How soon a second `metrosync simulate` starts computing, with a warm compile cache.

Fills the cache once, then, in several fresh interpreters, times:
  * ``import metrosync`` and building the CLI's parser (what `metrosync simulate` does
    before any work);
  * from there to the end of the kernel's first step (building the ensemble, checking
    the compile cache, loading the cached kernel): when computing has started;
  * a whole first ``simulate`` call of 0.1 s, including wrapping the result in xarray
    (whose first use imports pandas).

    python benchmarks/startup.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys

PROBE = """
import time
t0 = time.perf_counter()
import metrosync
from metrosync.cli import build_parser
build_parser().parse_args(["simulate", "--runs", "2", "--duration", "0.1"])
t1 = time.perf_counter()
from metrosync import build_ensemble, get_preset
from metrosync.integrators import verlet
from metrosync.integrators._state import StepState
ens = build_ensemble(7, 192.0, params=get_preset("default"), runs=2, seed=0)
state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                        n_records=2, trajectories=False)
verlet.advance_state(state, ens.system, dt=0.01, step0=0, n_steps=1, record_every=1,
                     overturn_angle=1.5707963)
t2 = time.perf_counter()
metrosync.simulate(7, 192, runs=2, duration=0.1)
t3 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2)
"""


def main(repeats: int = 5) -> None:
    subprocess.run([sys.executable, "-c", PROBE], check=True, capture_output=True)  # warm cache
    rows = []
    for _ in range(repeats):
        out = subprocess.run(
            [sys.executable, "-c", PROBE], check=True, capture_output=True, text=True
        )
        rows.append([float(x) for x in out.stdout.split()])
    imp, first_step, wrap = (statistics.median(col) for col in zip(*rows, strict=True))
    print(f"import + CLI parser {imp:.3f} s; first kernel step done {first_step:.3f} s later: "
          f"computing starts {imp + first_step:.3f} s after launch; "
          f"a whole first simulate (incl. xarray's first use) adds {wrap:.3f} s "
          f"(median of {repeats} fresh processes)")  # fmt: skip


if __name__ == "__main__":
    main()

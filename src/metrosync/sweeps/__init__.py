"""Parameter sweeps: grids, a resumable point store, executors, and ω_c analysis.

``grid``       swept axes, fixed settings and per-point seeds
``points``     one point: its `simulate` call, what it keeps, and its content key
``keep``       what a point stores of its result (also for `metrosync.reproduce`)
``store``      one atomically written file per finished point; the merged dataset
``executors``  in process, Dask LocalCluster, or an existing Dask cluster
``sweep``      the `sweep` entry point
``critical``   the critical frequency ω_c(N) and its finite-size extrapolation
``scaling``    the finite-size-scaling collapse of r_eq(ω₀, N) and ω_c(∞) from it
"""

from .grid import Grid, parse_values
from .store import PointStore, merge
from .sweep import SweepResult, sweep

__all__ = ["Grid", "PointStore", "SweepResult", "merge", "parse_values", "sweep"]

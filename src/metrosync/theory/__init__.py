"""Why the transition sits where it does: a reduced theory of the disk model.

* `sakaguchi`: the exact onset K_c(α, σ) of the Kuramoto–Sakaguchi model.
* `coupling`: K(ω₀, N) e^{−iα(ω₀)} measured on the full model two ways, and estimated.
* `reduced`, `fitted`: the phase model, alone or on the ensembles `simulate` builds.
* `predict`, `figure`: the predicted critical frequency ω_c(σ) for a preset, drawn.

Nothing here is imported by ``import metrosync``; `reduced_theory` and
`simulate_reduced` are served lazily from the top-level package.
"""

# The steady-swing tuning is single-pendulum mechanics and lives in `metrosync.model`;
# its names stay importable from here, where the theory uses them.
from ..model.steady_swing import (
    SteadySwing,
    relaxation_rate,
    steady_swing,
    steady_swing_bpm_range,
    steady_swing_l2,
    tick_rate_bpm,
)
from ..model.tuning import TUNINGS, l2_for_bpm
from .coupling import Coupling, disk_scale, measure_by_growth, measure_by_pair
from .estimate import estimate
from .figure import plot_theory
from .fitted import simulate_fitted
from .predict import coupling_curve, default_cache_dir, predict_onset, reduced_theory
from .reduced import simulate_reduced
from .sakaguchi import Onset, critical_coupling, growth_rate, onset

__all__ = [
    "TUNINGS",
    "Coupling",
    "Onset",
    "SteadySwing",
    "coupling_curve",
    "critical_coupling",
    "default_cache_dir",
    "disk_scale",
    "estimate",
    "growth_rate",
    "l2_for_bpm",
    "measure_by_growth",
    "measure_by_pair",
    "onset",
    "plot_theory",
    "predict_onset",
    "reduced_theory",
    "relaxation_rate",
    "simulate_fitted",
    "simulate_reduced",
    "steady_swing",
    "steady_swing_bpm_range",
    "steady_swing_l2",
    "tick_rate_bpm",
]

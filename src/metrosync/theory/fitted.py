"""The fitted phase model run on the very ensembles `metrosync.simulate` would build.

`simulate_fitted(n, bpm, sigma_bpm=..., runs=..., seed=...)` takes the same ensemble
arguments as `simulate`, builds the same ensemble (`build_ensemble`: the same drawn
natural frequencies and the same random initial phases), and runs the reduced model
(`reduced.simulate_reduced`) on it instead of the mechanics:

* each metronome's natural frequency is its tick rate at the steady swing
  (`model.steady_swing.tick_rate_bpm`), which is what the phase model's ω_i means;
* its initial phase is the analytic phase atan2(−θ̇/ω, θ) of its initial state;
* K and α are the measured coupling at the nominal ``bpm``, rescaled to ``n``
  (`coupling.measure_by_growth`, cached like `predict.coupling_curve`), unless given.

Because both models see the same draws, their r_eq differ only by the reduction's
error and by the dynamics, not by sampling.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from ..ensemble import build_ensemble
from ..model import ModelParameters, get_preset
from ..model.steady_swing import tick_rate_bpm
from ..model.tuning import with_tuning
from .coupling import Coupling
from .predict import _measure_cached
from .reduced import simulate_reduced


def simulate_fitted(
    n: int = 64,
    bpm: float = 192.0,
    *,
    sigma_bpm: float = 0.75,
    runs: int = 1,
    duration: float = 600.0,
    dt: float = 0.1,
    seed: int | None = 0,
    preset: ModelParameters | str = "default",
    tuning: str | None = None,
    coupling: Coupling | None = None,
    equilibrium_window: float | None = None,
    cache: Path | None = None,
) -> xr.Dataset:
    """Run the Kuramoto–Sakaguchi reduction on the ensemble `simulate` would build.

    n, bpm, sigma_bpm, runs, seed, preset : as for `metrosync.simulate`.
    duration, dt, equilibrium_window : of the phase model (dt may be far coarser than the
        mechanics' step: the phases are followed in the frame of the mean frequency).
    coupling : K e^{−iα} to use; default measured at ``bpm`` (growth method) for ``n``.
    cache : folder of cached coupling measurements.
    """
    params = with_tuning(get_preset(preset, warn=False), tuning)
    ensemble = build_ensemble(n, bpm, params=params, sigma_bpm=sigma_bpm, runs=runs, seed=seed)
    if coupling is None:
        coupling = _measure_cached(bpm, "growth", params, 32, cache)
    coupling = coupling.for_n(ensemble.n, params)
    ticks = tick_rate_bpm(params.metronome, ensemble.l2, exact=False)
    omega = math.pi / 60.0 * ticks
    phases = np.arctan2(-ensemble.theta_dot0 / ensemble.system.omega, ensemble.theta0)
    ds = simulate_reduced(
        k=coupling.k,
        alpha=coupling.alpha,
        omega=omega,
        phases0=phases,
        runs=ensemble.runs,
        duration=duration,
        dt=dt,
        seed=seed,
        equilibrium_window=equilibrium_window,
    )
    ds.attrs.update(
        bpm=float(bpm),
        sigma_bpm=float(sigma_bpm),
        preset=params.name,
        tuning=params.metronome.tuning,
        k_err=coupling.k_err,
        alpha_err=coupling.alpha_err,
        coupling_method=coupling.method,
    )
    ds["tick_bpm"] = (
        ("run", "metronome"),
        ticks,
        {"units": "BPM", "long_name": "tick rate at the steady swing"},
    )
    return ds

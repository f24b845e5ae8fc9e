"""`simulate`: the one entry point for running an ensemble.

It goes one way through four stages (`metrosync.simulation`): the request, its options
checked and the memory and time the run will take estimated before anything is
allocated (`metrosync.budget`: refused when it cannot fit, a warning when it will take
minutes); the ensemble built from it (`metrosync.ensemble`); the run, which advances it
(fixed-step schemes in chunks of about 0.25 s each, `metrosync.pacing`: Ctrl-C and the
progress bar act promptly); and the dataset, what was recorded wrapped in an
`xarray.Dataset` (its variables are listed in `metrosync.simulation.dataset`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from .groups import Group
from .model import Metronome, ModelParameters
from .simulation.dataset import to_dataset
from .simulation.request import SimulationRequest
from .simulation.run import run


def simulate(
    n: int | None = 7,
    bpm: float | None = 192.0,
    *,
    sigma_bpm: float = 0.0,
    groups: Sequence[Group | tuple] | None = None,
    runs: int = 1,
    duration: float = 600.0,
    dt: float = 0.01,
    seed: int | None = 0,
    preset: str | ModelParameters = "default",
    changes: Mapping[str, float] | None = None,
    integrator: str = "verlet",
    backend: str = "numba",
    frequencies_bpm: Sequence[float] | np.ndarray | None = None,
    metronomes: Sequence[Metronome] | None = None,
    amplitude: float | None = None,
    theta0: Sequence[float] | np.ndarray | None = None,
    theta_dot0: Sequence[float] | np.ndarray | None = None,
    record_every: int | None = None,
    trajectories: bool = False,
    equilibrium_window: float | None = None,
    overturn_angle: float = math.pi / 2,
    progress: bool | None = None,
) -> xr.Dataset:
    """Simulate ``runs`` independent ensembles of ``n`` metronomes on a free disk.

    The defaults describe one deterministic run of identical metronomes (σ = 0, one
    run): a building block that the calibration, the sweeps and the paper's studies
    configure explicitly. The command line's defaults (σ = 0.75 BPM, 20 runs) describe
    the paper's experiment instead; ``metrosync simulate --help`` says so too.

    Parameters
    ----------
    n, bpm : number of metronomes and nominal beat frequency (BPM, two beats a period).
        The nominal BPM tunes the small-swing frequency; at the default swing a
        metronome ticks slower (``tick_rate_bpm`` in the result holds the measured rate).
    sigma_bpm : spread (std, BPM) of the natural frequencies, drawn per run.
    groups : groups of metronomes at their own frequencies, e.g.
        ``[(7, 184.0), (7, 200.0)]`` or with a spread of their own ``(7, 200.0, 0.5)``;
        they replace ``n`` and ``bpm`` (pass None for those), ``sigma_bpm`` is the
        spread of the groups that give none, and the dataset gains each group's order
        parameters (`metrosync.simulation.dataset`). See `build_ensemble`.
    runs : number of independent runs B.
    duration, dt : simulated time and time step, s.
    seed : seed of every random choice; the result is a pure function of the inputs.
    preset : ``"default"``, ``"boda2013"`` or a `ModelParameters`.
    changes : model parameters to change by name, e.g. ``{"drive": 1e-4, "c_phi": 0}``.
    integrator : a name from `metrosync.integrators.REGISTRY`: ``"verlet"`` (the
        paper's scheme), ``"located"`` (the same with each kick at its crossing
        instant: second order with kicks) or ``"exact"`` (reference).
    backend : for a fixed-step integrator, ``"numba"`` (compiled, parallel over runs),
        ``"numpy"`` (the plain NumPy twin, slow) or ``"gpu"`` (an NVIDIA GPU through
        numba.cuda; no trajectories yet); see `metrosync.integrators.BACKENDS`.
    frequencies_bpm, metronomes, amplitude, theta0, theta_dot0 : see `build_ensemble`.
    record_every : record every this many steps; default the step count of 0.1 s, or
        the stride that keeps `MAX_RECORDS` records when 0.1 s would give more (the
        stride used is in ``attrs["record_every"]`` and ``attrs["record_interval"]``).
    trajectories : also keep θ, θ̇, φ, φ̇ at each record.
    equilibrium_window : length (s) of the final window averaged for r_eq;
        default a quarter of ``duration``.
    overturn_angle : the angle (rad) beyond which a run is flagged overturned: a
        metronome with ``abs(theta)`` above it.
    progress : show a progress bar; default when stderr is a terminal.

    Returns
    -------
    xarray.Dataset, described in `metrosync.simulation.dataset`.

    Raises
    ------
    ParameterError for bad input; `metrosync.budget.ResourceError` when the run would
    not fit in the memory available (before anything is allocated). Warns
    `metrosync.budget.LongRunWarning` when it is estimated to take minutes or more.
    """
    request = SimulationRequest(
        n=n,
        bpm=bpm,
        sigma_bpm=sigma_bpm,
        groups=groups,
        runs=runs,
        duration=duration,
        dt=dt,
        seed=seed,
        preset=preset,
        changes=changes,
        integrator=integrator,
        backend=backend,
        frequencies_bpm=frequencies_bpm,
        metronomes=metronomes,
        amplitude=amplitude,
        theta0=theta0,
        theta_dot0=theta_dot0,
        record_every=record_every,
        trajectories=trajectories,
        equilibrium_window=equilibrium_window,
        overturn_angle=overturn_angle,
        progress=progress,
    )
    ensemble = request.build_ensemble()
    return to_dataset(request, ensemble, run(request, ensemble))

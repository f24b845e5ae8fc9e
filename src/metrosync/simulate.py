"""`simulate`: the one entry point for running an ensemble.

It checks the inputs, builds the ensemble, advances it in chunks (with a progress
bar on long work), and wraps what was recorded in an `xarray.Dataset`:

    r            (time, run)              analytic-phase order parameter
    r_crossing   (time, run)              crossing-interpolated order parameter (NaN
                                          where some metronome has no phase yet)
    r_eq         (run)                    mean of r_crossing over the final window
    r_eq_analytic(run)                    the same from r
    status       (run)                    bit flags: 1 overturned, 2 diverged
    frequency_bpm, l2 (run, metronome)    natural frequency and slider position
    theta, theta_dot (time, run, metronome), phi, phi_dot (time, run)
                                          trajectories, only when asked for

``time`` is in seconds; every parameter is in ``attrs``.
"""

from __future__ import annotations

import math
import sys as _sys
from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from ._version import __version__
from .ensemble import Ensemble, build_ensemble, check_time_step
from .errors import ParameterError
from .integrators import BACKENDS, get_integrator
from .integrators._state import Records, StepState, records_of
from .model import Metronome, ModelParameters, get_preset
from .observables.order import ensemble_statistics, equilibrium_order
from .progress import progress_bar
from .status import STATUS_MEANINGS

#: Oscillator-steps per chunk between progress updates.
CHUNK_WORK = 4_000_000


def simulate(
    n: int | None = 7,
    bpm: float | None = 192.0,
    *,
    sigma_bpm: float = 0.0,
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

    Parameters
    ----------
    n, bpm : number of metronomes and nominal beat frequency (BPM, two beats a period).
    sigma_bpm : spread (std, BPM) of the natural frequencies, drawn per run.
    runs : number of independent runs B.
    duration, dt : simulated time and time step, s.
    seed : seed of every random choice; the result is a pure function of the inputs.
    preset : ``"default"``, ``"boda2013"`` or a `ModelParameters`.
    changes : model parameters to change by name, e.g. ``{"drive": 1e-4, "c_phi": 0}``.
    integrator : a name from `metrosync.integrators.REGISTRY`: ``"verlet"`` (the
        paper's scheme) or ``"exact"`` (reference).
    backend : for a fixed-step integrator, ``"numba"`` (compiled, parallel over runs),
        ``"numpy"`` (plain reference, slow) or ``"gpu"`` (an NVIDIA GPU through
        numba.cuda; no trajectories yet); see `metrosync.integrators.BACKENDS`.
    frequencies_bpm, metronomes, amplitude, theta0, theta_dot0 : see `build_ensemble`.
    record_every : record every this many steps; default the step count of 0.1 s.
    trajectories : also keep θ, θ̇, φ, φ̇ at each record.
    equilibrium_window : length (s) of the final window averaged for r_eq;
        default a quarter of ``duration``.
    overturn_angle : |θ| beyond which a run is flagged overturned, rad.
    progress : show a progress bar; default when stderr is a terminal.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    params = get_preset(preset, warn=not changes)
    if changes:
        params = get_preset(params.with_changes(**changes))
    scheme = get_integrator(integrator)
    if backend not in BACKENDS:
        raise ParameterError(f"unknown `backend` {backend!r}; choose one of {sorted(BACKENDS)}.")
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"`duration` must be a finite time > 0 s, got {duration!r}.")
    if not (math.isfinite(overturn_angle) and overturn_angle > 0):
        raise ParameterError(f"`overturn_angle` must be > 0 rad, got {overturn_angle!r}.")
    ensemble = build_ensemble(
        n,
        bpm,
        params=params,
        sigma_bpm=sigma_bpm,
        runs=runs,
        seed=seed,
        frequencies_bpm=frequencies_bpm,
        metronomes=metronomes,
        amplitude=amplitude,
        theta0=theta0,
        theta_dot0=theta_dot0,
    )
    check_time_step(dt, ensemble)
    n_steps = int(round(duration / dt))
    if record_every is None:
        record_every = max(1, int(round(0.1 / dt)))
    if (
        isinstance(record_every, bool)
        or not isinstance(record_every, int | np.integer)
        or record_every < 1
    ):
        raise ParameterError(f"`record_every` must be an integer >= 1 step, got {record_every!r}.")
    if record_every > n_steps:
        raise ParameterError(
            f"`record_every` = {record_every} steps exceeds the {n_steps} steps of the run; "
            f"lower it or lengthen `duration`."
        )
    n_records = n_steps // record_every + 1
    window = duration / 4 if equilibrium_window is None else float(equilibrium_window)
    if not (0 < window <= duration):
        raise ParameterError(
            f"`equilibrium_window` must be in (0, duration], got {equilibrium_window!r}."
        )
    show = _sys.stderr.isatty() if progress is None else progress

    if scheme.fixed_step:
        kernel = scheme.stepper(backend, trajectories=trajectories)
        records = _run_fixed_step(
            ensemble, kernel, dt, n_steps, record_every, n_records, trajectories,
            overturn_angle, show,
        )  # fmt: skip
    else:
        with progress_bar(total=ensemble.runs, unit="run", enabled=show) as bar:
            records = scheme.integrate(
                ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi_dot0,
                duration=n_steps * dt, grid_dt=record_every * dt, n_records=n_records,
                trajectories=trajectories, overturn_angle=overturn_angle,
                on_run_done=lambda: bar.update(1),
            )  # fmt: skip
    settings = {
        "n": ensemble.n,
        "bpm": "explicit"
        if bpm is None or frequencies_bpm is not None or metronomes is not None
        else bpm,
        "sigma_bpm": sigma_bpm,
        "runs": ensemble.runs,
        "duration": n_steps * dt,
        "dt": dt,
        "seed": "none" if seed is None else seed,
        "integrator": integrator,
        "backend": backend if scheme.fixed_step else scheme.backends[0],
        "record_every": record_every,
        "equilibrium_window": window,
        "overturn_angle": overturn_angle,
    }
    return _to_dataset(ensemble, records, record_every * dt, window, settings)


def _run_fixed_step(ensemble, backend, dt, n_steps, record_every, n_records, trajectories,
                    overturn_angle, show) -> Records:  # fmt: skip
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=n_records, trajectories=trajectories,
    )  # fmt: skip
    per_chunk = max(1, CHUNK_WORK // (ensemble.runs * ensemble.n))
    per_chunk = max(record_every, per_chunk // record_every * record_every)
    with progress_bar(total=round(n_steps * dt, 6), unit="s", enabled=show) as bar:
        step = 0
        while step < n_steps:
            count = min(per_chunk, n_steps - step)
            backend.advance_state(
                state, ensemble.system, dt=dt, step0=step, n_steps=count,
                record_every=record_every, overturn_angle=overturn_angle,
            )  # fmt: skip
            step += count
            bar.update(round(count * dt, 6))
    return records_of(state)


def _to_dataset(
    ensemble: Ensemble, rec: Records, grid_dt: float, window: float, settings
) -> xr.Dataset:
    n_rec = rec.r.shape[1]
    time = np.arange(n_rec) * grid_dt
    r = rec.r.T
    r_cross = rec.r_crossing.T
    r_eq = equilibrium_order(r_cross, time, window)
    r_eq_analytic = equilibrium_order(r, time, window)
    mean, spread = ensemble_statistics(r_eq)
    data = {
        "r": (("time", "run"), r, {"long_name": "Kuramoto order parameter (analytic phase)"}),
        "r_crossing": (
            ("time", "run"),
            r_cross,
            {"long_name": "Kuramoto order parameter (phase interpolated between upward crossings)"},
        ),
        "r_eq": (
            ("run",),
            r_eq,
            {"long_name": "equilibrium r (mean of r_crossing over final window)"},
        ),
        "r_eq_analytic": (("run",), r_eq_analytic, {"long_name": "equilibrium r from r"}),
        "status": (
            ("run",),
            rec.status.astype(np.int8),
            {
                "long_name": "run status bit flags (0 = ok)",
                "flag_masks": np.array(list(STATUS_MEANINGS), dtype=np.int8),
                "flag_meanings": " ".join(STATUS_MEANINGS.values()),
            },
        ),
        "frequency_bpm": (
            ("run", "metronome"),
            ensemble.frequency_bpm,
            {"units": "BPM", "long_name": "natural frequency on a rigid support"},
        ),
        "l2": (
            ("run", "metronome"),
            ensemble.l2,
            {"units": "m", "long_name": "slider position L2"},
        ),
    }
    if rec.theta is not None:
        data["theta"] = (
            ("time", "run", "metronome"),
            rec.theta.transpose(1, 0, 2),
            {"units": "rad"},
        )
        data["theta_dot"] = (
            ("time", "run", "metronome"),
            rec.theta_dot.transpose(1, 0, 2),
            {"units": "rad/s"},
        )
        data["phi"] = (("time", "run"), rec.phi.T, {"units": "rad"})
        data["phi_dot"] = (("time", "run"), rec.phi_dot.T, {"units": "rad/s"})
    attrs = {**settings, **_flat_params(ensemble.params)}
    attrs.update(
        r_eq_mean=mean,
        r_eq_std=spread,
        disk_inertia=float(ensemble.disk_inertia[0]),
        metrosync_version=__version__,
    )
    return xr.Dataset(
        data,
        coords={
            "time": ("time", time, {"units": "s"}),
            "run": np.arange(ensemble.runs),
            "metronome": np.arange(ensemble.n),
        },
        attrs=attrs,
    )


def _flat_params(params: ModelParameters) -> dict:
    out = {}
    for key, value in params.as_dict().items():
        if isinstance(value, float) and math.isinf(value):
            value = "inf"
        out[key] = value
    return out

"""`simulate`: the one entry point for running an ensemble.

It checks the inputs, estimates the memory and time the run will take before it
allocates anything (`metrosync.budget`: refused when it cannot fit, a warning when
it will take minutes), builds the ensemble, advances it in chunks of about 0.25 s
each (`metrosync.pacing`: Ctrl-C and the progress bar act promptly), and wraps what
was recorded in an `xarray.Dataset`:

    r            (time, run)              analytic-phase order parameter
    r_crossing   (time, run)              crossing-interpolated order parameter (NaN
                                          where some metronome has no phase yet)
    r_eq         (run)                    mean of r_crossing over the final window
    r_eq_analytic(run)                    the same from r
    status       (run)                    bit flags (see `metrosync.status`)
    frequency_bpm, l2 (run, metronome)    natural frequency and slider position
    tick_rate_bpm (run, metronome)        ticks per minute measured at the end of the
                                          run (see `metrosync.observables.ticks`)
    escapement_offset (run, metronome)    where each escapement acts, rad, only when
                                          some metronome is out of beat
    escapement_stopped (run, metronome)   True for a metronome whose escapement stopped
                                          firing ("metronome death", `status` bit
                                          ``stopped``), only when some run has one
    disk_at_rest (run)                    fraction of the final window with the disk
                                          held at rest by dry friction, only when
                                          ``disk_dry_friction`` is on
    theta, theta_dot (time, run, metronome), phi, phi_dot (time, run)
                                          trajectories, only when asked for

With ``groups`` (`metrosync.groups`), also each group's order parameters, taken over
its own metronomes only:

    group        (metronome)              the group of each metronome (coordinate)
    group_n, group_bpm, group_sigma_bpm (group)
                                          each group's size, nominal BPM and spread
    r_group, r_crossing_group (time, run, group)
                                          r and r_crossing of each group
    r_eq_group, r_eq_analytic_group (run, group)
                                          r_eq and r_eq_analytic of each group

``time`` is in seconds; every parameter is in ``attrs`` (the groups as ``groups``,
e.g. ``"7@184:0.75 7@200:0.75"``, and each group's mean and σ of r_eq as
``r_eq_group_mean``, ``r_eq_group_std``).
"""

from __future__ import annotations

import math
import operator
import sys as _sys
import warnings
from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from ._version import __version__
from ._words import plural
from .budget import simulation_budget
from .ensemble import MIN_STEPS_PER_PERIOD, Ensemble, build_ensemble, check_time_step
from .errors import EscapementWarning, OverturnWarning, ParameterError
from .groups import Group, describe_groups
from .integrators import BACKENDS, get_integrator
from .integrators._state import Records, StepState, records_of
from .model import Metronome, ModelParameters, get_preset
from .observables.death import flag_stopped, stopped_metronomes
from .observables.order import ensemble_statistics, equilibrium_order
from .observables.ticks import CrossingTally, tail_span, tick_rate
from .pacing import Pacer
from .progress import progress_bar
from .status import STATUS_MEANINGS, STATUS_STOPPED

#: Time between records of r(t) when `record_every` is not given, s.
RECORD_SECONDS = 0.1
#: Most records of r(t) per run when `record_every` is not given: a longer run records
#: at a larger stride, so that memory does not grow with the duration.
MAX_RECORDS = 100_000
#: Most steps of one run: step times are exact in float64 below 2**53.
MAX_STEPS = 2.0**53


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
        parameters (module docstring). See `build_ensemble`.
    runs : number of independent runs B.
    duration, dt : simulated time and time step, s.
    seed : seed of every random choice; the result is a pure function of the inputs.
    preset : ``"default"``, ``"boda2013"`` or a `ModelParameters`.
    changes : model parameters to change by name, e.g. ``{"drive": 1e-4, "c_phi": 0}``.
    integrator : a name from `metrosync.integrators.REGISTRY`: ``"verlet"`` (the
        paper's scheme), ``"located"`` (the same with each kick at its crossing
        instant: second order with kicks) or ``"exact"`` (reference).
    backend : for a fixed-step integrator, ``"numba"`` (compiled, parallel over runs),
        ``"numpy"`` (plain reference, slow) or ``"gpu"`` (an NVIDIA GPU through
        numba.cuda; no trajectories yet); see `metrosync.integrators.BACKENDS`.
    frequencies_bpm, metronomes, amplitude, theta0, theta_dot0 : see `build_ensemble`.
    record_every : record every this many steps; default the step count of 0.1 s, or
        the stride that keeps `MAX_RECORDS` records when 0.1 s would give more (the
        stride used is in ``attrs["record_every"]`` and ``attrs["record_interval"]``).
    trajectories : also keep θ, θ̇, φ, φ̇ at each record.
    equilibrium_window : length (s) of the final window averaged for r_eq;
        default a quarter of ``duration``.
    overturn_angle : |θ| beyond which a run is flagged overturned, rad.
    progress : show a progress bar; default when stderr is a terminal.

    Returns
    -------
    xarray.Dataset, described in the module docstring.

    Raises
    ------
    ParameterError for bad input; `metrosync.budget.ResourceError` when the run would
    not fit in the memory available (before anything is allocated). Warns
    `metrosync.budget.LongRunWarning` when it is estimated to take minutes or more.
    """
    params = get_preset(preset, warn=not changes)
    if changes:
        params = get_preset(params.with_changes(**changes))
    scheme = get_integrator(integrator)
    if backend not in BACKENDS:
        raise ParameterError(f"unknown `backend` {backend!r}; choose one of {sorted(BACKENDS)}.")
    # What runs where is one table (`metrosync.capabilities`): refuse before any work.
    request = {"trajectories": trajectories, "groups": groups, "escapement_stopped": True}
    scheme.require(backend, params, request)
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"`duration` must be a finite time > 0 s, got {duration!r}.")
    if not (math.isfinite(overturn_angle) and overturn_angle > 0):
        raise ParameterError(f"`overturn_angle` must be > 0 rad, got {overturn_angle!r}.")
    # Size before work: everything below that grows with the inputs is estimated and
    # checked before the ensemble's first array is allocated.
    if not (math.isfinite(dt) and dt > 0):
        raise ParameterError(
            f"`dt` = {dt!r} s does not resolve any period: it needs 0 < dt <= "
            f"period/{MIN_STEPS_PER_PERIOD} ({120 / 192 / MIN_STEPS_PER_PERIOD:g} s at 192 BPM)."
        )
    if not duration / dt < MAX_STEPS:
        raise ParameterError(
            f"`duration` / `dt` = {duration:g} s / {dt:g} s = {duration / dt:.3g} steps, more "
            f"than the {MAX_STEPS:.3g} a run can count; shorten `duration` or enlarge `dt`."
        )
    n_steps = int(round(duration / dt))
    if n_steps < 1:
        raise ParameterError(
            f"`duration` = {duration!r} s is shorter than one time step (`dt` = {dt!r} s); "
            f"lengthen `duration`."
        )
    record_every, record_reason = record_stride(record_every, n_steps, dt)
    n_records = n_steps // record_every + 1
    size = _request_size(n, runs, frequencies_bpm, metronomes, theta0, groups)
    if size is not None:
        # Several groups keep their records per group: count them as that many records.
        simulation_budget(
            n=size[0], runs=size[1], steps=n_steps, records=n_records * size[2],
            trajectories=trajectories, integrator=integrator, backend=backend, dt=dt,
        ).check()  # fmt: skip
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
        groups=groups,
    )
    check_time_step(dt, ensemble)
    window = duration / 4 if equilibrium_window is None else float(equilibrium_window)
    if not (0 < window <= duration):
        raise ParameterError(
            f"`equilibrium_window` must be in (0, duration], got {equilibrium_window!r}."
        )
    show = _sys.stderr.isatty() if progress is None else progress
    _warn_overturned_start(ensemble, amplitude, overturn_angle)
    _warn_silent_escapement(ensemble, amplitude)
    longest_period = float(2 * np.pi / np.min(ensemble.system.omega))
    tail_steps = min(n_steps, math.ceil(tail_span(window, longest_period) / dt))

    if scheme.fixed_step:
        kernel = scheme.stepper(backend, trajectories=trajectories)
        window_steps = min(n_steps, int(round(window / dt)))
        records, rates = _run_fixed_step(
            ensemble, kernel, backend, dt, n_steps, record_every, n_records, trajectories,
            overturn_angle, show, tail_steps, window_steps,
        )  # fmt: skip
    else:
        with progress_bar(total=ensemble.runs, unit="run", enabled=show) as bar:
            records = scheme.integrate(
                ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi_dot0,
                duration=n_steps * dt, grid_dt=record_every * dt, n_records=n_records,
                trajectories=trajectories, overturn_angle=overturn_angle,
                on_run_done=lambda: bar.update(1), group_start=ensemble.group_start,
                rest_since=n_steps * dt - window,
            )  # fmt: skip
        since = (n_steps - tail_steps) * dt
        rates = np.stack([tick_rate(run, since) for run in records.crossings])
    # A metronome whose escapement stopped firing is dead: its run is flagged too.
    records.status = flag_stopped(
        records.status, records.last_kick, n_steps * dt, ensemble.system.omega
    )
    # A run that overturned, diverged or stopped has no steady tick.
    rates[records.status != 0] = np.nan
    settings = {
        "n": ensemble.n,
        "bpm": "groups"
        if groups is not None
        else "explicit"
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
        "record_interval": record_every * dt,
        "record_every_reason": record_reason,
        "equilibrium_window": window,
        "overturn_angle": overturn_angle,
        "tick_rate_span": tail_steps * dt,
    }
    return _to_dataset(ensemble, records, rates, record_every * dt, window, settings)


def _warn_overturned_start(ensemble: Ensemble, amplitude, overturn_angle: float) -> None:
    """Warn when some pendulum starts swinging past ``overturn_angle``: its run will be
    flagged at once and its r means nothing."""
    swing = np.hypot(ensemble.theta0, ensemble.theta_dot0 / ensemble.system.omega)
    if not np.any(swing > overturn_angle):
        return
    runs = int(np.any(swing > overturn_angle, axis=1).sum())
    given = (
        f"`amplitude` = {amplitude!r} rad"
        if amplitude is not None
        else (
            f"the start (`theta0`, `theta_dot0`) swings up to {float(swing.max()):.3g} rad, which"
        )
    )
    warnings.warn(
        f"{given} is beyond `overturn_angle` = {overturn_angle:.4g} rad: {runs} of "
        f"{ensemble.runs} run(s) start overturned, are flagged in `status`, and their r is "
        f"not meaningful. Start below {overturn_angle:.4g} rad.",
        OverturnWarning,
        stacklevel=3,
    )


def _warn_silent_escapement(ensemble: Ensemble, amplitude) -> None:
    """Warn when some escapement's angle lies beyond its pendulum's start swing: it
    cannot fire, the pendulum decays ("metronome death", `observables.death`), and the
    run will be flagged `stopped`."""
    swing = np.hypot(ensemble.theta0, ensemble.theta_dot0 / ensemble.system.omega)
    offset = np.abs(ensemble.system.escapement_offset)
    beyond = offset > swing
    if not np.any(beyond):
        return
    runs = int(np.any(beyond, axis=1).sum())
    start = f"`amplitude` = {amplitude!r} rad" if amplitude is not None else "the start swing"
    warnings.warn(
        f"`escapement_offset` = {float(offset[beyond].max()):.4g} rad lies beyond "
        f"{start} ({float(swing[beyond].min()):.3g} rad) of "
        f"{plural(int(beyond.sum()), 'metronome')} in {runs} of "
        f"{plural(ensemble.runs, 'run')}: their escapement never fires, "
        f'the pendulum decays ("metronome death"), and the run is flagged `stopped` in '
        f"`status`. Give an `escapement_offset` below the swing, or start wider (`amplitude`).",
        EscapementWarning,
        stacklevel=3,
    )


def record_stride(record_every, n_steps: int, dt: float) -> tuple[int, str]:
    """The record stride (steps) of a run of ``n_steps`` steps of ``dt`` s, and why it
    is what it is (stored in ``attrs``): ``record_every`` when given, else 0.1 s or
    the stride that keeps `MAX_RECORDS` records."""
    reason = "given"
    defaulted = record_every is None
    if record_every is None:
        record_every = max(1, int(round(RECORD_SECONDS / dt)))
        reason = f"default {RECORD_SECONDS:g} s"
        capped = math.ceil(n_steps / (MAX_RECORDS - 1))
        if capped > record_every:
            record_every = capped
            reason = (
                f"raised from {RECORD_SECONDS:g} s to keep at most {MAX_RECORDS} records per run"
            )
    if (
        isinstance(record_every, bool)
        or not isinstance(record_every, int | np.integer)
        or record_every < 1
    ):
        raise ParameterError(f"`record_every` must be an integer >= 1 step, got {record_every!r}.")
    if record_every > n_steps:
        if defaulted:  # the user gave no stride: the run is what is too short
            raise ParameterError(
                f"`duration` = {n_steps * dt:g} s is shorter than the default recording "
                f"interval ({record_every * dt:g} s, {plural(record_every, 'step')} of {dt!r} s); "
                f"lengthen `duration`, or give `record_every` <= {plural(n_steps, 'step')}."
            )
        raise ParameterError(
            f"`record_every` = {plural(record_every, 'step')} exceeds the "
            f"{plural(n_steps, 'step')} of the run; "
            f"lower it or lengthen `duration`."
        )
    return int(record_every), reason


def _request_size(n, runs, frequencies_bpm, metronomes, theta0, groups) -> tuple[int, int, int] | None:  # fmt: skip  # noqa: E501
    """(N, runs, groups) of a request, read without building anything; None when the
    inputs are malformed (`build_ensemble` then says what is wrong)."""
    try:
        if groups is not None:
            n = sum(operator.index(g.n if isinstance(g, Group) else g[0]) for g in groups)
        elif metronomes is not None:
            n = len(metronomes)
        elif frequencies_bpm is not None:
            n = np.shape(frequencies_bpm)[-1]
        elif theta0 is not None and n is None:
            n = np.shape(theta0)[-1]
        n, runs = operator.index(n), operator.index(runs)
    except (TypeError, IndexError):
        return None
    count = len(groups) if groups is not None else 1
    return (n, runs, count) if n >= 1 and runs >= 1 else None


def _run_fixed_step(ensemble, kernel, backend, dt, n_steps, record_every, n_records, trajectories,
                    overturn_angle, show, tail_steps, window_steps) -> tuple[Records, np.ndarray]:  # fmt: skip  # noqa: E501
    """Advance in paced chunks; the last ``tail_steps`` go in segments shorter than half
    the shortest period, to count ticks (`CrossingTally`), and the steps with the disk
    at rest are counted over the last ``window_steps`` (``rest_time``). Returns the
    records and the (B, N) tick rates."""
    state = StepState.start(
        ensemble.system, ensemble.theta0, ensemble.theta_dot0, ensemble.phi0, ensemble.phi_dot0,
        n_records=n_records, trajectories=trajectories, group_start=ensemble.group_start,
    )  # fmt: skip
    # Chunks sized from the measured throughput end every ~0.25 s, so that Ctrl-C and
    # the progress bar act promptly whatever the problem size (see `metrosync.pacing`).
    estimate = simulation_budget(
        n=ensemble.n, runs=ensemble.runs, steps=1, records=1, trajectories=False,
        backend="numpy" if backend == "numpy" else "numba",
    ).seconds  # fmt: skip
    per_segment = max(1, int(ensemble.shortest_period() / 2 / dt))
    head = n_steps - tail_steps
    with progress_bar(total=round(n_steps * dt, 6), unit="s", enabled=show) as bar:

        def advance(step: int, count: int) -> None:
            kernel.advance_state(
                state, ensemble.system, dt=dt, step0=step, n_steps=count,
                record_every=record_every, overturn_angle=overturn_angle,
            )  # fmt: skip
            bar.update(round(count * dt, 6))

        # The tail is within the window: the head is cut where the window starts.
        window_start = min(n_steps - window_steps, head)
        for first, stop in ((0, window_start), (window_start, head)):
            if first == window_start:
                rest_before = state.rest_steps.copy()
            for step, count in Pacer(stop - first, estimate):
                advance(first + step, count)
        tally = CrossingTally(state.last_up)
        for step, count in Pacer(tail_steps, estimate):
            for part in range(0, count, per_segment):
                advance(head + step + part, min(per_segment, count - part))
                tally.see(state.last_up)
    records = records_of(state)
    records.rest_time = (state.rest_steps - rest_before) * dt
    return records, tally.rate()


def _to_dataset(
    ensemble: Ensemble, rec: Records, rates: np.ndarray, grid_dt: float, window: float, settings
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
        "tick_rate_bpm": (
            ("run", "metronome"),
            rates,
            {
                "units": "BPM",
                "long_name": f"ticks per minute measured over the final "
                f"{settings['tick_rate_span']:g} s (NaN for a flagged run)",
            },
        ),
    }
    system = ensemble.system
    if np.any(rec.status & STATUS_STOPPED):  # say which metronomes died
        stopped = stopped_metronomes(rec.last_kick, settings["duration"], system.omega)
        data["escapement_stopped"] = (
            ("run", "metronome"),
            stopped & ((rec.status & STATUS_STOPPED) != 0)[:, None],
            {"long_name": "the escapement gave no impulse in the metronome's last "
             "two periods (metronome death; see metrosync.observables.death)"},
        )  # fmt: skip
    if np.any((system.dry_friction > 0) & ~np.isinf(system.total_inertia)):
        data["disk_at_rest"] = (
            ("run",),
            np.minimum(rec.rest_time / window, 1.0),
            {"units": "1", "long_name": "fraction of the final window with the disk held at "
             "rest by its dry friction"},
        )  # fmt: skip
    offset = system.escapement_offset
    if np.any(offset != 0):  # some metronome is out of beat: say which, and by how much
        data["escapement_offset"] = (
            ("run", "metronome"),
            np.array(offset, dtype=float),
            {"units": "rad", "long_name": "angle at which the escapement acts"},
        )
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
    coords = {
        "time": ("time", time, {"units": "s"}),
        "run": np.arange(ensemble.runs),
        "metronome": np.arange(ensemble.n),
    }
    if ensemble.groups:
        _add_groups(data, coords, attrs, ensemble, rec, time, window)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _add_groups(data, coords, attrs, ensemble: Ensemble, rec: Records, time, window) -> None:
    """Each group's order parameters and description (module docstring)."""
    groups = ensemble.groups
    r = rec.r_group.transpose(1, 0, 2)
    r_cross = rec.r_crossing_group.transpose(1, 0, 2)
    r_eq = equilibrium_order(r_cross, time, window)
    dims = ("time", "run", "group")
    data["r_group"] = (dims, r, {"long_name": "order parameter of each group (analytic phase)"})
    data["r_crossing_group"] = (
        dims,
        r_cross,
        {"long_name": "order parameter of each group (crossing-interpolated phase)"},
    )
    data["r_eq_group"] = (
        ("run", "group"),
        r_eq,
        {"long_name": "equilibrium r of each group (mean of r_crossing_group over final window)"},
    )
    data["r_eq_analytic_group"] = (
        ("run", "group"),
        equilibrium_order(r, time, window),
        {"long_name": "equilibrium r of each group from r_group"},
    )
    bounds = ensemble.group_start
    coords["group"] = (
        "metronome",
        np.repeat(np.arange(len(groups)), np.diff(bounds)),
        {"long_name": "group of each metronome (index along the group dimension)"},
    )
    coords["group_n"] = ("group", np.array([g.n for g in groups]), {"long_name": "metronomes"})
    coords["group_bpm"] = (
        "group",
        np.array([g.bpm for g in groups]),
        {"units": "BPM", "long_name": "nominal beat frequency of the group"},
    )
    coords["group_sigma_bpm"] = (
        "group",
        np.array([g.sigma_bpm for g in groups]),
        {"units": "BPM", "long_name": "spread (std) of the group's natural frequencies"},
    )
    stats = np.array([ensemble_statistics(r_eq[:, g]) for g in range(len(groups))])
    attrs.update(
        groups=describe_groups(groups),
        r_eq_group_mean=stats[:, 0],
        r_eq_group_std=stats[:, 1],
    )


def _flat_params(params: ModelParameters) -> dict:
    out = {}
    for key, value in params.as_dict().items():
        if isinstance(value, float) and math.isinf(value):
            value = "inf"
        out[key] = value
    return out

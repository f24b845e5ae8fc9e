"""The last stage of `metrosync.simulate`: a run's records as an `xarray.Dataset`:

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
                                          trajectories, only when asked for; phi and
                                          phi_dot (time, run, platform_coordinate) for
                                          a platform of more than one coordinate

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

import numpy as np
import xarray as xr

from .._version import __version__
from ..ensemble import Ensemble
from ..groups import describe_groups
from ..integrators._state import Records
from ..model import Metronome, MetronomeDesign, ModelParameters
from ..model.quantity import units
from ..observables.death import stopped_metronomes
from ..observables.order import ensemble_statistics, equilibrium_order
from ..status import STATUS_MEANINGS, STATUS_STOPPED
from .request import SimulationRequest
from .run import RunRecords


def to_dataset(request: SimulationRequest, ensemble: Ensemble, run: RunRecords) -> xr.Dataset:
    """The dataset of ``run``, the run of ``ensemble`` that ``request`` asked for."""
    rec, window = run.records, run.window
    time = np.arange(rec.r.shape[1]) * request.record_interval
    r = rec.r.T
    r_cross = rec.r_crossing.T
    r_eq = equilibrium_order(r_cross, time, window)
    r_eq_analytic = equilibrium_order(r, time, window)
    mean, spread = ensemble_statistics(r_eq)
    span = run.tail_steps * request.dt
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
            {"units": units(Metronome)["l2"], "long_name": "slider position L2"},
        ),
        "tick_rate_bpm": (
            ("run", "metronome"),
            run.rates,
            {
                "units": "BPM",
                "long_name": f"ticks per minute measured over the final "
                f"{span:g} s (NaN for a flagged run)",
            },
        ),
    }
    _add_when_present(data, ensemble, rec, window, request.simulated_time)
    attrs = {**_settings(request, ensemble, run), **_flat_params(ensemble.params)}
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


def _settings(request: SimulationRequest, ensemble: Ensemble, run: RunRecords) -> dict:
    """What was asked and what was used, for ``attrs``."""
    scheme = request.scheme
    explicit = (
        request.bpm is None or request.frequencies_bpm is not None or request.metronomes is not None
    )
    return {
        "n": ensemble.n,
        "bpm": "groups" if request.groups is not None else "explicit" if explicit else request.bpm,
        "sigma_bpm": request.sigma_bpm,
        "runs": ensemble.runs,
        "duration": request.simulated_time,
        "dt": request.dt,
        "seed": "none" if request.seed is None else request.seed,
        "integrator": request.integrator,
        "backend": request.backend if scheme.fixed_step else scheme.backends[0],
        "record_every": request.stride,
        "record_interval": request.record_interval,
        "record_every_reason": request.stride_reason,
        "equilibrium_window": run.window,
        "overturn_angle": request.overturn_angle,
        "tick_rate_span": run.tail_steps * request.dt,
    }


def _add_when_present(data, ensemble: Ensemble, rec: Records, window: float, duration) -> None:
    """The variables a run has only with some feature on: stopped escapements, a disk
    held by dry friction, escapements out of beat, trajectories (module docstring)."""
    system = ensemble.system
    if np.any(rec.status & STATUS_STOPPED):  # say which metronomes died
        stopped = stopped_metronomes(rec.last_kick, duration, system.omega)
        data["escapement_stopped"] = (
            ("run", "metronome"),
            stopped & ((rec.status & STATUS_STOPPED) != 0)[:, None],
            {
                "long_name": "the escapement gave no impulse in the metronome's last "
                "two periods (metronome death; see metrosync.observables.death)"
            },
        )
    if np.any((system.dry_friction > 0) & ~np.any(np.isinf(system.total_inertia), axis=(1, 2))):
        data["disk_at_rest"] = (
            ("run",),
            np.minimum(rec.rest_time / window, 1.0),
            {
                "units": "1",
                "long_name": f"fraction of the final window with the "
                f"{ensemble.params.platform.platform} held at rest by its dry friction",
            },
        )
    offset = system.escapement_offset
    if np.any(offset != 0):  # some metronome is out of beat: say which, and by how much
        data["escapement_offset"] = (
            ("run", "metronome"),
            np.array(offset, dtype=float),
            {
                "units": units(MetronomeDesign)["escapement_offset"],
                "long_name": "angle at which the escapement acts",
            },
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
        # φ is the platform's coordinate: the disk's angle, or the board's position.
        board = ensemble.params.platform.platform == "board"
        what, unit = ("board position", "m") if board else ("disk angle", "rad")
        # One coordinate: (time, run), as ever; more: a `platform_coordinate` axis.
        dims = ("time", "run") if rec.phi.ndim == 2 else ("time", "run", "platform_coordinate")
        order = (1, 0, 2)[: rec.phi.ndim]
        data["phi"] = (dims, rec.phi.transpose(order), {"units": unit, "long_name": what})
        data["phi_dot"] = (
            dims,
            rec.phi_dot.transpose(order),
            {"units": f"{unit}/s", "long_name": f"rate of the {what}"},
        )


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

"""The paper's §5 parameter estimation, run on simulated measurements of known truth.

Contract: `run_estimation(study, mode, workdir)`, for an `EstimationStudy`
(`metrosync.paper.studies`, whose ``run`` calls it), "measures" with the public
`metrosync.simulate` and the study's true parameters (its preset), then runs the
paper's procedure through `metrosync.calibration`, and returns one `xarray.Dataset`:

1. free decay of one metronome on a rigid support, drive off → c_θ, both from the
   trajectory's extrema and from a virtual light-gate log (the experiment's
   instrument; the log is written under ``workdir``);
2. steady amplitude of the driven metronome → M, solving the model with the c_θ just
   estimated from the log;
3. steady amplitude of the disk under ``n`` synchronized metronomes → c_φ, solving
   the model with the estimated c_θ and M, at the true c_φ and at a control value
   where the amplitude depends on c_φ; and once more at the true c_φ given the
   true c_θ and M, which isolates this step from the errors of the first two.

`metrosync.calibration.fit_c_phi` refuses (`CalibrationError`) when the disk's
amplitude does not identify c_φ; the refusal is recorded, never hidden. The
disk amplitude over the study's c_φ scan (with the true c_θ and M) shows why.

Dataset: ``true``, ``estimate`` (NaN when refused), ``relative_error``,
``recovered`` and ``outcome`` (the estimate's summary or the refusal) along
``parameter``; the fitted data of each step (``decay_*``, ``gate_*``, ``drive_*``)
for the figure; ``disk_amplitude`` and ``sensitivity`` (d ln A / d ln c_φ) along
``c_phi``; the measured amplitudes and run lengths in ``attrs``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from ..calibration import (
    Estimate,
    c_theta_from_log,
    c_theta_from_trajectory,
    disk_amplitude,
    fit_c_phi,
    fit_drive,
)
from ..calibration.pendulum import swing_amplitudes
from ..errors import CalibrationError
from ..lightgate import LightGate, write_logs
from ..model import get_preset
from ..simulate import simulate

#: The parameters the procedure estimates, in report order: (coordinate, true value key).
PARAMETERS = (
    ("c_theta (trajectory)", "c_theta"),
    ("c_theta (light gate)", "c_theta"),
    ("M", "drive"),
    ("c_phi (published)", "c_phi"),
    ("c_phi (published, true c_theta and M)", "c_phi"),
    ("c_phi (control)", "c_phi_control"),
)
UNITS = {"c_theta": "kg m2/s", "drive": "N m s", "c_phi": "kg m2/s", "c_phi_control": "kg m2/s"}


def run_estimation(study, mode: str, workdir: Path) -> xr.Dataset:
    """Simulate the measurements, run the §5 procedure, and collect what it found."""
    grid = study.grid(mode)
    params = get_preset(study.preset)
    truth = {
        "c_theta": params.metronome.c_theta,
        "drive": params.metronome.drive,
        "c_phi": params.platform.c_phi,
        "c_phi_control": study.c_phi_control,
    }
    metronome = params.metronome.with_l2(params.metronome.l2_for_bpm(study.bpm))
    rigid = {"inertia": math.inf}

    decay = _trajectory(study, grid.decay_duration, {**rigid, "drive": 0.0}, study.decay_theta0)
    by_trajectory = c_theta_from_trajectory(
        decay.time.values, decay.theta.values[:, 0, 0], metronome=metronome
    )
    gate = LightGate(offset=study.gate_offset, width=study.gate_width)
    log = write_logs(decay, Path(workdir), gate, prefix="free_decay")[0]
    by_gate = c_theta_from_log(log, offset=study.gate_offset, metronome=metronome)

    steady = _trajectory(study, grid.steady_duration, rigid, study.steady_theta0)
    t, theta = steady.time.values, steady.theta.values[:, 0, 0]
    tail = t >= 0.75 * t[-1]
    amplitude = float(np.mean(swing_amplitudes(t[tail], theta[tail])[1]))
    drive = fit_drive(amplitude, c_theta=by_gate.value, bpm=study.bpm, preset=study.preset)

    disk = {"n": study.n, "bpm": study.bpm, "preset": study.preset, "duration": grid.disk_duration}
    scan = np.asarray(grid.c_phi_scan, dtype=float)
    curve = np.array(
        [disk_amplitude(c, c_theta=truth["c_theta"], drive=truth["drive"], **disk) for c in scan]
    )
    measured = {
        key: disk_amplitude(truth[key], c_theta=truth["c_theta"], drive=truth["drive"], **disk)
        for key in ("c_phi", "c_phi_control")
    }
    fits = [
        (measured["c_phi"], by_gate.value, drive.value),
        (measured["c_phi"], truth["c_theta"], truth["drive"]),
        (measured["c_phi_control"], by_gate.value, drive.value),
    ]
    found = [by_trajectory, by_gate, drive] + [
        _try_fit_c_phi(a, study, c_theta, m, scan=scan.size, **disk) for a, c_theta, m in fits
    ]
    names = [name for name, _ in PARAMETERS]
    true = np.array([truth[key] for _, key in PARAMETERS])
    estimate = np.array([f.value if isinstance(f, Estimate) else np.nan for f in found])
    error = estimate / true - 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        sensitivity = np.gradient(np.log(curve), np.log(scan))
    return xr.Dataset(
        {
            "true": ("parameter", true),
            "estimate": ("parameter", estimate, {"long_name": "estimate (NaN: refused)"}),
            "relative_error": ("parameter", error),
            "recovered": ("parameter", np.abs(error) <= study.tolerance),
            "unit": ("parameter", [UNITS[key] for _, key in PARAMETERS]),
            "outcome": (
                "parameter",
                [f.summary() if isinstance(f, Estimate) else f for f in found],
            ),
            **_fit_data("decay", by_trajectory),
            **_fit_data("gate", by_gate),
            **_fit_data("drive", drive),
            "disk_amplitude": (
                "c_phi",
                curve,
                {"units": "rad", "long_name": "steady disk amplitude, true c_θ and M"},
            ),
            "sensitivity": ("c_phi", sensitivity, {"long_name": "d ln A / d ln c_φ"}),
        },
        coords={"parameter": names, "c_phi": ("c_phi", scan, {"units": "kg m2/s"})},
        attrs={
            "preset": study.preset,
            "bpm": study.bpm,
            "n": study.n,
            "tolerance": study.tolerance,
            "steady_amplitude_measured": amplitude,
            "disk_amplitude_measured": measured["c_phi"],
            "disk_amplitude_measured_control": measured["c_phi_control"],
            "c_phi_bracket": list(study.c_phi_bracket),
            "decay_duration": grid.decay_duration,
            "steady_duration": grid.steady_duration,
            "disk_duration": grid.disk_duration,
            "gate_offset": study.gate_offset,
        },
    )


def _trajectory(study, duration: float, changes: dict, theta0: float):
    """One metronome of the study's preset, every step recorded."""
    return simulate(1, study.bpm, duration=duration, preset=study.preset, changes=changes,
                    theta0=[theta0], theta_dot0=[0.0], record_every=1, trajectories=True,
                    progress=False)  # fmt: skip


def _try_fit_c_phi(amplitude, study, c_theta, drive, **model) -> Estimate | str:
    """`fit_c_phi`'s estimate, or the text of its refusal."""
    try:
        return fit_c_phi(amplitude, c_theta=c_theta, drive=drive, bracket=study.c_phi_bracket,
                         **model)  # fmt: skip
    except CalibrationError as refusal:
        return f"refused: {refusal}"


def _fit_data(prefix: str, est: Estimate) -> dict:
    """An estimate's data and fitted curve, as variables on their own dimensions."""
    return {
        f"{prefix}_x": (f"{prefix}_point", est.x, {"long_name": est.xlabel}),
        f"{prefix}_y": (f"{prefix}_point", est.y, {"long_name": est.ylabel}),
        f"{prefix}_fit_x": (f"{prefix}_fit", est.fit_x),
        f"{prefix}_fit_y": (f"{prefix}_fit", est.fit_y),
    }

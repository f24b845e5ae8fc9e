"""M from a measured steady amplitude, by solving the model (paper §5).

Contract: `fit_drive` finds the escapement impulse M for which one metronome on a
rigid support, with the given c_θ, settles at the measured amplitude. The model is
solved by `simulate` (n = 1, ``inertia = inf``); the steady amplitude is the mean
swing amplitude (`swing_amplitudes`) over the last quarter of the run. The steady
amplitude grows monotonically with M, so a bracketing root finder (Brent, on log M)
converges; the bracket starts at the energy-balance value M ≈ π c_θ A / 2.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.optimize import brentq

from ..errors import CalibrationError, OverturnWarning, ParameterError
from ..model import MetronomeDesign, balance_amplitude
from ..model.quantity import declared
from ..simulate import simulate
from .estimate import Estimate
from .pendulum import swing_amplitudes


def simulated_steady_amplitude(drive: float, *, c_theta: float, bpm: float = 192.0,
                               preset="default", changes=None, duration: float = 40.0,
                               dt: float = 0.01, integrator: str = "verlet") -> float:  # fmt: skip
    """Mean swing amplitude (rad) over the last quarter of a driven single-metronome run:
    the steady amplitude as `simulate` gives it (the closed-form estimate is
    `metrosync.model.balance_amplitude`, the exact one `metrosync.model.steady_swing`)."""
    params = {
        **(changes or {}),
        "drive": float(drive),
        "c_theta": float(c_theta),
        "inertia": math.inf,
    }
    start = min(max(balance_amplitude(drive, c_theta), 0.05), 1.2) if c_theta > 0 else 0.5
    with warnings.catch_warnings():
        # Trial values of M may overturn: the root finder only needs their amplitude.
        warnings.simplefilter("ignore", OverturnWarning)
        ds = simulate(1, bpm, duration=duration, dt=dt, preset=preset, changes=params,
                      theta0=[start], theta_dot0=[0.0], record_every=1, trajectories=True,
                      integrator=integrator, progress=False, overturn_angle=math.pi)  # fmt: skip
    t = ds.time.values
    th = ds.theta.values[:, 0, 0]
    tail = t >= 0.75 * t[-1]
    _, amp = swing_amplitudes(t[tail], th[tail])
    return float(np.mean(amp)) if amp.size else float("nan")


def fit_drive(amplitude: float, *, c_theta: float, bpm: float = 192.0, preset="default",
              changes=None, duration: float = 40.0, dt: float = 0.01,
              integrator: str = "verlet", rtol: float = 1e-5) -> Estimate:  # fmt: skip
    """M (N m s) such that the steady amplitude equals ``amplitude`` (rad)."""
    if not (math.isfinite(amplitude) and 0 < amplitude < math.pi / 2):
        raise ParameterError(f"`amplitude` must be in (0, π/2) rad, got {amplitude!r}.")
    if not (math.isfinite(c_theta) and c_theta > 0):
        raise ParameterError(f"`c_theta` must be > 0 kg m²/s (estimate it first), got {c_theta!r}.")
    kw = dict(c_theta=c_theta, bpm=bpm, preset=preset, changes=changes, duration=duration, dt=dt,
              integrator=integrator)  # fmt: skip
    trials: dict[float, float] = {}

    def excess(log_m: float) -> float:
        value = simulated_steady_amplitude(math.exp(log_m), **kw)
        trials[math.exp(log_m)] = value
        return value - amplitude

    guess = math.log(math.pi * c_theta * amplitude / 2)
    lo, hi = guess - 0.7, guess + 0.7
    for _ in range(8):
        f_lo, f_hi = excess(lo), excess(hi)
        if f_lo < 0 < f_hi:
            break
        lo, hi = (lo - 1.0, hi) if f_lo >= 0 else (lo, hi + 1.0)
    else:
        raise CalibrationError(
            f"no drive M in [{math.exp(lo):.3g}, {math.exp(hi):.3g}] N m s gives a steady "
            f"amplitude of {amplitude} rad with c_theta = {c_theta}."
        )
    log_m = brentq(excess, lo, hi, rtol=rtol)
    value = math.exp(log_m)
    ms = np.array(sorted(trials))
    return Estimate(
        name="M", value=value, unit=declared(MetronomeDesign, "drive"),
        x=ms, y=np.array([trials[m] for m in ms]),
        fit_x=np.array([ms.min(), ms.max()]), fit_y=np.array([amplitude, amplitude]),
        xlabel="M (N m s)", ylabel="steady amplitude (rad)",
        title=f"M from the steady amplitude ({bpm} BPM, rigid support)",
        details={"energy_balance": math.pi * c_theta * amplitude / 2, "model_runs": len(trials)},
    )  # fmt: skip

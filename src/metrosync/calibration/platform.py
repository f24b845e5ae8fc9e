"""c_φ from the platform's steady oscillation once the metronomes are in sync (paper §5).

Contract: `fit_c_phi` finds the disk friction c_φ for which N identical metronomes,
started in phase on the free disk with the given c_θ and M, make the disk oscillate
with the measured amplitude. The disk amplitude is half the peak-to-peak of φ(t)
over the last half of the run, after removing its linear drift.

Identifiability: the disk's swing is set mostly by its inertia; it depends on c_φ
only once c_φ is comparable with J ω (about 1–10 kg m²/s here). At the published
c_φ = 1e-5 the amplitude changes by < 0.1 % over five decades of c_φ, so no amount
of tuning can recover it from the amplitude. `fit_c_phi` scans the bracket and
refuses (`CalibrationError`) when the solution is not unique or when the amplitude
hardly depends on c_φ. With s = d ln A / d ln c_φ, a relative error ε in the measured
amplitude (or in the model's c_θ and M, which shift the modelled amplitude alike)
becomes a relative error ε/|s| in c_φ; below ``min_sensitivity`` = 0.1, a 1 % error
would already move c_φ by more than 10 %. (At 0.02, estimated c_θ and M 2 % off the
truth once made a published-value run return c_φ 3700 times too large.) The estimate
reports 1/|s| as ``details["error_gain"]``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..errors import CalibrationError, ParameterError
from ..model import Platform
from ..model.quantity import declared
from ..simulate import simulate
from .estimate import Estimate


def disk_amplitude(c_phi: float, *, n: int = 7, bpm: float = 192.0, c_theta: float, drive: float,
                   preset="default", changes=None, amplitude: float = 0.7,
                   duration: float = 30.0, dt: float = 0.01) -> float:  # fmt: skip
    """Steady half peak-to-peak of the disk angle (rad), metronomes started in phase."""
    params = {**(changes or {}), "c_phi": float(c_phi), "c_theta": c_theta, "drive": drive}
    ds = simulate(n, bpm, duration=duration, dt=dt, preset=preset, changes=params,
                  theta0=[amplitude] * n, theta_dot0=[0.0] * n, record_every=1,
                  trajectories=True, progress=False)  # fmt: skip
    if int(ds.status[0]) != 0:
        return float("nan")
    t = ds.time.values
    phi = ds.phi.values[:, 0]
    tail = t >= 0.5 * t[-1]
    resid = phi[tail] - np.polyval(np.polyfit(t[tail], phi[tail], 1), t[tail])
    return float((resid.max() - resid.min()) / 2)


def fit_c_phi(amplitude: float, *, n: int = 7, bpm: float = 192.0, c_theta: float, drive: float,
              bracket: tuple[float, float] = (1e-3, 10.0), scan: int = 9,
              min_sensitivity: float = 0.1, rtol: float = 1e-5, **model) -> Estimate:  # fmt: skip
    """c_φ (kg m²/s) such that the synchronized disk swings with ``amplitude`` (rad)."""
    if not (math.isfinite(amplitude) and amplitude > 0):
        raise ParameterError(f"`amplitude` must be a disk amplitude > 0 rad, got {amplitude!r}.")
    lo, hi = bracket
    if not (0 < lo < hi and math.isfinite(hi)):
        raise ParameterError(f"`bracket` must satisfy 0 < low < high, got {bracket!r}.")
    kw = dict(n=n, bpm=bpm, c_theta=c_theta, drive=drive, **model)
    grid = np.geomspace(lo, hi, scan)
    values = np.array([disk_amplitude(c, **kw) for c in grid])
    diff = values - amplitude
    finite = np.isfinite(diff)
    change = np.flatnonzero(finite[:-1] & finite[1:] & (np.sign(diff[:-1]) != np.sign(diff[1:])))
    if change.size == 0:
        raise CalibrationError(
            f"no c_phi in [{lo:g}, {hi:g}] kg m²/s gives a disk amplitude of {amplitude:.4g} rad: "
            f"the model gives {np.nanmin(values):.4g} .. {np.nanmax(values):.4g} rad there."
        )
    if change.size > 1:
        roots = ", ".join(f"{grid[i]:.3g}..{grid[i + 1]:.3g}" for i in change)
        raise CalibrationError(
            f"the disk amplitude {amplitude:.4g} rad is reached for several c_phi ({roots} "
            f"kg m²/s): c_phi is not identifiable from the amplitude here; narrow `bracket`."
        )
    i = int(change[0])
    log_c = brentq(lambda x: disk_amplitude(math.exp(x), **kw) - amplitude,
                   math.log(grid[i]), math.log(grid[i + 1]), rtol=rtol)  # fmt: skip
    value = math.exp(log_c)
    step = 0.05
    up, down = (disk_amplitude(value * math.exp(s), **kw) for s in (step, -step))
    sensitivity = (math.log(up) - math.log(down)) / (2 * step)
    if abs(sensitivity) < min_sensitivity:
        raise CalibrationError(
            f"the disk amplitude hardly depends on c_phi near {value:.3g} kg m²/s "
            f"(d ln A / d ln c_phi = {sensitivity:.3g}, so a 1 % amplitude error moves c_phi "
            f"by {1 / max(abs(sensitivity), 1e-12):.3g} %); it cannot be estimated this way."
        )
    return Estimate(
        name="c_phi", value=value, unit=declared(Platform, "c_phi"),
        x=grid, y=values, fit_x=np.array([grid[0], grid[-1]]), fit_y=np.array([amplitude] * 2),
        xlabel=r"$c_\varphi$ (kg m²/s)", ylabel="disk amplitude (rad)",
        title=rf"$c_\varphi$ from the synchronized disk's amplitude (N = {n}, {bpm} BPM)",
        details={"sensitivity": float(sensitivity), "error_gain": 1.0 / abs(sensitivity)},
    )  # fmt: skip

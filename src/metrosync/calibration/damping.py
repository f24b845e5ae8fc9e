"""c_θ from the free decay of one metronome with the drive off (paper §5).

Contract: `fit_c_theta` fits the swing amplitudes A_k at times t_k of a free decay
on a rigid support. With u(A) the envelope coordinate of `pendulum`, energy
balance makes u(A(t)) = u(A0) − c_θ t / (2I) exactly in A (averaged over a swing),
so a least-squares line through (t_k, u(A_k)) gives c_θ = −2 I × slope, with I the
metronome's inertia m h² + J_i. The amplitudes come from

* a trajectory θ(t) (`c_theta_from_trajectory`): its extrema, or
* a light-gate log (`c_theta_from_log`): for a gate at angle δ > 0, the fraction
  s/T of each period spent beyond the gate fixes the amplitude of that swing,
  timed at its turning point (the middle of the short interval).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import CalibrationError
from ..lightgate.cleaning import clean_log
from ..lightgate.reader import DEFAULT_TICK, read_log
from ..model import Metronome, MetronomeDesign
from ..model.quantity import declared
from .estimate import Estimate
from .pendulum import amplitude_from_ratio, envelope_coordinate, swing_amplitudes


def fit_c_theta(time, amplitude, *, metronome: Metronome, min_amplitude: float = 0.02) -> Estimate:
    """c_θ (kg m²/s) from amplitudes (rad) at times (s) of a free decay.

    time, amplitude : (K,) with K >= 3 amplitudes above ``min_amplitude``.
    """
    t = np.asarray(time, dtype=float)
    a = np.asarray(amplitude, dtype=float)
    ok = np.isfinite(t) & np.isfinite(a) & (a > min_amplitude) & (a < np.pi)
    t, a = t[ok], a[ok]
    if t.size < 3:
        raise CalibrationError(
            f"a free-decay fit needs at least 3 amplitudes above {min_amplitude} rad, got "
            f"{t.size}; record a longer decay or start it from a larger swing."
        )
    u = envelope_coordinate(a)
    (slope, intercept), cov = (
        np.polyfit(t, u, 1, cov=True)
        if t.size > 3
        else (np.polyfit(t, u, 1), np.full((2, 2), np.nan))
    )
    if not slope < 0:
        raise CalibrationError(
            f"the amplitudes do not decay (slope {slope:.3g} /s); is the drive off?"
        )
    inertia = metronome.inertia
    value = -2.0 * inertia * slope
    fit_t = np.linspace(t.min(), t.max(), 100)
    return Estimate(
        name="c_theta", value=float(value), unit=declared(MetronomeDesign, "c_theta"),
        x=t, y=u, fit_x=fit_t, fit_y=intercept + slope * fit_t,
        xlabel="t (s)", ylabel="log swing amplitude: u(A) ≈ ln(A / rad)",
        title=r"$c_\theta$ from the free decay (drive off, rigid support)",
        details={"stderr": float(2 * inertia * np.sqrt(cov[0, 0])), "amplitudes": int(t.size),
                 "inertia": float(inertia)},
    )  # fmt: skip


def c_theta_from_trajectory(time, theta, *, metronome: Metronome, **options) -> Estimate:
    """c_θ from a sampled free decay θ(t): time, theta (T,)."""
    t_peak, amp = swing_amplitudes(time, theta)
    return fit_c_theta(t_peak, amp, metronome=metronome, **options)


def decay_amplitudes_from_log(path: str | Path, *, offset: float, channel: int = 0,
                              tick: float = DEFAULT_TICK, **read_options):  # fmt: skip
    """(times, amplitudes) of a free decay recorded by a gate at ``offset`` rad (> 0).

    Each kept pass opens a short interval s (bob beyond the gate) closed by the next
    second pass; with the period T to the next kept pass, s/T gives the amplitude.
    """
    log = read_log(path, tick=tick, **read_options)
    if not 0 <= channel < log.channels:
        raise CalibrationError(
            f"`channel` {channel} is not a gate of {path} (0..{log.channels - 1})."
        )
    passes = clean_log(log)[channel]
    kept, second = passes.kept, passes.second
    times, ratios = [], []
    for j in range(kept.size - 1):
        if passes.cycles[j] != 1:
            continue
        inside = second[(second > kept[j]) & (second < kept[j + 1])]
        if inside.size != 1:
            continue
        s = inside[0] - kept[j]
        times.append(kept[j] + s / 2)
        ratios.append(s / (kept[j + 1] - kept[j]))
    return np.array(times), amplitude_from_ratio(np.array(ratios), offset)


def c_theta_from_log(path: str | Path, *, offset: float, metronome: Metronome, channel: int = 0,
                     tick: float = DEFAULT_TICK, **options) -> Estimate:  # fmt: skip
    """c_θ from a light-gate log of a free decay (gate at ``offset`` rad > 0)."""
    t, a = decay_amplitudes_from_log(path, offset=offset, channel=channel, tick=tick)
    return fit_c_theta(t, a, metronome=metronome, **options)

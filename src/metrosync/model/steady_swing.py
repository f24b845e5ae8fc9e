"""The steady swing of one metronome on a rigid support, and the slider position at which
it *ticks* at its marking (the ``"steady-swing"`` tuning of `metrosync.model.tuning`).

Single-pendulum mechanics: nothing here runs the ensemble simulator.

A metronome's marking is its actual tick rate, two ticks per period. The model's
default tuning (``"small-amplitude"``) inverts the *small-amplitude*
frequency ω₀² = m g h / (m h² + J_i); at the steady swing of ≈ 0.77 rad the pendulum
is slower, so a metronome tuned to "192 BPM" that way ticks about 184.7 times a
minute. This module finds instead the ``L2`` whose tick rate *at the steady swing*
equals the nominal BPM.

The steady swing, exactly for the continuous-time model on a rigid support
-------------------------------------------------------------------------
Between two zero crossings the pendulum obeys I θ̈ = −m g h sin θ − c_θ θ̇
(eq. (metron2) with φ̈ = 0), and at each crossing the escapement adds angular
momentum M in the direction of motion (eq. (excitation)). In the time τ = ω₀ t this is

    θ'' + sin θ + γ θ' = 0,   γ = c_θ / (I ω₀),   a kick Δθ' = κ = M / (I ω₀),

so a half swing maps the speed just after a kick, u₊, to the speed u₋ with which
the pendulum comes back to θ = 0. The steady swing is the fixed point
u₊ = u₋(u₊) + κ, found with Brent's method on an 8th-order Dormand–Prince solution
of the half swing; its tick interval is the duration of that half swing. Nothing is
linearised: friction, the kick's speed jump (≈ 14 % at the default drive) and the
pendulum's anharmonicity are all in. This agrees with the model's reference
integrator (``integrator="exact"``) to 10⁻³ BPM.

The first-order (small γ) approximation, `energy_balance_swing`, balances the energy
a kick gives, M·θ̇(0) = 2 M ω₀ k, against friction over a conservative half swing,
4 c_θ ω₀ [E(k) − (1 − k²) K(k)], with k = sin(A/2) and K, E the complete elliptic
integrals; the tick rate is then 30 ω₀ / K(k) BPM. It ignores the speed jump and
runs ≈ 0.2 BPM fast at the default drive, more than the 0.1 BPM this tuning must hit,
which is why the exact half-swing map is the solver.

Both describe the continuous model. The paper's fixed-step scheme (Verlet, dt =
0.01 s, the kick spread over one step) ticks ≈ 0.13 BPM slower near 192 BPM, and its
tick period can lock to a whole number of steps; `tick_rate_bpm` is therefore checked
against simulations at a small step.

Contract: `steady_swing_l2(design, bpm)` is the tuning, vectorised like
`MetronomeDesign.l2_for_bpm`; it is computed once per design (a spline of the
ratio of tick rate to small-amplitude rate against ``L2``, inverted by iteration)
and cached in memory. `metrosync.model.tuning` picks a tuning by name.
Throughout, ``design`` is a `MetronomeDesign` and ``metronome`` a `Metronome` (this
module does not import theirs, which loads this one on use).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from ..errors import ParameterError, shown_range

#: Slider positions in the per-design table of the tick-rate ratio (interpolation
#: error below 1e-4 BPM, checked in the tests).
TABLE_POINTS = 33
#: Rounds of the fixed-point inversion (it converges in about ten).
MAX_ROUNDS = 60
_RTOL = 1e-11
_ATOL = 1e-13


@dataclass(frozen=True)
class SteadySwing:
    """The steady swing of one metronome on a rigid support.

    amplitude : turning angle of the steady swing, rad.
    tick_bpm : ticks per minute (two per period) at the steady swing.
    speed_after_kick, speed_before_kick : θ̇ at θ = 0 just after and before a kick, rad/s.
    small_amplitude_bpm : the small-amplitude rate of the same metronome, BPM.
    """

    amplitude: float
    tick_bpm: float
    speed_after_kick: float
    speed_before_kick: float
    small_amplitude_bpm: float


def _check_swing(design) -> None:
    if design.drive <= 0 or design.c_theta <= 0:
        raise ParameterError(
            f"steady-swing tuning needs both friction and drive (`c_theta` = {design.c_theta!r}, "
            f"`drive` = {design.drive!r}): without them there is no steady swing. Use "
            f"tuning='small-amplitude'."
        )


def _half_swing(u_plus: float, gamma: float) -> tuple[float, float, float]:
    """One half swing in τ = ω₀ t from θ = 0 at speed ``u_plus``.

    Returns (duration, speed back at θ = 0, turning angle); duration is inf when the
    pendulum goes over the top instead of coming back.
    """

    def rhs(_t, y):
        return (y[1], -math.sin(y[0]) - gamma * y[1])

    def back(_t, y):
        return y[0]

    back.terminal, back.direction = True, -1

    def over(_t, y):
        return y[0] - math.pi

    over.terminal, over.direction = True, 1

    def turn(_t, y):
        return y[1]

    turn.direction = -1
    sol = solve_ivp(
        rhs,
        (0.0, 200.0),
        (0.0, u_plus),
        method="DOP853",
        rtol=_RTOL,
        atol=_ATOL,
        events=(back, over, turn),
    )
    if sol.t_events[0].size == 0:
        return math.inf, 0.0, math.pi
    return float(sol.t_events[0][0]), float(-sol.y_events[0][0][1]), float(sol.y_events[2][0][0])


def _overturns(design, metronome) -> ParameterError:
    return ParameterError(
        f"the steady swing does not exist: with `drive` = {design.drive!r} N m s and "
        f"`c_theta` = {design.c_theta!r} kg m²/s the escapement drives the pendulum "
        f"(L2 = {metronome.l2:.4g} m) over the top (energy-balance amplitude "
        f"{metronome.balance_amplitude:.2f} rad). Lower `drive` or raise `c_theta`, or use "
        f"tuning='small-amplitude'."
    )


def steady_swing(metronome) -> SteadySwing:
    """The exact steady swing of ``metronome`` on a rigid support (see module docstring)."""
    design = metronome.design
    _check_swing(design)
    omega0 = metronome.natural_omega
    gamma = design.c_theta / (metronome.inertia * omega0)
    kappa = design.drive / (metronome.inertia * omega0)
    if kappa >= 2.0:
        raise _overturns(design, metronome)

    def excess(u_plus: float) -> float:
        duration, u_minus, _ = _half_swing(u_plus, gamma)
        return -1.0 if math.isinf(duration) else u_plus - kappa - u_minus

    # Speeds at θ = 0 run up to 2 (the separatrix); bracket the fixed point around
    # the first-order guess, falling back to the whole range.
    guess = 2.0 * math.sin(energy_balance_swing(metronome).amplitude / 2) + kappa / 2
    lo, hi = max(kappa, 0.95 * guess), min(2.0 - 1e-9, 1.05 * guess)
    if not (excess(lo) < 0 < excess(hi)):
        lo, hi = kappa, 2.0 - 1e-9
        if excess(hi) <= 0:
            raise _overturns(design, metronome)
    u_plus = brentq(excess, lo, hi, xtol=1e-13, rtol=1e-13)
    duration, u_minus, amplitude = _half_swing(u_plus, gamma)
    return SteadySwing(
        amplitude=amplitude,
        tick_bpm=60.0 * omega0 / duration,
        speed_after_kick=u_plus * omega0,
        speed_before_kick=u_minus * omega0,
        small_amplitude_bpm=metronome.natural_bpm,
    )


def relaxation_rate(metronome) -> float:
    """Rate (1/s) at which the swing amplitude returns to the steady swing.

    The Floquet exponent of the half-swing map at its fixed point: a change δu₊ of the
    speed after a kick comes back as (du₋/du₊) δu₊ half a period later, so the rate is
    −ln(du₋/du₊) / (half period). For small swings it is c_θ / (2I).
    """
    swing = steady_swing(metronome)
    omega0 = metronome.natural_omega
    gamma = metronome.design.c_theta / (metronome.inertia * omega0)
    u = swing.speed_after_kick / omega0
    h = 1e-6 * u
    back = [_half_swing(u + sign * h, gamma)[1] for sign in (-1.0, 1.0)]
    multiplier = (back[1] - back[0]) / (2 * h)
    return -math.log(multiplier) * swing.tick_bpm / 60.0


def energy_balance_swing(metronome) -> SteadySwing:
    """First-order steady swing: elliptic-integral energy balance and period.

    Solves M k = 4 c_θ [E(k) − (1 − k²) K(k)] for k = sin(A/2) (independent of L2)
    and returns the conservative tick rate 30 ω₀ / K(k) at that amplitude. Accurate
    to O(c_θ, M); see the module docstring for its size.
    """
    design = metronome.design
    _check_swing(design)
    ratio = design.drive / design.c_theta

    def balance(k: float) -> float:
        m = k * k
        return ratio * k - 4.0 * (ellipe(m) - (1.0 - m) * ellipk(m))

    # balance > 0 for small k, and → ratio − 4 at k → 1: no root means over the top.
    if ratio >= 4.0:
        raise _overturns(design, metronome)
    k = brentq(balance, 1e-12, 1.0 - 1e-15, xtol=1e-15)
    omega0 = metronome.natural_omega
    speed = 2.0 * omega0 * k
    return SteadySwing(
        amplitude=2.0 * math.asin(k),
        tick_bpm=30.0 * omega0 / float(ellipk(k * k)),
        speed_after_kick=speed,
        speed_before_kick=speed,
        small_amplitude_bpm=metronome.natural_bpm,
    )


def tick_rate_bpm(design, l2, *, exact: bool = True):
    """Tick rate (BPM) at the steady swing of ``design`` with slider at ``l2`` (m).

    Scalars give a float, arrays an array of the same shape. ``exact`` solves each
    swing (tens of ms apiece); otherwise the per-design table is interpolated (to
    ~1e-7 BPM, for many metronomes at once).
    """
    if not exact:
        l2_arr = np.asarray(l2, dtype=float)
        natural = np.sqrt(_natural_omega_sq(design, l2_arr)) * 60.0 / math.pi
        out = _table(design).ratio(l2_arr) * natural
        return out if out.ndim else float(out)
    l2_arr = np.asarray(l2, dtype=float)
    out = np.array([steady_swing(design.with_l2(float(x))).tick_bpm for x in l2_arr.flat])
    out = out.reshape(l2_arr.shape)
    return out if out.ndim else float(out)


def _natural_omega_sq(design, l2):
    m = design.mass
    h = (design.w1 * design.l1 - design.w2 * l2) / m
    return m * design.g * h / (m * h * h + design.w1 * design.l1**2 + design.w2 * l2 * l2)


@dataclass(frozen=True)
class _Table:
    """Per design: the ratio ρ(L2) = tick rate / small-amplitude rate, and its spline."""

    l2: np.ndarray
    tick_bpm: np.ndarray
    ratio: CubicSpline


def _table(design) -> _Table:
    # One table per physical design: the `tuning` field does not change the swing.
    return _design_table(replace(design, tuning="small-amplitude"))


@functools.lru_cache(maxsize=32)
def _design_table(design) -> _Table:
    lo, hi = design.l2_bounds
    # Chebyshev–Lobatto nodes: the ends (the tunable range) are exact, and the spline
    # of the slowly varying ratio stays accurate near them.
    l2 = lo + (hi - lo) * (1 - np.cos(np.linspace(0.0, np.pi, TABLE_POINTS))) / 2
    ticks = np.asarray(tick_rate_bpm(design, l2))
    natural = np.array([design.with_l2(x).natural_bpm for x in l2])
    return _Table(l2=l2, tick_bpm=ticks, ratio=CubicSpline(l2, ticks / natural))


def steady_swing_bpm_range(design) -> tuple[float, float]:
    """Lowest and highest tick rate (BPM) the slider reaches at the steady swing."""
    _check_swing(design)
    ticks = _table(design).tick_bpm
    return float(ticks[-1]), float(ticks[0])


def steady_swing_spline(design) -> dict:
    """The per-design spline of `steady_swing_l2`, for a twin in another language: its
    ``knots`` (L2, m), the ``coefficients`` [c3, c2, c1, c0] of each piece in powers of
    (L2 − knot), the ``natural_range`` (BPM) the iteration clips to, its
    ``max_rounds``, and the ``drive`` and ``c_theta`` it was made for; the iteration is
    `steady_swing_l2`'s."""
    _check_swing(design)
    ratio = _table(design).ratio
    return {
        "knots": ratio.x.tolist(),
        "coefficients": ratio.c.T.tolist(),
        "natural_range": list(design.small_amplitude_range()),
        "max_rounds": MAX_ROUNDS,
        "drive": design.drive,
        "c_theta": design.c_theta,
    }


def steady_swing_l2(design, bpm):
    """Slider position ``L2`` (m) at which ``design`` ticks at ``bpm`` at its steady swing.

    The steady-swing counterpart of `MetronomeDesign.small_amplitude_l2` (what
    `MetronomeDesign.l2_for_bpm` calls for ``tuning="steady-swing"``): scalars or arrays;
    raises `ParameterError` for a BPM outside `steady_swing_bpm_range` or a design
    without a steady swing. The first call for a design builds its table (about two
    seconds); later calls cost a few closed-form small-amplitude inversions.
    """
    bpm_arr = np.asarray(bpm, dtype=float)
    if not np.all(np.isfinite(bpm_arr)):
        raise ParameterError(f"`bpm` must be finite, got {bpm!r}.")
    low, high = steady_swing_bpm_range(design)
    bad = (bpm_arr < low) | (bpm_arr > high)
    if np.any(bad):
        shown, low_text, high_text = shown_range(low, high, float(bpm_arr[bad].flat[0]))
        raise ParameterError(
            f"`bpm` = {shown} is outside the steady-swing tunable range [{low_text}, "
            f"{high_text}] BPM of this metronome design (slider L2 in {design.l2_bounds} m). "
            f"Choose a BPM in range, or widen `l2_bounds`."
        )
    table = _table(design)
    lo, hi = design.l2_bounds
    # Tick rate = ρ(L2) × small-amplitude rate(L2), with ρ ≈ 0.96 varying slowly: the
    # iteration L2 ← (small-amplitude tuning of bpm/ρ(L2)) contracts by |d ln ρ/d ln ω₀|,
    # a few per cent, so a handful of rounds reach machine precision.
    x = np.full(bpm_arr.shape, (lo + hi) / 2)
    natural_lo, natural_hi = design.small_amplitude_range()
    for _ in range(MAX_ROUNDS):
        target = bpm_arr / table.ratio(x)
        x_new = np.asarray(design.small_amplitude_l2(np.clip(target, natural_lo, natural_hi)))
        done = np.max(np.abs(x_new - x), initial=0.0) < 1e-14
        x = x_new
        if done:
            break
    return x if x.ndim else float(x)

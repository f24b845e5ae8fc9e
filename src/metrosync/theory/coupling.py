"""The coupling K e^{−iα} of the reduced model, measured on the full model two ways.

Why a phase model, and which K
------------------------------
Each metronome is a limit-cycle oscillator (friction against escapement) weakly
coupled through the disk, so to first order in the coupling its phase obeys
dφ_i/dt = ω_i + (1/N) Σ_j H(φ_j − φ_i). Near the onset of synchrony at large N only
the first Fourier harmonic of H matters: the linear stability of incoherence involves
only the mode e^{iφ} (Daido; see `sakaguchi`). Writing that harmonic as
K sin(Δ − α) gives the Kuramoto–Sakaguchi model. Both methods below therefore aim at
the *first harmonic* K₁ e^{−iα₁}, and both use the continuous-time model (a small
Verlet step, 10⁻⁴ s): the paper's dt = 0.01 s locks single metronomes' periods to whole
numbers of steps, which would bias frequency measurements.

Method "growth" (the one the predictions use). N identical metronomes start at the
steady swing in a splay state, φ_j = 2πj/N + ε cos(2πj/N). For identical Sakaguchi
oscillators the mean field z then obeys dz/dt = (iω + (K/2) e^{−iα}) z exactly (N ≥ 3),
so the complex growth rate s of z gives K e^{−iα} = 2(s − iω). Harmonics of H enter
only through indices ≡ ±1 mod N, negligible for N ≥ 16. The phases are the
experiment's crossing-interpolated phases. One correction: the coupling acts partly
through the swing amplitude (a metronome pushed ahead swings less and, the pendulum
being anisochronous, faster), and the amplitude follows with the rate λ_A of
`metrosync.model.steady_swing.relaxation_rate`. For a mode growing at s this part is weakened by
λ_A/(λ_A + s); solving 2s = K cos α · λ_A/(λ_A + s) − iK sin α for the steady values
(what a slowly drifting oscillator near onset feels) removes it. Half the correction
is counted as its uncertainty.

Method "pair". Two metronomes, detuned by δω, lock at a phase difference Δ* and a
common frequency Ω. With H(Δ) = Σ_n K_n sin(nΔ − α_n), the pair obeys
δω = Σ_n K_n cos α_n sin nΔ* and Ω − ω̄ = −Σ_n (K_n/2) sin α_n (1 + cos nΔ*), ω̄ the
mean free frequency (`metrosync.model.steady_swing`). Locking at several detunings across the
locking range and fitting these sums with harmonics {1,2}, {1,3} and {1,2,3} gives
K₁ cos α₁ and K₁ sin α₁; the spread between the fits is their uncertainty. The
locked state is stationary, so no amplitude correction is needed.

N-dependence. To first order K is proportional to N/D₀(N), D₀ = J(N) + N m R², the
inertia the swinging weights push against (`disk_scale`; with today's J(N) law it
saturates at N → ∞ at 1/(j + m R²)). K(ω₀, N) is stored as κ(ω₀) = K/(N/D₀) and
rescaled; a test checks the law between N = 16 and 64.

The analytic estimate beside the measurements is in `estimate`.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from ..model import ModelParameters, get_preset
from ..model.steady_swing import relaxation_rate, steady_swing
from ..model.tuning import l2_for_bpm, with_tuning
from ..observables.entrainment import upward_crossings
from ..observables.order import crossing_phase
from ..simulate import simulate
from ._coupling_base import Coupling, disk_scale, tuned_metronome
from .estimate import estimate

METHODS = ("growth", "pair")
#: Most metronomes in a growth run (its trajectories are kept in memory).
MAX_GROWTH_N = 256
#: Integration step of the measurements, s (continuous-time model; see the docstring).
MEASURE_DT = 1e-4


def _start(phases, swing):
    omega = math.pi * swing.tick_bpm / 60.0
    return swing.amplitude * np.cos(phases), -swing.amplitude * omega * np.sin(phases)


def _free_omega(metronome, swing, params: ModelParameters, dt: float) -> float:
    """Angular tick frequency of ``metronome`` alone on a rigid support, as the measuring
    integrator sees it: the exact steady swing plus the step's own small offset
    (≈ −3×10⁻⁴ rad/s at dt = 10⁻⁴ s), which would otherwise pass for coupling."""
    theta0, theta_dot0 = _start(np.zeros(1), swing)
    ds = simulate(
        n=None,
        bpm=None,
        metronomes=[metronome],
        preset=params.on_rigid_support(),
        theta0=theta0,
        theta_dot0=theta_dot0,
        duration=60.0,
        dt=dt,
        trajectories=True,
        record_every=max(1, int(round(2.5e-3 / dt))),
        progress=False,
    )
    ticks = upward_crossings(ds.time.values, ds.theta.values[:, 0, 0])
    ticks = ticks[ticks > 20.0]
    return 2 * np.pi * (ticks.size - 1) / (ticks[-1] - ticks[0])


def _line(x, y):
    """Slope of a least-squares line and its standard error."""
    slope, icpt = np.polyfit(x, y, 1)
    res = y - (slope * x + icpt)
    se = math.sqrt(np.sum(res**2) / max(x.size - 2, 1) / np.sum((x - x.mean()) ** 2))
    return slope, se


def check_growth_n(n, name: str = "n") -> None:
    """Refuse a growth-run size outside [16, `MAX_GROWTH_N`], naming the argument."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 16 <= n <= MAX_GROWTH_N:
        raise ParameterError(
            f"`{name}` must be an integer in [16, {MAX_GROWTH_N}] for the growth method (below "
            f"16, harmonics of H enter through indices ±1 mod N; above, the recorded swings "
            f"outgrow memory, and K for any N follows from `Coupling.for_n`), got {n!r}."
        )


def measure_by_growth(
    bpm: float,
    *,
    n: int = 32,
    params: ModelParameters | str = "default",
    tuning: str | None = None,
    eps: float = 0.02,
    r_max: float = 0.08,
    dt: float = MEASURE_DT,
) -> Coupling:
    """K e^{−iα} at ``n`` from the growth of r out of a near-splay start (see module docs).

    eps : size of the splay's first-mode perturbation (r starts at eps/2).
    r_max : end of the fitted window (r stays in the linear regime below it).
    """
    params = with_tuning(get_preset(params, warn=False), tuning)
    check_growth_n(n)
    metronome, swing = tuned_metronome(bpm, params)
    guess = estimate(bpm, n, params)
    rate = max(guess.k_cos / 2, 1e-3)
    t_min = 5.0
    duration = min(t_min + 2.0 * math.log(2 * r_max / eps) / rate + 10.0, 2000.0)
    j = np.arange(n)
    theta0, theta_dot0 = _start(2 * np.pi * j / n + eps * np.cos(2 * np.pi * j / n), swing)
    every = max(1, int(round(2.5e-3 / dt)))
    ds = simulate(
        n=None,
        bpm=None,
        metronomes=[metronome] * n,
        preset=params,
        theta0=theta0,
        theta_dot0=theta_dot0,
        duration=duration,
        dt=dt,
        trajectories=True,
        record_every=every,
        progress=False,
    )
    t, theta = ds.time.values, ds.theta.values[:, 0, :]
    grid = np.arange(t_min, t[-1] - 2.0, 0.05)
    phases = np.stack([crossing_phase(upward_crossings(t, theta[:, i]), grid) for i in range(n)])
    z = np.mean(np.exp(1j * phases), axis=0)
    r = np.abs(z)
    past = np.nonzero(r > r_max)[0]
    if past.size == 0 or grid[past[0]] - t_min < 10.0:
        raise ParameterError(
            f"at {bpm} BPM the order parameter did not grow cleanly out of the splay state "
            f"(r = {r[0]:.3g} at {t_min} s, max {np.nanmax(r):.3g} within {duration:.0f} s); "
            f"K cos α may be <= 0 here, where the growth method does not apply; measure K "
            f"with `method` = 'pair' instead (two metronomes' phase difference, which needs "
            f"no growth)."
        )
    window = slice(0, past[0])
    growth, growth_se = _line(grid[window], np.log(r[window]))
    turn, turn_se = _line(grid[window], np.unwrap(np.angle(z[window])))
    s = complex(growth, turn - _free_omega(metronome, swing, params, dt))
    lam = relaxation_rate(metronome)
    u = lam + s
    k_sin = -(2 * s * u).imag / u.real
    k_cos = ((2 * s * u).real - k_sin * u.imag) / lam
    raw_cos, raw_sin = 2 * s.real, -2 * s.imag
    return Coupling(
        bpm=float(bpm),
        n=n,
        k_cos=k_cos,
        k_sin=k_sin,
        k_cos_err=math.hypot(2 * growth_se, (k_cos - raw_cos) / 2),
        k_sin_err=math.hypot(2 * turn_se, (k_sin - raw_sin) / 2),
        method="growth",
        scale=disk_scale(n, params),
        free_bpm=swing.tick_bpm,
    )


def _locked_pair(bpm, detune, params, dt, start_lag, duration=300.0):
    design = params.metronome
    pair = [
        design.with_l2(float(l2_for_bpm(design, b, tuning=design.tuning)))
        for b in (bpm - detune / 2, bpm + detune / 2)
    ]
    swings = [steady_swing(m) for m in pair]
    omega = np.array([math.pi * s.tick_bpm / 60.0 for s in swings])
    # Differences from the exact swing; the common reference as the integrator sees it.
    reference = np.mean(omega) + _free_omega(pair[0], swings[0], params, dt) - omega[0]
    amp = np.array([s.amplitude for s in swings])
    phases = np.array([0.0, start_lag])
    every = max(1, int(round(2.5e-3 / dt)))
    ds = simulate(
        n=None,
        bpm=None,
        metronomes=pair,
        preset=params,
        theta0=amp * np.cos(phases),
        theta_dot0=-amp * omega * np.sin(phases),
        duration=duration,
        dt=dt,
        trajectories=True,
        record_every=every,
        progress=False,
    )
    t = ds.time.values
    first, second = (upward_crossings(t, ds.theta.values[:, 0, i]) for i in range(2))
    keep = first[(first > duration / 2) & (first > second[0]) & (first < second[-1])]
    k = np.searchsorted(second, keep) - 1
    lead = np.exp(2j * np.pi * (keep - second[k]) / (second[k + 1] - second[k]))
    locked = abs(np.mean(lead)) > 0.999
    common = 2 * np.pi * (keep.size - 1) / (keep[-1] - keep[0])
    return omega[1] - omega[0], float(np.angle(np.mean(lead))), common - reference, locked


#: Harmonic sets fitted to the pair's locking curve.
PAIR_HARMONICS = ((1, 2), (1, 3), (1, 2, 3))


def measure_by_pair(
    bpm: float,
    *,
    params: ModelParameters | str = "default",
    tuning: str | None = None,
    points: int = 7,
    dt: float = MEASURE_DT,
) -> Coupling:
    """K₁ e^{−iα₁} at N = 2 from the locking curve of a detuned pair (see module docs)."""
    params = with_tuning(get_preset(params, warn=False), tuning)
    if isinstance(points, bool) or not isinstance(points, int) or points < 4:
        raise ParameterError(f"`points` must be an integer >= 4 detunings, got {points!r}.")
    _, swing = tuned_metronome(bpm, params)
    # A first small detuning gives the slope δω/Δ*, hence the locking range to span.
    dw, lag, _, _ = _locked_pair(bpm, 0.05, params, dt, 0.05)
    edge_bpm = 0.05 / math.sin(lag) if lag > 0 else 0.0
    if not (lag > 0 and edge_bpm > 0.1):
        raise ParameterError(
            f"at {bpm} BPM the pair locks at Δ* = {lag:.3g} rad for a 0.05 BPM detuning: no "
            f"attractive coupling to measure."
        )
    rows = []
    for fraction in np.linspace(0.1, 0.85, points):
        row = _locked_pair(bpm, fraction * edge_bpm, params, dt, math.asin(min(fraction, 0.95)))
        if row[3]:
            rows.append(row[:3])
    if len(rows) < 4:
        raise ParameterError(
            f"at {bpm} BPM only {len(rows)} of {points} detuned pairs locked; the locking "
            f"curve cannot be fitted."
        )
    dw, lag, shift = (np.array(c) for c in zip(*rows, strict=True))
    cos_fits, sin_fits = [], []
    for harmonics in PAIR_HARMONICS:
        odd = np.stack([np.sin(h * lag) for h in harmonics], axis=1)
        even = np.stack([-(1 + np.cos(h * lag)) / 2 for h in harmonics], axis=1)
        cos_fits.append(np.linalg.lstsq(odd, dw, rcond=None)[0][0])
        sin_fits.append(np.linalg.lstsq(even, shift, rcond=None)[0][0])
    return Coupling(
        bpm=float(bpm),
        n=2,
        k_cos=float(np.mean(cos_fits)),
        k_sin=float(np.mean(sin_fits)),
        k_cos_err=float(np.ptp(cos_fits)) / 2,
        k_sin_err=float(np.ptp(sin_fits)) / 2,
        method="pair",
        scale=disk_scale(2, params),
        free_bpm=swing.tick_bpm,
    )

"""Onset of synchrony in the Kuramoto–Sakaguchi model: the exact linear threshold.

The model (Sakaguchi & Kuramoto, Prog. Theor. Phys. 76, 576 (1986)) is

    dφ_i/dt = ω_i + (K/N) Σ_j sin(φ_j − φ_i − α) = ω_i + K Im(z e^{−i(φ_i + α)}),

with z = (1/N) Σ_j e^{iφ_j} = r e^{iψ}, and natural frequencies ω_i drawn from a density
g(ω) of standard deviation σ, measured from its mean (which a rotating frame removes).

Linear stability of incoherence
-------------------------------
For N → ∞ write the density of oscillators as g(ω)/(2π) [1 + b(ω, t) e^{−iφ} + c.c.],
so that z = ∫ g b dω. The continuity equation, linearised, gives
∂b/∂t = iω b + (K/2) e^{−iα} z. A mode b, z ∝ e^{st} exists when

    1 = (K/2) e^{−iα} ∫ g(ω) / (s − iω) dω,                                   (1)

and incoherence is unstable when a root has Re s > 0. With s = λ + iΩ and the
function G(Ω + iλ) = ∫ g(ω) / (λ + i(ω − Ω)) dω (its complex conjugate for real λ, Ω
is the integral in (1)), the threshold is the λ → 0⁺ limit of

    G(Ω) = (2/K) e^{−iα}.                                                      (2)

Ω is the drift of the critical mode: the mean field turns at ω̄ + Ω. (Omel'chenko &
Wolfrum, Phys. Rev. Lett. 109, 164101 (2012), analyse the same threshold and show that
for some unimodal g a phase lag makes the transition non-monotone; for the Gaussian
the tests check against simulations that r starts to grow where (2) says.)

For a Gaussian g of standard deviation σ, with the Faddeeva function
w(ζ) = e^{−ζ²} erfc(−iζ) (`scipy.special.wofz`),

    G(Ω + iλ) = √(π/2) w(ζ) / σ,   ζ = (Ω + iλ) / (√2 σ),

and for real x = Ω/(√2 σ), w(x) = e^{−x²} (1 + i erfi(x)). So (2) says
erfi(x) = −tan α and |G| = 2/K:

    Ω_c = −√2 σ erfi⁻¹(tan α),   K_c = √(8/π) σ e^{x²} cos α.

At α = 0 this is Kuramoto's K_c = 2/(π g(0)) = √(8/π) σ ≈ 1.596 σ. For a Lorentzian of
half-width γ, G = 1/(γ − iΩ) and K_c = 2γ / cos α exactly. For |α| ≥ π/2 the coupling
does not attract and incoherence is stable at every K: the threshold is ∞.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import erfi, wofz

from ..errors import ParameterError

#: Distributions of natural frequencies with an exact threshold.
DISTRIBUTIONS = ("gaussian", "lorentzian")
#: Steps in K from the threshold to the requested coupling in `growth_rate`.
CONTINUATION_STEPS = 40


@dataclass(frozen=True)
class Onset:
    """The linear threshold of incoherence.

    k_c : critical coupling, same units as ``sigma`` (rad/s when σ is in rad/s); inf
        when the coupling never synchronizes (|α| ≥ π/2).
    drift : Ω_c, frequency of the critical mode relative to the mean natural frequency.
    alpha, sigma, distribution : the inputs.
    """

    k_c: float
    drift: float
    alpha: float
    sigma: float
    distribution: str


def _check(alpha: float, sigma: float, distribution: str) -> tuple[float, float]:
    if distribution not in DISTRIBUTIONS:
        raise ParameterError(
            f"unknown `distribution` {distribution!r}; choose one of {list(DISTRIBUTIONS)}."
        )
    alpha, sigma = float(alpha), float(sigma)
    if not math.isfinite(alpha):
        raise ParameterError(f"`alpha` must be a finite phase lag in rad, got {alpha!r}.")
    if not (math.isfinite(sigma) and sigma > 0):
        raise ParameterError(
            f"`sigma` must be a spread > 0 of the natural frequencies, got {sigma!r}; with no "
            f"spread the threshold is 0 for |alpha| < pi/2."
        )
    # Fold α into (−π, π]: the model depends on α only through e^{iα}.
    return math.remainder(alpha, 2 * math.pi), sigma


def erfi_inverse(t: float) -> float:
    """The real x with erfi(x) = t (erfi is odd and increasing)."""
    if t == 0:
        return 0.0
    hi = 1.0
    while erfi(hi) < abs(t):
        hi *= 2.0
    return math.copysign(brentq(lambda x: erfi(x) - abs(t), 0.0, hi, xtol=1e-15), t)


def onset(alpha: float = 0.0, sigma: float = 1.0, *, distribution: str = "gaussian") -> Onset:
    """Critical coupling K_c and drift Ω_c of the Kuramoto–Sakaguchi model (eq. (2)).

    Parameters
    ----------
    alpha : phase lag α, rad.
    sigma : standard deviation of a Gaussian g, or half-width γ of a Lorentzian.
    distribution : ``"gaussian"`` or ``"lorentzian"``.
    """
    alpha, sigma = _check(alpha, sigma, distribution)
    if abs(alpha) >= math.pi / 2:
        return Onset(math.inf, math.nan, alpha, sigma, distribution)
    if distribution == "lorentzian":
        k_c = 2 * sigma / math.cos(alpha)
        return Onset(k_c, -k_c / 2 * math.sin(alpha), alpha, sigma, distribution)
    x = -erfi_inverse(math.tan(alpha))
    k_c = math.sqrt(8 / math.pi) * sigma * math.exp(x * x) * math.cos(alpha)
    return Onset(k_c, math.sqrt(2) * sigma * x, alpha, sigma, distribution)


def critical_coupling(alpha, sigma=1.0, *, distribution: str = "gaussian"):
    """K_c(α, σ) for scalars or arrays (broadcast together); see `onset`."""
    a, s = np.broadcast_arrays(np.asarray(alpha, dtype=float), np.asarray(sigma, dtype=float))
    out = np.array(
        [onset(x, y, distribution=distribution).k_c for x, y in zip(a.flat, s.flat, strict=True)]
    ).reshape(a.shape)
    return out if out.ndim else float(out)


def dispersion_integral(s: complex, sigma: float, *, distribution: str = "gaussian") -> complex:
    """H(s) = ∫ g(ω) / (s − iω) dω for Re s > 0 (the integral of eq. (1)), analytic in s.

    Gaussian: H(s) = √(π/2) w(i s / (√2 σ)) / σ.   Lorentzian: H(s) = 1 / (s + γ).
    For real λ, Ω, H(λ + iΩ) is the complex conjugate of G(Ω + iλ).
    """
    if distribution == "lorentzian":
        return 1.0 / (s + sigma)
    return math.sqrt(math.pi / 2) * complex(wofz(1j * s / (math.sqrt(2) * sigma))) / sigma


def _dispersion_derivative(s: complex, sigma: float, distribution: str) -> complex:
    if distribution == "lorentzian":
        return -1.0 / (s + sigma) ** 2
    u = 1j * s / (math.sqrt(2) * sigma)
    dw = -2 * u * complex(wofz(u)) + 2j / math.sqrt(math.pi)  # w'(u)
    return math.sqrt(math.pi / 2) / sigma * dw * 1j / (math.sqrt(2) * sigma)


def growth_rate(k: float, alpha: float, sigma: float, *, distribution: str = "gaussian"):
    """The unstable root s = λ + iΩ of eq. (1) for K above K_c (λ > 0), as a complex.

    Found by Newton's method on the analytic function (K/2) e^{−iα} H(s) − 1, followed
    from the threshold root s = iΩ_c as K rises to ``k``. Returns ``None`` when
    incoherence is linearly stable (K <= K_c).
    """
    alpha, sigma = _check(alpha, sigma, distribution)
    on = onset(alpha, sigma, distribution=distribution)
    if not k > on.k_c:
        return None
    lag = complex(math.cos(alpha), -math.sin(alpha))
    s = complex(0.0, on.drift)
    for kj in np.linspace(on.k_c, k, CONTINUATION_STEPS + 1)[1:]:
        for _ in range(50):
            f = kj / 2 * lag * dispersion_integral(s, sigma, distribution=distribution) - 1
            step = f / (kj / 2 * lag * _dispersion_derivative(s, sigma, distribution))
            s -= step
            if abs(step) < 1e-14 * max(1.0, abs(s)):
                break
    if not s.real > 0:
        raise ParameterError(
            f"no unstable root found for `k` = {k!r}, `alpha` = {alpha!r}, `sigma` = {sigma!r}."
        )
    return s

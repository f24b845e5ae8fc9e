"""The Kuramoto–Sakaguchi onset: closed forms, the dispersion relation by quadrature."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import fsolve

from metrosync import ParameterError
from metrosync.theory.sakaguchi import (
    critical_coupling,
    dispersion_integral,
    erfi_inverse,
    growth_rate,
    onset,
)


def test_kuramoto_threshold_at_zero_lag():
    # K_c = 2/(π g(0)) = √(8/π) σ for a Gaussian (Kuramoto 1975).
    on = onset(0.0, 1.0)
    assert on.k_c == pytest.approx(math.sqrt(8 / math.pi), rel=1e-14)
    assert round(on.k_c, 3) == 1.596
    assert on.drift == 0.0
    assert onset(0.0, 0.04).k_c == pytest.approx(0.04 * 1.5957691216, rel=1e-9)


def gaussian_dispersion_by_quadrature(alpha: float, sigma: float = 1.0):
    """Solve eq. (2) without the Faddeeva function.

    With λ → 0⁺, 1/(λ + i(ω − Ω)) → π δ(ω − Ω) − i PV 1/(ω − Ω), so
    G(Ω) = π g(Ω) − i PV∫ g(ω)/(ω − Ω) dω.
    """
    g = lambda w: math.exp(-0.5 * (w / sigma) ** 2) / (math.sqrt(2 * math.pi) * sigma)  # noqa: E731

    def big_g(om):
        # Cauchy principal value by scipy's QAWC (weight 1/(ω − Ω)) on a wide interval.
        pv, _ = quad(
            g,
            om - 12 * sigma,
            om + 12 * sigma,
            weight="cauchy",
            wvar=om,
            epsabs=1e-13,
            epsrel=1e-13,
            limit=200,
        )
        return complex(math.pi * g(om), -pv)

    def equations(v):
        k, om = v
        err = big_g(om) * k / 2 * complex(math.cos(alpha), math.sin(alpha)) - 1
        return [err.real, err.imag]

    k, om = fsolve(equations, [1.6 * sigma, -0.5 * sigma * alpha], xtol=1e-13)
    return k, om


@pytest.mark.parametrize("alpha", [0.0, 0.3, -0.6, 1.2])
def test_gaussian_threshold_matches_the_dispersion_relation_by_quadrature(alpha):
    k, om = gaussian_dispersion_by_quadrature(alpha, 0.7)
    on = onset(alpha, 0.7)
    assert on.k_c == pytest.approx(k, rel=1e-8)
    assert on.drift == pytest.approx(om, abs=1e-8)


def erfi_series(x: float) -> float:
    """erfi(x) = (2/√π) Σ x^(2n+1) / (n! (2n+1)), independently of scipy."""
    return (
        2
        / math.sqrt(math.pi)
        * sum(x ** (2 * n + 1) / (math.factorial(n) * (2 * n + 1)) for n in range(40))
    )


def test_a_value_at_nonzero_lag_computed_three_ways():
    # α = π/4: erfi(x) = −1, and K_c/σ = √(8/π) e^{x²} cos(π/4) = 1.9273 (to 4 decimals).
    x = erfi_inverse(1.0)
    assert erfi_series(x) == pytest.approx(1.0, rel=1e-13)
    assert x == pytest.approx(0.73170, abs=1e-5)
    on = onset(math.pi / 4, 1.0)
    assert on.k_c == pytest.approx(1.9273, abs=1e-4)
    assert on.drift == pytest.approx(-math.sqrt(2) * x, rel=1e-12)
    k, om = gaussian_dispersion_by_quadrature(math.pi / 4)
    assert k == pytest.approx(1.9273, abs=1e-4)
    assert om == pytest.approx(on.drift, abs=1e-8)


def test_lorentzian_closed_form():
    for alpha in (0.0, 0.5, -1.0):
        on = onset(alpha, 0.3, distribution="lorentzian")
        assert on.k_c == pytest.approx(0.6 / math.cos(alpha))
        h = dispersion_integral(complex(1e-12, on.drift), 0.3, distribution="lorentzian")
        assert h * on.k_c / 2 * complex(math.cos(alpha), -math.sin(alpha)) == pytest.approx(1)


def test_threshold_grows_with_lag_and_is_even_in_it():
    alphas = np.linspace(0, 1.5, 16)
    k = critical_coupling(alphas)
    assert np.all(np.diff(k) > 0)
    np.testing.assert_allclose(critical_coupling(-alphas), k)
    assert critical_coupling(alphas, 2.0) == pytest.approx(2 * k)
    # The drift of the critical mode is opposite in sign to α.
    assert onset(0.5).drift < 0 < onset(-0.5).drift


def test_repulsive_lag_never_synchronizes():
    assert onset(math.pi / 2).k_c == math.inf
    assert onset(2.0).k_c == math.inf
    # α is a phase: 2π + 0.3 is 0.3.
    assert onset(2 * math.pi + 0.3).k_c == pytest.approx(onset(0.3).k_c)


def test_dispersion_integral_by_quadrature():
    # H(s) = ∫ g/(s − iω) dω at a point off the axis, Gaussian σ = 0.8.
    s, sigma = complex(0.3, -0.2), 0.8

    def g(w):
        return math.exp(-0.5 * (w / sigma) ** 2) / (math.sqrt(2 * math.pi) * sigma)

    re = quad(lambda w: (g(w) / (s - 1j * w)).real, -np.inf, np.inf, epsabs=1e-13)[0]
    im = quad(lambda w: (g(w) / (s - 1j * w)).imag, -np.inf, np.inf, epsabs=1e-13)[0]
    assert dispersion_integral(s, sigma) == pytest.approx(complex(re, im), abs=1e-10)


def test_growth_rate_vanishes_at_threshold_and_tends_to_the_identical_limit():
    on = onset(0.4, 1.0)
    assert growth_rate(0.99 * on.k_c, 0.4, 1.0) is None
    s = growth_rate(1.001 * on.k_c, 0.4, 1.0)
    assert 0 < s.real < 0.01
    assert s.imag == pytest.approx(on.drift, abs=0.01)
    # For K ≫ σ the root approaches (K/2) e^{−iα} minus the spread's damping.
    s = growth_rate(200.0, 0.4, 1.0)
    assert s.real == pytest.approx(100 * math.cos(0.4), rel=0.02)
    assert s.imag == pytest.approx(-100 * math.sin(0.4), rel=0.02)


def test_bad_input_is_named():
    with pytest.raises(ParameterError, match=r"`sigma` must be a spread > 0"):
        onset(0.1, 0.0)
    with pytest.raises(ParameterError, match=r"`alpha` must be a finite"):
        onset(float("nan"))
    with pytest.raises(ParameterError, match=r"unknown `distribution` 'uniform'"):
        onset(0.1, distribution="uniform")

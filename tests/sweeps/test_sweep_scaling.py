"""The finite-size-scaling collapse: known forms, plain Kuramoto oscillators, bad input."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.sweeps.scaling import (
    KURAMOTO_EXPONENTS,
    collapse,
    finite_size_scaling,
    mean_and_error,
    plot_collapse,
)

X_C, A, B = 1.6, 0.2, 0.4
SIZES = np.array([100, 200, 400, 800, 1600])
X = np.linspace(1.45, 1.75, 13)


def _scaling_form_runs(seed: int, runs: int = 16, noise: float = 0.02) -> np.ndarray:
    """Per-run samples (M, K, runs) of r = N^(−a)·F((x − x_c)·N^b) plus Gaussian noise."""
    rng = np.random.default_rng(seed)
    master = 0.5 / (1 + np.exp(-(X[None, :] - X_C) * SIZES[:, None] ** B)) + 0.1
    r = SIZES[:, None] ** (-A) * master
    return r[..., None] + noise * rng.standard_normal(r.shape + (runs,))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fixed_exponents_recover_x_c_of_an_exact_scaling_form(seed):
    est = finite_size_scaling(
        X, SIZES, _scaling_form_runs(seed), exponents=(A, B), degree=4, n_boot=10
    )
    assert est.x_c_err < 0.03
    assert abs(est.x_c - X_C) < 3 * est.x_c_err
    assert 0.5 < est.best.chi2_dof < 2.0


@pytest.mark.parametrize("seed", [0, 3])
def test_free_exponents_recover_an_exact_scaling_form(seed):
    est = finite_size_scaling(X, SIZES, _scaling_form_runs(seed), degree=4, n_boot=0)
    for value, err, truth, bound in (
        (est.x_c, est.x_c_err, X_C, 0.2),
        (est.a, est.a_err, A, 0.2),
        (est.b, est.b_err, B, 0.25),
    ):
        assert err < bound
        assert abs(value - truth) < 3 * err


def test_wrong_exponents_collapse_worse():
    runs = _scaling_form_runs(4)
    r, err = mean_and_error(runs)
    right = collapse(X, SIZES, r, err, exponents=(A, B), degree=4)
    wrong = collapse(X, SIZES, r, err, exponents=(0.5, B), degree=4)
    assert wrong.chi2_dof > 3 * right.chi2_dof


def test_variants_and_systematic_error_are_reported():
    est = finite_size_scaling(X, SIZES, _scaling_form_runs(5), exponents=(A, B), degree=4, n_boot=0)
    # two narrower windows, smallest N left out, largest N left out
    assert len(est.variants) == 4
    assert {v.sizes for v in est.variants} >= {tuple(SIZES[1:]), tuple(SIZES[:-1])}
    assert est.x_c_syst == max(abs(v.x_c - est.x_c) for v in est.variants)
    assert est.x_c_err >= max(est.x_c_syst, est.best.x_c_err)


@numba.njit(cache=True, fastmath=True)
def _kuramoto_mean_r(theta, omega, k, dt, transient, window):
    """Time-averaged r of dθ_i/dt = ω_i + K·r·sin(ψ − θ_i), Heun steps, mean field O(N)."""
    n = theta.size
    c = np.empty(n)
    s = np.empty(n)
    acc = 0.0
    for step in range(transient + window):
        x = 0.0
        y = 0.0
        for i in range(n):
            c[i] = math.cos(theta[i])
            s[i] = math.sin(theta[i])
            x += c[i]
            y += s[i]
        x /= n
        y /= n
        if step >= transient:
            acc += math.sqrt(x * x + y * y)
        x2 = 0.0
        y2 = 0.0
        for i in range(n):
            f = omega[i] + k * (y * c[i] - x * s[i])
            pred = theta[i] + dt * f
            theta[i] += 0.5 * dt * f
            c[i] = math.cos(pred)
            s[i] = math.sin(pred)
            x2 += c[i]
            y2 += s[i]
        x2 /= n
        y2 /= n
        for i in range(n):
            theta[i] += 0.5 * dt * (omega[i] + k * (y2 * c[i] - x2 * s[i]))
    return acc / window


def _kuramoto_runs(sizes, couplings, runs, *, seed, dt=0.2, transient=100.0, window=100.0):
    """r_eq (M, K, runs): each run draws its own Gaussian frequencies (quenched disorder)."""
    out = np.empty((len(sizes), len(couplings), runs))
    steps = int(round(transient / dt)), int(round(window / dt))
    for m, n in enumerate(sizes):
        rng = np.random.default_rng([seed, n])
        for b in range(runs):
            omega = rng.standard_normal(n)
            theta0 = rng.uniform(0.0, 2 * np.pi, n)
            for j, k in enumerate(couplings):
                out[m, j, b] = _kuramoto_mean_r(theta0.copy(), omega, float(k), dt, *steps)
    return out


@pytest.mark.slow
def test_collapse_recovers_kuramoto_k_c_and_exponents():
    """Plain Kuramoto with unit Gaussian frequencies: K_c = 2/(π g(0)) = √(8/π) exactly,
    β/ν̄ = 1/5 and 1/ν̄ = 2/5 (Hong, Chaté, Park and Tang, PRL 98, 184101 (2007))."""
    k_c = 2 / (math.pi / math.sqrt(2 * math.pi))
    couplings = k_c + np.linspace(-0.3, 0.3, 7)
    sizes = np.array([200, 400, 800, 1600])
    runs = _kuramoto_runs(sizes, couplings, 24, seed=27)
    fixed = finite_size_scaling(
        couplings, sizes, runs, exponents=KURAMOTO_EXPONENTS, degree=4, n_boot=20
    )
    assert fixed.x_c_err < 0.08
    assert abs(fixed.x_c - k_c) < 3 * fixed.x_c_err
    free = finite_size_scaling(couplings, sizes, runs, degree=4, n_boot=20)
    for value, err, truth, bound in (
        (free.x_c, free.x_c_err, k_c, 0.2),
        (free.a, free.a_err, KURAMOTO_EXPONENTS[0], 0.2),
        (free.b, free.b_err, KURAMOTO_EXPONENTS[1], 0.2),
    ):
        assert err < bound
        assert abs(value - truth) < 3 * err


def test_plot_collapse_writes_both_panels(tmp_path):
    runs = _scaling_form_runs(6)
    r, err = mean_and_error(runs)
    fit = collapse(X, SIZES, r, err, exponents=(A, B), degree=4)
    path = tmp_path / "collapse.png"
    fig = plot_collapse(fit, X, SIZES, r, err, path=path, x_label="K")
    assert path.stat().st_size > 1000
    assert len(fig.axes) == 2
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_mean_and_error_ignores_nan_runs_and_needs_two():
    runs = np.array([[[1.0, 3.0, np.nan], [2.0, np.nan, np.nan]]])
    mean, err = mean_and_error(runs)
    assert mean[0, 0] == 2.0
    assert err[0, 0] == pytest.approx(math.sqrt(2) / math.sqrt(2))
    assert np.isnan(mean[0, 1]) and np.isnan(err[0, 1])


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        (dict(x=np.array([1.0, 2.0])), "`x`"),
        (dict(sizes=np.array([100, 100, 200, 400, 800])), "`sizes`"),
        (dict(r=np.zeros((3, 13))), "`r`"),
        (dict(degree=0), "`degree`"),
        (dict(window=(1.7, 1.5)), "`window`"),
        (dict(window=(1.59, 1.61)), "widen the window"),
        (dict(exponents=(0.2, 9.0)), "`exponents`"),
    ],
)
def test_bad_input_names_the_argument(kwargs, words):
    r, err = mean_and_error(_scaling_form_runs(7))
    args = dict(x=X, sizes=SIZES, r=r, r_err=err)
    args.update({k: v for k, v in kwargs.items() if k in args})
    options = {k: v for k, v in kwargs.items() if k not in args}
    with pytest.raises(ParameterError, match=words.replace("(", r"\(")):
        collapse(args["x"], args["sizes"], args["r"], args["r_err"], **options)


def test_bad_runs_and_bootstrap_count_are_named():
    with pytest.raises(ParameterError, match="`r_runs`"):
        finite_size_scaling(X, SIZES, np.zeros((5, 13)))
    with pytest.raises(ParameterError, match="`n_boot`"):
        finite_size_scaling(X, SIZES, _scaling_form_runs(0), n_boot=1)

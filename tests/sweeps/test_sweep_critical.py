"""The ω_c estimators recover a known transition from synthetic r(ω₀) curves."""

import numpy as np
import pytest
import xarray as xr

from metrosync import ParameterError
from metrosync.sweeps.critical import (
    critical_frequency,
    estimate,
    extrapolate,
    plot_critical,
    size_set_spread,
)

OMEGA_INF, AMPLITUDE, NU = 185.0, 60.0, 0.8


def true_omega_c(n):
    return OMEGA_INF + AMPLITUDE * np.asarray(n, dtype=float) ** -NU


def synthetic_sweep(seed=1, runs=100, sizes=(8, 16, 32, 64, 128)):
    """Each run synchronizes (r ≈ 0.9) with probability logistic((ω₀ − ω_c(N))/w(N)),
    else stays incoherent (r ≈ 0.2): the mean rises fastest and σ_r peaks at ω_c(N)."""
    rng = np.random.default_rng(seed)
    bpm = np.arange(160.0, 210.5, 1.0)
    n = np.array(sizes)
    r = np.empty((n.size, bpm.size, runs))
    for i, size in enumerate(n):
        p = 1 / (1 + np.exp(-(bpm - true_omega_c(size)) / (8 / np.sqrt(size))))
        synced = rng.random((bpm.size, runs)) < p[:, None]
        r[i] = np.where(synced, 0.9, 0.2) + rng.normal(0, 0.03, (bpm.size, runs))
    return xr.Dataset({"r_eq": (("n", "bpm", "run"), r)}, coords={"n": n, "bpm": bpm})


@pytest.fixture(scope="module")
def result():
    return critical_frequency(synthetic_sweep(), n_boot=400)


@pytest.mark.parametrize("method", ["peak", "rise"])
def test_each_size_is_recovered_within_the_bootstrap_error(result, method):
    truth = true_omega_c(result.n.values)
    estimate_, err = result[f"omega_c_{method}"].values, result[f"omega_c_{method}_err"].values
    assert np.all(err > 0) and np.all(err < 2.0)  # informative, not vacuous, error bars
    assert np.all(np.abs(estimate_ - truth) < 3 * err), (estimate_, truth, err)


@pytest.mark.parametrize("method", ["peak", "rise"])
def test_extrapolation_recovers_the_infinite_size_limit(result, method):
    a = result.attrs
    assert a[f"fit_form_{method}"] == "omega_inf + a*N**-nu"
    assert abs(a[f"omega_c_inf_{method}"] - OMEGA_INF) < 3 * a[f"omega_c_inf_{method}_err"]
    assert a[f"omega_c_inf_{method}_err"] < 2.0


def test_bootstrap_errors_shrink_with_more_runs():
    few = critical_frequency(synthetic_sweep(runs=25, sizes=(32,)), n_boot=300)
    many = critical_frequency(synthetic_sweep(runs=400, sizes=(32,)), n_boot=300)
    assert many.omega_c_peak_err.item() < few.omega_c_peak_err.item()


def test_sub_grid_refinement_finds_an_off_grid_peak():
    bpm = np.arange(180.0, 191.0, 1.0)
    center = 185.3
    spread = 0.5 - 0.01 * (bpm - center) ** 2  # σ_r is this parabola (ddof=1 of ±s pairs)
    runs = np.stack([0.5 + spread / np.sqrt(2), 0.5 - spread / np.sqrt(2)], axis=-1)
    assert estimate(bpm, runs)["peak"] == pytest.approx(center, abs=1e-9)


def test_fewer_sizes_fall_back_to_simpler_fits():
    n = np.array([8.0, 16.0, 32.0])
    exact = 185 + 40 / n
    fit = extrapolate(n, exact, np.full(3, 0.1), step=1.0)
    assert fit.form == "omega_inf + a/N" and fit.omega_inf == pytest.approx(185.0)
    assert extrapolate(n[:2], exact[:2], np.full(2, 0.1), step=1.0).form.startswith("none")


def test_size_set_spread_is_the_shift_when_an_end_size_is_left_out():
    n = np.array([64.0, 256.0, 1024.0, 4096.0])
    exact = 171 + 200 / n
    fit, spread = size_set_spread(n, exact, np.full(4, 0.05), step=2.5)
    assert fit.omega_inf == pytest.approx(171.0, abs=1e-3) and spread < 1e-3
    # The largest N off the law by 0.4: leaving it out moves the fit, and the
    # spread is that move (the three-size fit is then linear in 1/N and exact).
    bent = exact + np.array([0, 0, 0, 0.4])
    fit, spread = size_set_spread(n, bent, np.full(4, 0.05), step=2.5)
    assert spread == pytest.approx(abs(fit.omega_inf - 171.0), abs=1e-6) and spread > 0.1
    # Three sizes leave no variant of three.
    assert np.isnan(size_set_spread(n[:3], exact[:3], np.full(3, 0.05), step=2.5)[1])


def test_single_size_sweep_and_bad_inputs(tmp_path):
    one = synthetic_sweep(sizes=(16,)).isel(n=0).drop_vars("n")
    one.attrs["fixed_n"] = 16
    res = critical_frequency(one, n_boot=50)
    assert res.n.values.tolist() == [16]
    plot_critical(res, tmp_path / "c.png")
    assert (tmp_path / "c.png").stat().st_size > 0
    with pytest.raises(ParameterError, match="`bpm` needs at least 3"):
        critical_frequency(one.isel(bpm=[0, 1]))
    with pytest.raises(ParameterError, match="also varies"):
        critical_frequency(one.expand_dims(drive=[1e-5, 2e-5]))
    with pytest.raises(ParameterError, match="sweep `bpm`"):
        critical_frequency(one.rename(bpm="sigma_bpm"))


def test_frequencies_without_any_finite_run_are_skipped_not_fatal():
    """Short runs at low ω₀ leave r_eq NaN there (no two crossings yet)."""
    sweep = synthetic_sweep(sizes=(16, 64))
    sweep["r_eq"][:, :3, :] = np.nan
    sweep["r_eq"][:, 10, 1:] = np.nan  # one lone finite run
    res = critical_frequency(sweep, n_boot=100)
    for method in ("peak", "rise"):
        assert np.all(np.abs(res[f"omega_c_{method}"] - true_omega_c(res.n.values)) < 3.0)
    sweep["r_eq"][1] = np.nan
    with pytest.raises(ParameterError, match=r"no finite r_eq for N = \[64\]"):
        critical_frequency(sweep, n_boot=10)

"""The reduced phase model: its scheme's order, exact growth rates, the onset."""

import math

import numpy as np
import pytest

from metrosync import ParameterError
from metrosync.theory.reduced import simulate_reduced
from metrosync.theory.sakaguchi import onset


def splay(n: int, eps: float) -> np.ndarray:
    j = np.arange(n)
    return 2 * np.pi * j / n + eps * np.cos(2 * np.pi * j / n)


@pytest.mark.parametrize("alpha", [0.0, 0.7, -0.4])
def test_identical_oscillators_leave_the_splay_state_at_half_k_cos_alpha(alpha):
    # Linearising about the splay state gives dz/dt = (iω + (K/2) e^{−iα}) z exactly for
    # N >= 3, so r grows as e^{(K/2) cos α t}: a check of the sign convention of α.
    k, eps = 0.2, 1e-4
    ds = simulate_reduced(
        omega=np.zeros(16),
        k=k,
        alpha=alpha,
        phases0=splay(16, eps),
        duration=60.0,
        dt=0.05,
        record_every=20,
    )
    r = ds.r.values[:, 0]
    t = ds.time.values
    rate = np.polyfit(t, np.log(r), 1)[0]
    assert rate == pytest.approx(k / 2 * math.cos(alpha), rel=2e-3)
    assert r[0] == pytest.approx(eps / 2, rel=1e-3)


def test_scheme_is_second_order():
    rng = np.random.default_rng(3)
    omega, phases = rng.normal(0, 0.05, 300), rng.uniform(0, 2 * np.pi, 300)
    runs = {
        dt: simulate_reduced(
            omega=omega,
            phases0=phases,
            k=0.15,
            alpha=0.5,
            duration=40.0,
            dt=dt,
            record_every=int(round(2.0 / dt)),
        ).r.values[:, 0]
        for dt in (0.4, 0.2, 0.1, 0.05)
    }
    errors = [np.max(np.abs(runs[dt] - runs[0.05])) for dt in (0.4, 0.2, 0.1)]
    slopes = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # The error against dt/2^k: 1 − 4^(−k) times the leading term, so the ratios near 2nd
    # order are (1 − 1/64)/(1 − 1/16) ≈ 4.2 and (1 − 1/16)/(1 − 1/4) = 5.0.
    assert np.all(slopes > 1.8) and np.all(slopes < 2.6), slopes


@pytest.mark.parametrize("alpha", [0.0, 0.8])
def test_incoherence_gives_way_at_the_sakaguchi_threshold(alpha):
    sigma = 0.05
    k_c = onset(alpha, sigma).k_c
    r = {
        f: float(
            simulate_reduced(
                20_000, k=f * k_c, alpha=alpha, sigma=sigma, duration=800.0, dt=0.25, seed=5
            ).r_eq[0]
        )
        for f in (0.9, 1.1)
    }
    # 10 % below: finite-size noise, a few/√N ≈ 0.02. 10 % above: partial locking.
    assert r[0.9] < 0.05
    assert r[1.1] > 0.25


def test_output_shape_and_statistics():
    ds = simulate_reduced(32, k=0.3, sigma=0.05, runs=5, duration=100.0, dt=0.2, seed=1)
    assert ds.r.dims == ("time", "run") and ds.r.shape == (101, 5)
    assert ds.time.values[-1] == pytest.approx(100.0)
    assert ds.attrs["r_eq_mean"] == pytest.approx(float(ds.r_eq.mean()))
    late = ds.r.sel(time=slice(75.0, None)).mean("time")
    np.testing.assert_allclose(ds.r_eq, late)
    again = simulate_reduced(32, k=0.3, sigma=0.05, runs=5, duration=100.0, dt=0.2, seed=1)
    np.testing.assert_array_equal(ds.r.values, again.r.values)


def test_large_n_path_matches_the_small_n_path():
    from metrosync.theory import reduced

    rng = np.random.default_rng(0)
    omega, phases = rng.normal(0, 0.05, 5000), rng.uniform(0, 2 * np.pi, 5000)
    kw = dict(omega=omega, phases0=phases, k=0.2, alpha=0.3, duration=50.0, dt=0.25)
    big = simulate_reduced(**kw)
    threaded = simulate_reduced(**kw, threads=True)
    old = reduced.LARGE_N
    try:
        reduced.LARGE_N = 10**9
        small = simulate_reduced(**kw)
    finally:
        reduced.LARGE_N = old
    np.testing.assert_allclose(big.r.values, small.r.values, rtol=1e-10)
    np.testing.assert_allclose(threaded.r.values, small.r.values, rtol=1e-10)


def test_bad_input_is_named():
    with pytest.raises(ParameterError, match=r"`dt` = 5.0 s lets a phase move"):
        simulate_reduced(10, k=0.3, sigma=0.05, dt=5.0, duration=50.0)
    with pytest.raises(ParameterError, match=r"`sigma` must be a spread"):
        simulate_reduced(10, k=0.3)
    with pytest.raises(ParameterError, match=r"`omega` must have shape"):
        simulate_reduced(k=0.3, omega=np.zeros((3, 4)), runs=2)
    with pytest.raises(ParameterError, match=r"`phases0` must have shape \(4,\)"):
        simulate_reduced(k=0.3, omega=np.zeros(4), phases0=np.zeros(5))
    with pytest.raises(ParameterError, match=r"`n` must be an integer"):
        simulate_reduced(0, k=0.3, sigma=0.1)
    with pytest.raises(ParameterError, match=r"`k` must be a finite"):
        simulate_reduced(10, k=float("inf"), sigma=0.1)
    with pytest.raises(ParameterError, match=r"`record_every`"):
        simulate_reduced(10, k=0.1, sigma=0.1, duration=10.0, dt=0.1, record_every=1000)

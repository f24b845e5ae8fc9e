"""The fitted phase model reproduces the full model's r_eq curve at N = 64."""

import numpy as np
import pytest

from metrosync import simulate
from metrosync.theory.fitted import simulate_fitted


@pytest.mark.slow
def test_reduced_model_matches_the_full_model_away_from_the_onset(tmp_path):
    # σ = 0.75 BPM: the onset at N = 64 is near 169 BPM (predicted and simulated).
    # 150 BPM is well below it, 185 well above (r ≈ 0.8). The full model runs with a
    # small step (the continuous-time model the coupling was measured on).
    runs, kw = 12, dict(sigma_bpm=0.75, duration=400.0, equilibrium_window=150.0, seed=3)
    for bpm in (150.0, 185.0):
        full = simulate(64, bpm, runs=runs, dt=0.002, **kw).r_eq.values
        fitted = simulate_fitted(64, bpm, runs=runs, dt=0.1, cache=tmp_path, **kw).r_eq.values
        sem = np.hypot(full.std(ddof=1), fitted.std(ddof=1)) / np.sqrt(runs)
        assert abs(full.mean() - fitted.mean()) < 2 * sem, (bpm, full.mean(), fitted.mean())
        if bpm < 169:
            assert fitted.mean() < 0.25  # finite-size noise
        else:
            assert fitted.mean() > 0.7  # partially locked


def test_fitted_model_uses_the_ensembles_draws(tmp_path):
    from metrosync import build_ensemble, get_preset
    from metrosync.theory import Coupling, disk_scale, tick_rate_bpm

    coupling = Coupling(
        bpm=192.0,
        n=32,
        k_cos=0.08,
        k_sin=-0.04,
        k_cos_err=0.0,
        k_sin_err=0.0,
        method="given",
        scale=disk_scale(32),
        free_bpm=184.7,
    )
    ds = simulate_fitted(16, 192.0, sigma_bpm=1.0, runs=3, duration=50.0, seed=9, coupling=coupling)
    ens = build_ensemble(16, 192.0, params=get_preset("default"), sigma_bpm=1.0, runs=3, seed=9)
    expected = tick_rate_bpm(get_preset("default").metronome, ens.l2, exact=False)
    np.testing.assert_allclose(ds.tick_bpm.values, expected)
    assert ds.r.values[0] == pytest.approx(
        np.abs(
            np.mean(np.exp(1j * np.arctan2(-ens.theta_dot0 / ens.system.omega, ens.theta0)), axis=1)
        )
    )
    # Rescaled from N = 32 to N = 16 by N/D₀(N).
    assert ds.attrs["k"] == pytest.approx(coupling.k * disk_scale(16) / disk_scale(32))
    assert ds.attrs["alpha"] == pytest.approx(coupling.alpha)

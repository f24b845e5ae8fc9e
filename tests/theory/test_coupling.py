"""The coupling of the reduced model: two measurements agree, the N law, the estimate."""

import math

import numpy as np
import pytest

from metrosync import ParameterError, get_preset, simulate
from metrosync.theory.coupling import disk_scale, measure_by_growth, measure_by_pair
from metrosync.theory.estimate import estimate

PARAMS = get_preset("default")


def agree(a: float, a_err: float, b: float, b_err: float) -> bool:
    """Within two combined standard errors."""
    return abs(a - b) <= 2 * math.hypot(a_err, b_err)


@pytest.mark.slow
@pytest.mark.parametrize("bpm", [176.0, 208.0])
def test_growth_and_pair_measure_the_same_coupling(bpm):
    growth = measure_by_growth(bpm, n=32).for_n(2)
    pair = measure_by_pair(bpm)
    assert agree(growth.k_cos, growth.k_cos_err, pair.k_cos, pair.k_cos_err)
    assert agree(growth.k_sin, growth.k_sin_err, pair.k_sin, pair.k_sin_err)
    # ...and the errors are not so wide that agreement is empty: a few per cent.
    assert growth.k_cos_err / growth.k_cos < 0.08 and pair.k_cos_err / pair.k_cos < 0.08
    assert abs(growth.k / pair.k - 1) < 0.1
    # Attractive (K cos α > 0), and the locked pair ticks faster than alone (α < 0).
    assert growth.k_cos > 0 and pair.k_cos > 0
    assert -0.6 < growth.alpha < -0.3 and -0.6 < pair.alpha < -0.3


@pytest.mark.slow
def test_coupling_scales_as_n_over_the_disk_inertia():
    # K ∝ N/D₀(N): measured at N = 16 and N = 64 the strength κ = K/(N/D₀) agrees.
    k16, k64 = (measure_by_growth(192.0, n=n) for n in (16, 64))
    assert disk_scale(64) / disk_scale(16) == pytest.approx(1.116, abs=0.002)
    assert k16.kappa == pytest.approx(k64.kappa, rel=0.04)
    assert k16.alpha == pytest.approx(k64.alpha, abs=0.03)


def test_coupling_grows_with_the_beat_frequency():
    low, high = (estimate(bpm, 64) for bpm in (160.0, 200.0))
    assert high.k > 2 * low.k  # ∝ (m R h ω)²: a lower slider, a larger h


def test_reactive_estimate_is_the_frequency_shift_of_one_metronome_on_the_disk():
    # For N = 1 the estimate's K sin α is −(1/2) μ ω ⟨cos²θ⟩, the first-order shift of a
    # pendulum on a free disk; check it against the model at a small swing (A ≈ 0.08 rad).
    params = PARAMS.with_changes(drive=6e-6)
    est = estimate(192.0, 1, params)
    design = params.metronome
    metronome = design.with_l2(design.l2_for_bpm(192.0))
    ticks = {}
    for name, changes in (("disk", None), ("rigid", {"inertia": math.inf})):
        ds = simulate(
            n=None,
            bpm=None,
            metronomes=[metronome],
            preset=params,
            changes=changes,
            theta0=[0.08],
            theta_dot0=[0.0],
            duration=120.0,
            dt=2.5e-4,
            trajectories=True,
            record_every=4,
        )
        theta, t = ds.theta.values[:, 0, 0], ds.time.values
        i = np.nonzero((theta[:-1] < 0) & (theta[1:] >= 0))[0]
        up = t[i] + (t[i + 1] - t[i]) * (-theta[i]) / (theta[i + 1] - theta[i])
        up = up[up > 60]
        ticks[name] = 2 * np.pi * (up.size - 1) / (up[-1] - up[0])
    assert ticks["disk"] - ticks["rigid"] == pytest.approx(-est.k_sin, rel=0.03)


@pytest.mark.slow
def test_analytic_estimate_is_within_a_fifth_of_the_measurement():
    measured = measure_by_growth(192.0, n=32)
    est = estimate(192.0, 32)
    assert est.k_cos == pytest.approx(measured.k_cos, rel=0.2)
    assert est.k_sin == pytest.approx(measured.k_sin, rel=0.2)


def test_disk_scale_and_its_limit():
    p = PARAMS.platform
    mass = PARAMS.metronome.mass
    assert disk_scale(7) == pytest.approx(7 / (p.disk_inertia(7) + 7 * mass * p.radius**2))
    limit = disk_scale(math.inf)
    assert limit == pytest.approx(1 / (p.j_per_metronome + mass * p.radius**2))
    assert disk_scale(10**6) == pytest.approx(limit, rel=1e-4)
    with pytest.raises(ParameterError, match=r"`n` = inf needs the J\(N\) law"):
        disk_scale(math.inf, PARAMS.with_changes(inertia=0.25515))
    with pytest.raises(ParameterError, match=r"`n` must be a whole number"):
        disk_scale(2.5)


def test_bad_input_is_named():
    with pytest.raises(ParameterError, match=r"`n` must be an integer in \[16, 256\]"):
        measure_by_growth(192.0, n=4)
    with pytest.raises(ParameterError, match=r"outgrow memory"):
        measure_by_growth(192.0, n=10_000)
    with pytest.raises(ParameterError, match=r"`points` must be an integer >= 4"):
        measure_by_pair(192.0, points=2)
    with pytest.raises(ParameterError, match=r"over the top"):
        estimate(192.0, 8, "boda2013")

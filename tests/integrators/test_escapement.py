"""The escapement's placement (``escapement_offset``) and reaction
(``escapement_reaction``): a metronome out of beat, measured against independent
calculations."""

import math

import numpy as np
import pytest
from scipy.special import ellipk, ellipkinc

from metrosync import Metronome, ParameterError, build_ensemble, get_preset, simulate
from metrosync.observables import platform_momentum

DELTA = 0.05  # rad: about 7 % of the default steady swing of 0.77 rad
RIGID = {"inertia": math.inf}


def level_crossings(ds, level):
    """Times at which θ (one metronome) crosses ``level``, linearly interpolated
    between records, and whether each crossing is upward."""
    theta = ds.theta.values[:, 0, 0] - level
    t = ds.time.values
    k = np.nonzero(theta[:-1] * theta[1:] < 0)[0]
    times = t[k] + (t[k + 1] - t[k]) * theta[k] / (theta[k] - theta[k + 1])
    return times, theta[k + 1] > 0


def tick_tock(ds, level, after):
    """Mean time above ``level`` (from an upward crossing to the next downward one) and
    below it, over the crossings after ``after`` s."""
    times, up = level_crossings(ds, level)
    times, up = times[times > after], up[times > after]
    if not up[0]:
        times = times[1:]
    gaps = np.diff(times)
    n = len(gaps) // 2
    return gaps[0 : 2 * n : 2].mean(), gaps[1 : 2 * n : 2].mean()


def one_out_of_beat(integrator, dt, duration=25.0, **changes):
    return simulate(
        1, 192, duration=duration, dt=dt, integrator=integrator, theta0=[0.76],
        changes={"escapement_offset": DELTA, **changes}, trajectories=True, record_every=1,
    )  # fmt: skip


def conservative_half_periods(omega0, delta, above, below):
    """Time a frictionless pendulum (small-angle frequency ``omega0``) spends above and
    below the angle ``delta`` when it swings to ``above`` on one side and ``below`` on
    the other: with θ = 2 arcsin(k sin ψ), k = sin(a/2), the time from θ to the turning
    point is (K(k) − F(ψ, k))/ω0 (Landau & Lifshitz §11)."""

    def to_turn(theta, amplitude):
        m = math.sin(amplitude / 2) ** 2
        psi = math.asin(math.sin(theta / 2) / math.sqrt(m))
        return (ellipk(m) - ellipkinc(psi, m)) / omega0

    return 2 * to_turn(delta, above), 2 * to_turn(-delta, below)


@pytest.fixture(scope="module")
def exact_rigid():
    return one_out_of_beat("exact", 0.001, **RIGID)


def test_out_of_beat_tick_and_tock_match_the_conservative_pendulum(exact_rigid):
    ds = exact_rigid
    short, long_ = tick_tock(ds, DELTA, after=5)
    late = ds.theta.sel(time=slice(5, None)).values[:, 0, 0]
    params = get_preset("default")
    omega0 = Metronome(params.metronome, params.metronome.l2_for_bpm(192)).natural_omega
    want_short, want_long = conservative_half_periods(omega0, DELTA, late.max(), -late.min())
    # The swing is clearly asymmetric (about 8 %) ...
    assert short / long_ == pytest.approx(0.921, abs=0.002)
    # ... and the asymmetry is the one the kick's place predicts: what is left is the
    # friction and kicks within each swing (measured 1.6e-4).
    assert short / long_ == pytest.approx(want_short / want_long, abs=5e-4)
    assert short == pytest.approx(want_short, rel=3e-3)
    assert long_ == pytest.approx(want_long, rel=3e-3)


def test_the_fixed_step_scheme_puts_tick_and_tock_where_exact_does(exact_rigid):
    want = np.divide(*tick_tock(exact_rigid, DELTA, after=5))
    fine = one_out_of_beat("verlet", 0.001, **RIGID)
    assert np.divide(*tick_tock(fine, DELTA, after=5)) == pytest.approx(want, abs=1e-4)
    # The paper's step quantises each kick to 0.01 s, a few parts in 10^4 of the ratio.
    coarse = one_out_of_beat("verlet", 0.01, duration=60.0, **RIGID)
    assert np.divide(*tick_tock(coarse, DELTA, after=5)) == pytest.approx(want, abs=1e-3)


def test_the_located_scheme_kicks_at_the_offset_inside_the_step(exact_rigid):
    """``located`` interpolates the crossing of δ, not of 0: at the paper's step its
    ratio is as close to ``exact``'s as ``verlet``'s at a tenth of the step."""
    want = np.divide(*tick_tock(exact_rigid, DELTA, after=5))
    got = one_out_of_beat("located", 0.01, duration=60.0, **RIGID)
    assert np.divide(*tick_tock(got, DELTA, after=5)) == pytest.approx(want, abs=1e-4)


@pytest.mark.parametrize("reaction", [True, False])
def test_on_a_free_disk_the_fixed_step_scheme_agrees_with_exact(reaction):
    changes = {"escapement_reaction": reaction}
    want = np.divide(*tick_tock(one_out_of_beat("exact", 0.001, 12.0, **changes), DELTA, 3))
    got = np.divide(*tick_tock(one_out_of_beat("verlet", 0.001, 12.0, **changes), DELTA, 3))
    assert got == pytest.approx(want, abs=2e-4)
    assert want < 0.93


def test_zero_crossings_still_define_the_phase_when_kicks_are_off_zero():
    kwargs = dict(duration=4.0, dt=0.001, theta0=[0.5, -0.3], record_every=10)
    for integrator in ("exact", "verlet", "located"):
        ds = simulate(2, 192, integrator=integrator, changes={"escapement_offset": 0.1}, **kwargs)
        # Phases are known from the second upward crossing to the last one.
        assert np.isfinite(ds.r_crossing.sel(time=slice(1.5, 3.0))).all(), integrator


def test_without_reaction_the_kicks_leave_the_disk_momentum_alone():
    """The disk's momentum p_φ = (J + R²Σm) φ̇ + R Σ m h cos θ θ̇ changes only by the
    torque F of eq. (metron2a). With a frictionless bearing, F is the escapement's
    reaction alone: each kick moves p_φ by ∓M with it, and not at all without it."""
    free = {"c_phi": 0.0}
    common = dict(duration=3.0, dt=0.001, theta0=[0.6], record_every=1, trajectories=True)
    params = get_preset("default").with_changes(**free)
    sys = build_ensemble(1, 192, params=params).system

    def momentum(ds):
        th, thd = ds.theta.values[:, 0, :], ds.theta_dot.values[:, 0, :]
        return platform_momentum(sys, th, thd, ds.phi_dot.values[:, 0])

    on = simulate(1, 192, changes=free, **common)
    off = simulate(1, 192, changes={**free, "escapement_reaction": 0}, **common)
    assert on.attrs["escapement_reaction"] == 1 and off.attrs["escapement_reaction"] == 0
    drive = params.metronome.drive
    assert np.ptp(momentum(on)) == pytest.approx(drive, rel=1e-6)
    assert np.ptp(momentum(off)) < 1e-9 * drive


def test_offset_and_reaction_are_checked():
    with pytest.raises(ParameterError, match=r"`escapement_offset` must lie in \(-pi/2, pi/2\)"):
        simulate(1, 192, duration=1, changes={"escapement_offset": 2.0})
    with pytest.raises(ParameterError, match="`escapement_reaction` must be true or false"):
        simulate(1, 192, duration=1, changes={"escapement_reaction": 0.5})

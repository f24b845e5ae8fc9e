"""The kick-located scheme: its layouts against its NumPy twin, its order against
``exact``, and its ensemble statistics at a large step."""

import math

import numpy as np
import pytest
from test_kernels import DEATH_OFFSET, features_for

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.integrators import REGISTRY, located, twin, verlet
from metrosync.integrators._state import StepState


def run(advance, ens, steps, *, dt=0.01, chunks=1, **kwargs):
    state = StepState.start(
        ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
        n_records=steps // 10 + 1, trajectories=True, group_start=ens.group_start,
    )  # fmt: skip
    per = steps // chunks
    for k in range(chunks):
        advance(state, ens.system, dt=dt, step0=k * per, n_steps=per, record_every=10,
                overturn_angle=math.pi / 2, **kwargs)  # fmt: skip
    return state


#: The features of the capability table that ``located`` runs (test_kernels).
LOCATED_FEATURES = features_for("located/numba")


@pytest.mark.parametrize("feature", sorted(LOCATED_FEATURES))
@pytest.mark.parametrize("layout", sorted(located.LAYOUTS))
@pytest.mark.parametrize("n, runs", [(3, 11), (20, 3)])  # 11 runs: a partly filled block
def test_every_layout_matches_the_numpy_twin_over_1000_steps(layout, n, runs, feature):
    options = {"params": get_preset("default"), "sigma_bpm": 2.0, **LOCATED_FEATURES[feature](n)}
    ens = build_ensemble(n, 192.0, runs=runs, seed=7, **options)
    ref = run(twin.LOCATED.advance_state, ens, 1000)
    got = run(located.advance_state, ens, 1000, layout=layout)
    assert np.count_nonzero(np.diff(np.sign(ref.traj_theta), axis=1)) > 50 * runs  # kicks
    names = ("theta", "theta_dot", "phi", "phi_dot", "p_phi", "acc_theta", "traj_theta", "r")
    for name in (*names, "r_group"):
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=0, atol=1e-10)
    for name in ("crossing_order", "group_crossing_order", "group_order"):
        np.testing.assert_allclose(getattr(got, name)(), getattr(ref, name)(), atol=1e-10)
    for name in ("status", "cross_count", "last_kick"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)
    fired = ref.last_kick >= 0
    if feature == "death":  # the escapements below the start swing never fired
        expected = np.broadcast_to(ens.theta0 > DEATH_OFFSET, fired.shape)
        np.testing.assert_array_equal(fired, expected)
    else:
        assert fired.all() and ref.last_kick.max() > 9.0, "some escapement stopped"


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_dry_friction_is_refused_by_name(backend):
    with pytest.raises(ParameterError, match=r"`disk_dry_friction` = 0.01 N m: integrator 'located' has no dry friction"):  # fmt: skip  # noqa: E501
        simulate(2, 192, duration=1.0, integrator="located", backend=backend,
                 changes={"disk_dry_friction": 0.01})  # fmt: skip


@pytest.mark.parametrize("layout", sorted(located.LAYOUTS))
def test_chunking_does_not_change_the_result(layout):
    ens = build_ensemble(4, 192.0, params=get_preset("default"), sigma_bpm=2.0, runs=17, seed=3)
    one = run(located.advance_state, ens, 600, layout=layout)
    many = run(located.advance_state, ens, 600, chunks=6, layout=layout)
    np.testing.assert_array_equal(one.traj_theta, many.traj_theta)
    np.testing.assert_array_equal(one.cross_re, many.cross_re)


def test_without_kicks_it_is_the_verlet_step():
    params = get_preset("default").with_changes(drive=0.0)
    ens = build_ensemble(5, 192.0, params=params, sigma_bpm=2.0, runs=3, seed=4, amplitude=0.5)
    ours = run(located.advance_state, ens, 500)
    theirs = run(verlet.advance_state, ens, 500)
    np.testing.assert_allclose(ours.traj_theta, theirs.traj_theta, rtol=0, atol=1e-12)


def test_located_has_its_declared_order_with_kicks():
    """Against ``exact`` over 5 s, N = 2, θ(0) = (0.1, −0.05), as ``verlet`` is measured
    in test_verlet.py (0.13, 0.017, 0.0011 rad there). Measured here: 9.5e-3, 9.5e-5,
    9.7e-7 rad, slope 2.00."""
    order, errors, _ = order_against_exact(frequencies_bpm=[192.0, 192.0])
    assert order == pytest.approx(REGISTRY["located"].order_with_kicks, abs=0.3), (order, errors)
    assert errors[0] < 0.02, errors  # verlet: 0.13 at dt = 0.01


def test_located_has_its_declared_order_with_kicks_on_the_board():
    board = {"frequencies_bpm": [208.0, 208.0], "preset": "pantaleone2002"}
    order, errors, exact = order_against_exact(**board)
    assert order == pytest.approx(REGISTRY["located"].order_with_kicks, abs=0.3), (order, errors)
    # The board moved the pendulums: on a rigid support they swing otherwise.
    held = get_preset("pantaleone2002").on_rigid_support()
    rigid = simulate(
        None,
        None,
        frequencies_bpm=[208.0, 208.0],
        preset=held,
        integrator="exact",
        theta0=[0.1, -0.05],
        duration=5.0,
        trajectories=True,
        record_every=10,
    )
    assert not np.allclose(rigid.theta.values, exact.theta.values, atol=1e-3)


def order_against_exact(**kw):
    """``located``'s measured order against ``exact`` over 5 s from θ(0) = (0.1, −0.05)
    at dt = 10⁻², 10⁻³, 10⁻⁴ s; its errors (rad) and the exact run."""
    kw = dict(theta0=[0.1, -0.05], duration=5.0, trajectories=True, **kw)
    exact = simulate(None, None, integrator="exact", dt=0.01, record_every=10, **kw)
    dts = np.array([0.01, 0.001, 0.0001])
    errors = []
    for dt in dts:
        ds = simulate(None, None, integrator="located", dt=dt, record_every=int(round(0.1 / dt)),
                      **kw)  # fmt: skip
        errors.append(np.max(np.abs(ds.theta.values - exact.theta.values)))
    return np.polyfit(np.log(dts), np.log(errors), 1)[0], errors, exact


def test_registered_with_both_cpu_backends_and_the_gpu():
    scheme = REGISTRY["located"]
    assert scheme.order == 2 and scheme.order_with_kicks == 2
    assert set(scheme.backends) == {"numba", "numpy", "gpu"} and scheme.fixed_step
    ds = simulate(3, 192, runs=2, duration=2, integrator="located", backend="numpy", seed=1)
    assert ds.attrs["integrator"] == "located" and np.isfinite(ds.r).all()


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::metrosync.budget.LongRunWarning")  # exact: about a minute
def test_r_eq_at_a_large_step_agrees_with_exact_as_well_as_verlet_at_a_quarter_of_it():
    """Ensemble mean and spread of r_eq: ``located`` at dt = 0.04 s against ``exact``, as
    close as ``verlet`` at dt = 0.01 s is (within the ensembles' standard error).
    Measured: exact 0.704 ± 0.244, located 0.679 ± 0.231, verlet 0.714 ± 0.232."""
    kw = dict(sigma_bpm=1.5, runs=12, duration=40.0, seed=5)
    stats = {}
    for name, integrator, dt in [
        ("exact", "exact", 0.04), ("located", "located", 0.04), ("verlet", "verlet", 0.01),
    ]:  # fmt: skip
        ds = simulate(3, 192.0, integrator=integrator, dt=dt, record_every=int(round(0.2 / dt)),
                      **kw)  # fmt: skip
        stats[name] = (float(ds.r_eq.mean()), float(ds.r_eq.std()))
    mean_exact, spread_exact = stats["exact"]
    error = spread_exact / math.sqrt(kw["runs"])
    off = {name: abs(stats[name][0] - mean_exact) for name in ("located", "verlet")}
    assert off["located"] <= max(off["verlet"], error), stats
    assert stats["located"][1] == pytest.approx(spread_exact, rel=0.5, abs=0.05), stats

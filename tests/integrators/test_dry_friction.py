"""Dry (Coulomb) friction on the disk: held exactly at rest below the threshold, no
chattering, the event-driven ``exact`` solution above it, and the scheme's pieces."""

import math

import numpy as np
import pytest

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.equations import SystemArrays, accelerations, dry_friction, holding_torque
from metrosync.integrators import kernel_cuda, twin, verlet
from metrosync.integrators._abi import constants_of
from metrosync.integrators._physics import disk_friction, disk_friction_stop, pendulum_terms
from metrosync.integrators._state import StepState

DT = 0.01
BACKENDS = {
    "runs": lambda *a, **k: verlet.advance_state(*a, layout="runs", **k),
    "metronomes": lambda *a, **k: verlet.advance_state(*a, layout="metronomes", **k),
    "numpy": twin.VERLET.advance_state,
}


def run(advance, ens, steps, dt=DT):
    state = StepState.start(
        ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
        n_records=steps + 1, trajectories=True,
    )  # fmt: skip
    advance(state, ens.system, dt=dt, step0=0, n_steps=steps, record_every=1,
            overturn_angle=math.pi / 2)  # fmt: skip
    return state.one_coordinate()  # the disk's state per run


def ensemble(changes, runs=3, n=3, seed=5):
    params = get_preset("default").with_changes(**changes)
    return build_ensemble(n, 192.0, params=params, sigma_bpm=2.0, runs=runs, seed=seed)


@pytest.mark.parametrize("backend", sorted(BACKENDS))
def test_below_the_threshold_the_disk_does_not_move(backend):
    # T = 0.2 N m: above the swinging pendulums' reaction (about 0.012 N m each) and
    # above the kick's torque M/dt (1 + R m h / I) (about 0.023 N m at dt = 0.01 s).
    held = ensemble({"disk_dry_friction": 0.2}, runs=17)  # 17 runs: the runs layout's block
    pinned = ensemble({"inertia": math.inf}, runs=17)
    got = run(BACKENDS[backend], held, 2000)
    assert np.all(got.traj_phi_dot == 0.0) and np.all(got.traj_phi == 0.0)
    assert np.all(got.phi_dot == 0.0) and np.all(got.acc_phi == 0.0)
    # The disk's angular momentum is that of a disk at rest, R Σ m h cos θ θ̇.
    coupling = held.system.one_coordinate().lever * np.sum(
        held.system.mh * np.cos(got.theta) * got.theta_dot, 1
    )
    np.testing.assert_allclose(got.p_phi, coupling, rtol=1e-13, atol=1e-18)
    # The pendulums move exactly as on a rigid support.
    rigid = run(BACKENDS[backend], pinned, 2000)
    np.testing.assert_array_equal(got.traj_theta, rigid.traj_theta)
    np.testing.assert_array_equal(got.traj_theta_dot, rigid.traj_theta_dot)
    assert np.ptp(got.traj_theta) > 1.0  # they did swing


def test_exact_holds_the_disk_below_the_threshold_without_kicks():
    kw = dict(duration=5, dt=0.01, trajectories=True, integrator="exact", record_every=1,
              theta0=[0.5, -0.3], theta_dot0=[0.0, 0.0])  # fmt: skip
    held = simulate(2, 192, changes={"drive": 0.0, "disk_dry_friction": 0.05}, **kw)
    rigid = simulate(2, 192, changes={"drive": 0.0, "inertia": math.inf}, **kw)
    assert np.all(held.phi_dot == 0.0) and np.all(held.phi == 0.0)
    np.testing.assert_array_equal(held.theta, rigid.theta)


def above_threshold(dt, integrator, case):
    """Metronomes whose reaction on the disk beats its dry friction T."""
    theta0, threshold, drive = CASES[case]
    return simulate(
        len(theta0), 192, duration=3.0, dt=dt, record_every=int(round(0.01 / dt)),
        integrator=integrator, trajectories=True, theta0=theta0, theta_dot0=[0.0] * len(theta0),
        changes={"disk_dry_friction": threshold, "drive": drive},
    )  # fmt: skip


#: θ(0), T (N m), M (N m s): one free-swinging metronome whose disk sticks and slips
#: (at rest about 40 % of the time), and two driven ones whose kicks jolt it.
CASES = {"stick-slip": ([0.5], 3e-3, 0.0), "with-kicks": ([0.5, 0.4], 1e-2, 6e-5)}


@pytest.mark.parametrize(
    "case, theta_tol, phi_tol, min_rest",
    [("stick-slip", 4e-5, 2e-5, 0.2), ("with-kicks", 1e-2, 6e-5, 0.01)],
)
def test_above_the_threshold_the_disk_follows_the_event_driven_solution(
    case, theta_tol, phi_tol, min_rest
):
    """Against ``exact`` (DOP853 with located stick, slip and kick events) over 3 s. The
    scheme resolves stops, reversals and kicks to the step: first order, so the error at
    dt = 1e-3 s is within the stated tolerance and falls about tenfold at dt = 1e-4 s
    (measured, θ and φ in rad: stick-slip 2.3e-5 → 2.2e-6 and 8.2e-6 → 8.6e-7; with
    kicks 6.4e-3 → 5.8e-4 and 4.4e-5 → 1.3e-6)."""
    ref = above_threshold(1e-3, "exact", case)
    at_rest = float((ref.phi_dot == 0).mean())
    assert min_rest < at_rest < 0.95, f"the disk is at rest {at_rest:.0%} of the time"
    assert float(np.abs(ref.phi).max()) > 10 * phi_tol  # the disk moved
    errors = []
    for dt in (1e-3, 1e-4):
        got = above_threshold(dt, "verlet", case)
        errors.append((float(np.abs(got.theta - ref.theta).max()),
                       float(np.abs(got.phi - ref.phi).max())))  # fmt: skip
    (theta_err, phi_err), (theta_fine, phi_fine) = errors
    assert theta_err < theta_tol and phi_err < phi_tol, errors
    assert theta_fine < theta_err / 5 and phi_fine < phi_err / 5, errors  # first order


def test_sticking_does_not_chatter():
    """Stick/slip transitions are the dynamics', not the step's: as many at every dt."""
    counts = []
    for dt in (0.01, 0.001, 0.0001):
        ds = simulate(1, 192, duration=5, dt=dt, record_every=1, trajectories=True,
                      theta0=[0.5], theta_dot0=[0.0],
                      changes={"drive": 0.0, "disk_dry_friction": 3e-3})  # fmt: skip
        rest = ds.phi_dot.values[:, 0] == 0.0
        counts.append(np.count_nonzero(np.diff(rest.astype(int))))
    assert counts[0] >= 4 and len(set(counts)) == 1, counts


def random_state(rng, sys, at_rest):
    theta = rng.uniform(-1, 1, sys.shape)
    theta_dot = rng.normal(0, 3, sys.shape)
    phi_dot = np.where(at_rest, 0.0, rng.normal(0, 0.01, sys.shape[0]))
    kick = rng.choice([-1.0, 0.0, 1.0], sys.shape) * sys.drive / DT
    return theta, theta_dot, phi_dot, kick


def test_scalar_friction_law_equals_the_vectorised_one(rng, random_system):
    sys = random_system(b=40, n=3)
    theta, theta_dot, phi_dot, kick = random_state(rng, sys, rng.random(40) < 0.7)
    holding = holding_torque(sys, theta, theta_dot, phi_dot, kick)
    # Thresholds from well below to well above each run's holding torque.
    sys = SystemArrays(**{**vars(sys), "dry_friction": np.abs(holding) * rng.uniform(0.3, 3, 40)})
    want = dry_friction(sys, phi_dot, holding)
    c = constants_of(sys)
    for b in range(40):
        sum_num = sum(
            pendulum_terms(c, (b, i), kick[b, i], math.sin(theta[b, i]), math.cos(theta[b, i]),
                           theta_dot[b, i])[2]
            for i in range(3)
        )  # fmt: skip
        others = -sys.one_coordinate().c_phi[b] * phi_dot[b] - kick[b].sum()
        got, held = disk_friction(c, b, phi_dot[b], sum_num, others)
        assert got == pytest.approx(want[b], rel=1e-10, abs=1e-16)
        assert held == (phi_dot[b] == 0 and abs(holding[b]) <= sys.dry_friction[b])
    # The law solves the equations: held runs do not accelerate, the others slip.
    phdd, _ = accelerations(sys, theta, theta_dot, phi_dot, kick)
    stays = (phi_dot == 0) & (np.abs(holding) <= sys.dry_friction)
    assert np.all(phdd[stays] == 0.0) and np.all(phdd[~stays] != 0.0)


def test_friction_at_a_stop_brings_the_step_to_rest(rng, random_system):
    """The end value `disk_friction_stop` solves for makes the step's end velocity 0,
    checked against the step computed independently with that friction."""
    sys = random_system(b=6, n=4)
    sys = SystemArrays(**{**vars(sys), "dry_friction": np.full(6, 1e3)})  # every stop holds
    theta, theta_dot, _, _ = random_state(rng, sys, np.ones(6, bool))
    no_kick = np.zeros(sys.shape)
    phi_dot = rng.normal(0, 1e-3, 6)
    p_phi, force_prev = rng.normal(0, 1e-3, 6), rng.normal(0, 1e-3, 6)
    acc = rng.normal(0, 1, sys.shape)

    flat = sys.one_coordinate()  # the disk's constants per run

    def end_velocity(friction):
        _, thdd = accelerations(sys, theta, theta_dot, phi_dot, no_kick, friction=friction)
        new_theta_dot = theta_dot + 0.5 * (acc + thdd) * DT
        p = p_phi + 0.5 * (force_prev - flat.c_phi * phi_dot + friction) * DT
        coupling = flat.lever * np.sum(sys.mh * np.cos(theta) * new_theta_dot, axis=1)
        return (p - coupling) / flat.total_inertia

    start = -1e-3 * np.sign(phi_dot)
    c = constants_of(sys)
    sum_den = np.sum(sys.mh**2 * np.cos(theta) ** 2 / sys.inertia, axis=1)
    for b, v in enumerate(end_velocity(start)):
        stop, held = disk_friction_stop(c, b, start[b], v, sum_den[b], DT)
        assert held
        friction = start.copy()
        friction[b] = stop
        assert abs(end_velocity(friction)[b]) < 1e-12 * abs(v) + 1e-17


def test_start_of_a_run_at_rest_is_held():
    ens = ensemble({"disk_dry_friction": 0.2})
    state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                            n_records=2, trajectories=False)  # fmt: skip
    assert np.all(state.acc_phi == 0.0)
    # The torque on the held disk is the pendulums' reaction, balanced by the friction.
    assert np.all(np.abs(state.force_phi) <= 0.2) and np.any(state.force_phi != 0.0)


def test_threshold_reaches_attrs_and_sweeps():
    ds = simulate(2, 192, duration=1, theta0=[0.2, -0.1], theta_dot0=[0.0, 0.0],
                  changes={"disk_dry_friction": 0.01})  # fmt: skip
    assert ds.attrs["disk_dry_friction"] == 0.01
    from metrosync.sweeps.grid import UNITS, canonical_name

    assert canonical_name("disk_dry_friction") == "disk_dry_friction"
    assert UNITS["disk_dry_friction"] == "N m"


@pytest.mark.parametrize("bad", [-1e-3, math.nan, math.inf])
def test_a_bad_threshold_is_refused_by_name(bad):
    with pytest.raises(ParameterError, match="`disk_dry_friction`"):
        get_preset("default").with_changes(disk_dry_friction=bad)


def test_gpu_backend_refuses_dry_friction_clearly():
    ens = ensemble({"disk_dry_friction": 0.01})
    state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                            n_records=2, trajectories=False)  # fmt: skip
    with pytest.raises(ParameterError, match="`disk_dry_friction`.*backend='numba'"):
        kernel_cuda.advance_state(state, ens.system, dt=DT, step0=0, n_steps=1,
                                  record_every=1, overturn_angle=1.5)  # fmt: skip


@pytest.mark.parametrize("integrator, backend", [("verlet", "numba"), ("verlet", "numpy"),
                                                 ("exact", "scipy")])  # fmt: skip
def test_disk_at_rest_is_the_fraction_of_the_final_window_the_disk_is_held(integrator, backend):
    """``disk_at_rest`` against the records of φ̇ (0 exactly while held) over the window,
    in the stick-slip case (at rest about 40 % of the time): the fixed-step count of
    held steps equals the records', ``exact`` sums its stuck intervals."""
    theta0, threshold, drive = CASES["stick-slip"]
    options = {} if integrator == "exact" else {"backend": backend}
    ds = simulate(1, 192, duration=3.0, dt=1e-3, record_every=1, trajectories=True,
                  equilibrium_window=1.5, theta0=theta0, theta_dot0=[0.0], integrator=integrator,
                  changes={"disk_dry_friction": threshold, "drive": drive}, **options)  # fmt: skip
    at_rest = float(ds.disk_at_rest[0])
    # Records in (1.5, 3] s: each the end of a step of the window.
    window = ds.phi_dot.sel(time=slice(1.5 + 1e-9, None)).values[:, 0]
    held = float(np.mean(np.abs(window) < 1e-12))
    assert 0.2 < held < 0.8, held
    if integrator == "exact":  # stuck intervals against the records that fall in them
        assert abs(at_rest - held) < 0.01, (at_rest, held)
    else:
        assert at_rest == pytest.approx(held, abs=1e-12)


@pytest.mark.slow
def test_the_docs_table_of_dry_friction_is_what_its_command_gives():
    """The docs' row for T = 0.03 N m, re-run with its command's settings (seconds)."""
    import re
    from pathlib import Path

    readme = (Path(__file__).parents[2] / "docs" / "beyond.md").read_text()
    row = re.search(r"^\| 0\.03 \| (\d+) % \| (0\.\d\d) ± (0\.\d\d) \|$", readme, re.MULTILINE)
    assert row, "docs/beyond.md's dry-friction table has no row for T = 0.03"
    command = "--runs 10 --duration 300 \\\n    --window 100 --seed 0 --set disk_dry_friction="
    assert command in readme
    ds = simulate(7, 184, sigma_bpm=0.75, runs=10, duration=300, equilibrium_window=100,
                  seed=0, changes={"disk_dry_friction": 0.03})  # fmt: skip
    assert round(100 * float(ds.disk_at_rest.mean())) == int(row[1])
    assert f"{ds.attrs['r_eq_mean']:.2f}" == row[2] and f"{ds.attrs['r_eq_std']:.2f}" == row[3]

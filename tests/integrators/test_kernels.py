"""Every kernel layout against the plain reference; vectorization; the compile cache."""

import math
import os
import re
import shutil
import subprocess
import sys
from functools import partial
from pathlib import Path

import numba as nb
import numpy as np
import pytest

from metrosync import build_ensemble, get_preset
from metrosync.capabilities import FEATURES as TABLE
from metrosync.capabilities import runs
from metrosync.integrators import _cache, layout_metronomes, layout_runs, layouts, twin, verlet
from metrosync.integrators._abi import constants_of, settings_of
from metrosync.integrators._state import StepState
from metrosync.integrators.trig import REDUCTION_LIMIT, sincos
from metrosync.model.platform import DISK_FIELDS
from metrosync.status import STATUS_DIVERGED


def run(advance, ens, steps, **kwargs):
    state = StepState.start(
        ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
        n_records=steps // 10 + 1, trajectories=True, group_start=ens.group_start,
    )  # fmt: skip
    advance(state, ens.system, dt=0.01, step0=0, n_steps=steps, record_every=10,
            overturn_angle=math.pi / 2, **kwargs)  # fmt: skip
    return state


#: Model features every layout must reproduce, switched on one at a time and all at once:
#: name -> keyword arguments of `build_ensemble` for n metronomes (``params`` included).
#: The model's terms are the capability table's (`metrosync.capabilities`), each with
#: its example values, so a term added there is tested here (and for every scheme that
#: runs it, `features_for`) without a line written here. The table's dry friction is
#: below the pendulums' reaction: stick-slip, with stops and reversals within steps.


DEATH_OFFSET = 0.45
#: The board's Coulomb force, N: about a tenth of the pendulums' reaction, so the board
#: sticks at the swing's ends and slips in between.
BOARD_DRY_FRICTION = 5e-3


def death_start(n):
    """Start swings from 0.2 to 0.8 rad at rest, θ̇ = 0: below and above `DEATH_OFFSET`."""
    return {"theta0": np.linspace(0.2, 0.8, n), "theta_dot0": np.zeros(n)}


def with_changes(**changes):
    return {"params": get_preset("default").with_changes(**changes)}


#: The table's run options, as ensembles: a new one must be given its builder here.
RUN_OPTIONS = {
    # Three groups at their own frequencies, the first of a single metronome.
    "groups": lambda n: {
        "groups": [(1, 184.0), ((n - 1) // 2, 192.0), (n - 1 - (n - 1) // 2, 200.0, 1.0)]
    },
    # Escapements beyond the start swing of the first metronomes: those never fire and
    # decay ("metronome death"), the others keep going.
    "death": lambda n: {**with_changes(escapement_offset=DEATH_OFFSET), **death_start(n)},
    "trajectories": None,  # every run here records them
}


def features_for(consumer: str) -> dict:
    """The features of the capability table that ``consumer`` runs, one at a time and
    all at once (``"all"``), with the baseline (``"plain"``)."""
    out = {"plain": lambda n: {}}
    together = {}
    for name, f in TABLE.items():
        if not runs(consumer, name):
            continue
        if f.kind == "model":
            out[name] = partial(lambda example, n: with_changes(**example), dict(f.example))
            if name != "board":  # the platform: "all" runs on each (below)
                together.update(f.example)
        elif RUN_OPTIONS[name] is not None:
            out[name] = RUN_OPTIONS[name]
    if "dry-friction" in out:  # ... and near the kick's torque: held, jolted, held again.
        out["dry-friction-held"] = lambda n: with_changes(disk_dry_friction=2e-2)
    out["all"] = lambda n: {**out["groups"](n), **with_changes(**together)}
    if "board" in out:
        # Every feature the board has: the disk's own parameters (its escapement
        # reaction, its dry friction) give way to the board's dry friction.
        on_board = {k: v for k, v in together.items() if k not in DISK_FIELDS}
        if "dry-friction" in out:
            on_board["board_dry_friction"] = BOARD_DRY_FRICTION
            out["board-dry-friction"] = lambda n: with_changes(
                platform="board", board_dry_friction=BOARD_DRY_FRICTION
            )
        out["all-on-board"] = lambda n: {
            **out["groups"](n),
            **with_changes(platform="board", **on_board),
        }
    return out


FEATURES = features_for("verlet/numba")


@pytest.mark.parametrize("feature", sorted(FEATURES))
@pytest.mark.parametrize("layout", sorted(verlet.LAYOUTS))
@pytest.mark.parametrize("n, runs", [(3, 11), (20, 3)])  # 11 runs: a partly filled block
def test_every_layout_matches_the_reference_over_1000_steps(layout, n, runs, feature):
    options = {"params": get_preset("default"), "sigma_bpm": 2.0, **FEATURES[feature](n)}
    ens = build_ensemble(n, 192.0, runs=runs, seed=7, **options)
    ref = run(twin.VERLET.advance_state, ens, 1000)
    got = run(verlet.advance_state, ens, 1000, layout=layout)
    for name in ("theta", "theta_dot", "phi", "phi_dot", "p_phi", "traj_theta", "r", "r_group"):
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=0, atol=1e-10)
    for name in ("crossing_order", "group_crossing_order", "group_order"):
        np.testing.assert_allclose(getattr(got, name)(), getattr(ref, name)(), atol=1e-10)
    for name in ("status", "cross_count", "last_kick", "rest_steps"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)
    fired = ref.last_kick >= 0
    if feature == "death":  # the escapements below the start swing never fired
        expected = np.broadcast_to(ens.theta0 > DEATH_OFFSET, fired.shape)
        np.testing.assert_array_equal(fired, expected)
    else:
        assert fired.all() and ref.last_kick.max() > 9.0, "some escapement stopped"
    if "dry" in feature:
        assert ref.rest_steps.max() > 0, "the platform was never held"
    elif not feature.startswith("all"):
        assert not ref.rest_steps.any()
    assert np.count_nonzero(ref.cross_count) > 0, "no crossing phase was booked"
    shape = (runs, 101, len(ens.group_start) - 1)
    assert ref.group_order().shape == got.group_order().shape == shape


@pytest.mark.parametrize("layout", sorted(verlet.LAYOUTS))
def test_a_run_diverged_from_the_start_records_nothing_in_any_layout(layout):
    theta_dot0 = np.zeros((3, 4))
    theta_dot0[1, 2] = 1e200  # θ̇² overflows in the very first force evaluation
    ens = build_ensemble(4, 192.0, params=get_preset("default"), runs=3, seed=2,
                         theta0=np.full((3, 4), 0.3), theta_dot0=theta_dot0)  # fmt: skip
    ref = run(twin.VERLET.advance_state, ens, 30)
    got = run(verlet.advance_state, ens, 30, layout=layout)
    assert ref.status[1] & STATUS_DIVERGED and np.isnan(ref.r[1]).all()
    np.testing.assert_array_equal(got.status, ref.status)
    for name in ("r", "traj_theta"):  # NaN (the same places) where nothing was recorded
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=0, atol=1e-10)


def test_layout_follows_the_problem():
    assert layouts.choose_layout(7, 100) == "runs"
    assert layouts.choose_layout(7, 4) == "metronomes"  # too few runs to fill a block
    assert layouts.choose_layout(64, 100) == "metronomes"


def test_far_wound_angles_fall_back_to_libm():
    # A pendulum wound past the fast reduction's range still gets exact trig.
    far = [2.5 * REDUCTION_LIMIT, 0.1, -0.1]
    params = get_preset("default")
    ens = build_ensemble(3, 192.0, params=params, runs=2, seed=1, theta0=far, theta_dot0=[0.0] * 3)
    ref = run(twin.VERLET.advance_state, ens, 200)
    for layout in ("runs", "metronomes"):
        got = run(verlet.advance_state, ens, 200, layout=layout)
        np.testing.assert_allclose(got.theta, ref.theta, rtol=1e-13, atol=1e-10)


def test_fast_sincos_is_within_two_ulp_of_libm(rng):
    @nb.njit
    def fill(x, s, c):
        for i in range(x.size):
            s[i], c[i] = sincos(x[i])

    for limit in (1.0, 100.0, REDUCTION_LIMIT):
        x = rng.uniform(-limit, limit, 200_000)
        s, c = np.empty_like(x), np.empty_like(x)
        fill(x, s, c)
        assert np.max(np.abs(s - np.sin(x)) / np.spacing(np.abs(np.sin(x)))) <= 2
        assert np.max(np.abs(c - np.cos(x)) / np.spacing(np.abs(np.cos(x)))) <= 2


def packed_double_ops(kernel, layout, fastmath, ens):
    """Recompile ``kernel`` (in ``layout``) without the cache and count AVX packed-double
    ops.

    Compiled serially: the kernel's prange over blocks only splits the outer loop
    among threads, and the loops inside it, the ones that must vectorize, go through
    the same LLVM passes either way (326 and 208 packed ops serially, 605 and 318 with
    the outer loop outlined for threads), in less than half the compile time (31 s
    against 68 s for both kernels on the 2-core machine)."""
    state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                            n_records=2, trajectories=False)  # fmt: skip
    fresh = nb.njit(parallel=False, fastmath=fastmath)(kernel.py_func)
    settings = settings_of(dt=0.01, step0=0, n_steps=10, record_every=10, overturn_angle=1.5)
    constants = layout.arrange(constants_of(ens.system))
    fresh(state.kernel_state(), constants, settings, state.kernel_recording())
    asm = "\n".join(fresh.inspect_asm().values())
    return len(re.findall(r"\tv\w+pd\t[^\n]*%[yz]mm", asm))


@pytest.mark.slow
@pytest.mark.parametrize(
    "kernel, layout, fastmath",
    [
        (verlet.advance_runs, layout_runs, False),
        (verlet.advance_metronomes, layout_metronomes, layout_metronomes.FASTMATH),
    ],
)
def test_hot_loops_are_vectorized(kernel, layout, fastmath):
    ens = build_ensemble(5, 192.0, params=get_preset("default"), runs=3, seed=1)
    count = packed_double_ops(kernel, layout, fastmath, ens)
    assert count >= 100, (
        f"{kernel.__name__} in {layout.__name__}: only {count} AVX packed-double instructions "
        f"in the generated code; the hot loop no longer vectorizes (a branch, a call or a "
        f"float reduction in it?). Inspect with `inspect_asm()` on a fresh, uncached njit of "
        f"the kernel."
    )


@pytest.mark.slow
def test_a_corrupt_compile_cache_is_rebuilt_not_used(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "NUMBA_NUM_THREADS": "1"}
    code = (
        "import metrosync as ms; ds = ms.simulate(3, 192, runs=2, duration=5, seed=1); "
        "print(repr(float(ds.r.isel(time=-1).sum())))"
    )
    # This run's compiled kernels, where they are cached already, start the cache (the
    # first run loads them instead of compiling them once more); else it compiles them.
    ours = _cache.kernel_cache_dir()
    if ours.is_dir():
        shutil.copytree(ours, tmp_path / "cache" / ours.relative_to(nb.config.CACHE_DIR))
    first = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    files = [p for p in Path(tmp_path / "cache").rglob("*") if p.is_file()]
    assert any(p.name.startswith("verlet.advance_") for p in files), "no cached kernel"
    for path in files:
        path.write_bytes(b"\x00garbage" * 7)
    again = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert again.stdout == first.stdout
    # A kernel source that changed (here: a stamp that no longer matches) purges the
    # cache before the first kernel call; what follows is the cold compile run above.
    index = sorted(Path(tmp_path / "cache").rglob("verlet.advance_*-*.nbi"))
    assert index, "the kernel was not cached again"
    (stamp,) = Path(tmp_path / "cache").rglob("metrosync-kernels.stamp")
    assert stamp.parent == index[0].parent  # beside this install's kernels, not others'
    stamp.write_text("an older source")
    heal = "from metrosync.integrators import _cache; print(len(_cache.heal_compile_cache()))"
    third = subprocess.run([sys.executable, "-c", heal], env=env, capture_output=True, text=True)
    assert third.returncode == 0 and int(third.stdout) >= len(index), third.stderr
    assert not any(path.exists() for path in index)
    assert stamp.read_text() == _cache.source_stamp()  # and the cache is current again


@pytest.mark.slow
def test_every_layout_gives_the_same_ensemble_statistics():
    """Over a long horizon rounding differences may grow; the statistics must not move."""
    from metrosync.observables import ensemble_statistics, equilibrium_order

    ens = build_ensemble(7, 184.0, params=get_preset("default"), sigma_bpm=0.75, runs=48, seed=2)
    steps = 30_000  # 300 s
    stats = {}
    backends = {layout: partial(verlet.advance_state, layout=layout) for layout in verlet.LAYOUTS}
    backends["numpy"] = twin.VERLET.advance_state
    for name, advance in backends.items():
        state = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                                n_records=steps // 10 + 1, trajectories=False)  # fmt: skip
        advance(state, ens.system, dt=0.01, step0=0, n_steps=steps, record_every=10,
                overturn_angle=math.pi / 2)  # fmt: skip
        time = np.arange(steps // 10 + 1) * 0.1
        stats[name] = ensemble_statistics(equilibrium_order(state.crossing_order().T, time, 75.0))
    mean_ref, spread_ref = stats["numpy"]
    standard_error = spread_ref / np.sqrt(ens.runs)
    for layout, (mean, spread) in stats.items():
        assert abs(mean - mean_ref) < 3 * standard_error, (layout, stats)
        assert spread == pytest.approx(spread_ref, rel=0.3), (layout, stats)

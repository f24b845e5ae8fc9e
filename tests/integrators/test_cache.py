"""The compile cache: where it lives, how a cold one is announced and kept out of
throughputs, and the guard that covers every source the compiled kernels depend on."""

import importlib
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numba as nb
import pytest

from metrosync.integrators import _cache, layout_metronomes, layout_runs, located, verlet


def modules_compiled_into(module, seen=None) -> set[str]:
    """Files of every metrosync module whose compiled functions or frozen globals
    ``module``'s kernels use, followed through the compiled functions they call."""
    seen = set() if seen is None else seen
    if module.__name__ in seen:
        return seen
    seen.add(module.__name__)
    for value in vars(module).values():
        origin = getattr(getattr(value, "py_func", None), "__module__", None)
        if isinstance(value, nb.core.registry.CPUDispatcher) and origin.startswith("metrosync"):
            modules_compiled_into(sys.modules[origin], seen)
    for name in vars(module):
        if name.startswith("STATUS_"):
            seen.add("metrosync.status")
    return seen


def test_stamp_covers_every_module_the_kernels_use():
    stamped = {path.resolve() for path in _cache.stamped_sources()}
    for kernel in (verlet, located, layout_runs, layout_metronomes):
        for name in modules_compiled_into(kernel):
            path = Path(sys.modules[name].__file__).resolve()
            assert path in stamped, f"{kernel.__name__} uses {name}, which the stamp misses"


def test_every_module_of_the_package_counts_as_ours(tmp_path):
    folder = tmp_path / "__pycache__"
    folder.mkdir()
    for name in ("_physics.pendulum_terms-60.py311.nbi", "verlet.advance_runs-57.py311.1.nbc",
                 "trig.sincos-53.py311.nbi"):  # fmt: skip
        assert _cache._ours(folder / name)
    assert not _cache._ours(folder / "somebody_else.f-1.py311.nbi")


def python(code: str, **env: str) -> list[str]:
    """Run ``code`` in a fresh interpreter with ``env`` (None removes a variable)."""
    environ = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environ.update(env)
    done = subprocess.run([sys.executable, "-c", code], env=environ, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


WHERE = (
    "import os, metrosync, numba; print(os.environ.get('NUMBA_CACHE_DIR'), numba.config.CACHE_DIR)"
)


def test_the_compiled_kernels_live_in_the_user_s_cache_folder(tmp_path):
    """A reinstall replaces the package's folder; the compiled kernels are kept outside."""
    user = tmp_path / "xdg" / "metrosync" / "numba"
    assert python(WHERE, XDG_CACHE_HOME=str(tmp_path / "xdg")) == [f"{user} {user}"]
    assert user.is_dir()
    # numba imported first (by the user's own code) still takes it
    first = WHERE.replace("import os, metrosync, numba", "import numba, os, metrosync")
    assert python(first, XDG_CACHE_HOME=str(tmp_path / "xdg")) == [f"{user} {user}"]
    # the user's own NUMBA_CACHE_DIR is honoured
    mine = tmp_path / "mine"
    assert python(WHERE, NUMBA_CACHE_DIR=str(mine), XDG_CACHE_HOME=str(tmp_path / "xdg")) == [
        f"{mine} {mine}"
    ]
    # a cache folder that cannot be made leaves numba's default, beside the sources
    (tmp_path / "a-file").write_text("")
    assert python(WHERE, XDG_CACHE_HOME=str(tmp_path / "a-file")) == ["None "]


def test_the_kernel_folder_is_numba_s_own_for_this_package(tmp_path, monkeypatch):
    monkeypatch.setattr(nb.config, "CACHE_DIR", str(tmp_path))
    folder = _cache.kernel_cache_dir()
    assert folder.parent == tmp_path and folder.name.startswith("integrators_")
    assert _cache._folder_of(verlet.advance_runs) == folder
    assert _cache.kernel_name(verlet.advance_runs) == "verlet.advance_runs"
    assert not _cache.is_cached(verlet.advance_runs)
    folder.mkdir()
    (folder / "verlet.advance_runs-72.py311.nbi").write_bytes(b"")
    assert _cache.is_cached(verlet.advance_runs)
    assert not _cache.is_cached(verlet.advance_metronomes)


def test_a_sweep_point_s_seconds_leave_out_compiling(monkeypatch):
    """A point whose simulation spent most of its time compiling reports the rest."""
    from metrosync.sweeps import executors

    def compiles_then_fails(**kwargs):
        time.sleep(0.3)
        monkeypatch.setattr(_cache, "_compile_seconds", _cache.compile_seconds() + 0.25)
        raise RuntimeError("a point that fails is timed too")

    # the module, loaded here: run alone, nothing has imported it yet
    module = importlib.import_module("metrosync.simulate")
    monkeypatch.setattr(module, "simulate", compiles_then_fails)
    spec = SimpleNamespace(key="k", kwargs={"runs": 2}, keep="run_mean_r")
    executors.run_point(spec)  # the first call also imports what a failed point needs
    ds, seconds, _ = executors.run_point(spec)
    assert "a point that fails" in ds.attrs["error"]
    assert 0.03 < seconds < 0.2, seconds


@pytest.mark.slow
def test_a_cold_cache_is_announced_once_and_left_out_of_the_throughput(tmp_path):
    code = (
        "import sys; from metrosync.cli import main; "
        "sys.exit(main(['simulate', '--n', '3', '--runs', '2', '--duration', '5']))"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "NUMBA_NUM_THREADS": "1"}
    runs = [subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                           timeout=600) for _ in range(2)]  # fmt: skip
    for done in runs:
        assert done.returncode == 0, done.stderr
    cold, warm = runs
    announced = [line for line in cold.stderr.splitlines() if "compiling kernels" in line]
    assert len(announced) == 1, cold.stderr
    assert re.fullmatch(r"metrosync: compiling kernels, once: about \d+ s \(kept in .+\)",
                        announced[0]), announced  # fmt: skip
    assert "compiling" not in warm.stderr + warm.stdout
    pattern = r"([\d.]+) s wall(?: \(([\d.]+) s of it compiling kernels, once\))?, ([\d.e+]+) osc"
    (wall, compiling, cold_rate), (_, none, warm_rate) = (
        re.search(pattern, done.stdout).groups() for done in runs
    )
    assert none is None and float(compiling) > 0.5 * float(wall)
    # Compiling took seconds, the simulation milliseconds: counted in, the cold rate would
    # be hundreds of times the warm one's inverse.
    assert float(cold_rate) > float(warm_rate) / 20, (cold_rate, warm_rate)


def test_the_warm_up_compiles_both_layouts_of_each_scheme_it_is_given(capsys):
    from metrosync.integrators import warm_up

    assert warm_up.main(["verlet", "located"]) == 0  # a cold cache compiles, a warm one loads
    for kernel in (verlet.advance_runs, verlet.advance_metronomes, located.advance_runs,
                   located.advance_metronomes):  # fmt: skip
        assert _cache.is_cached(kernel), _cache.kernel_name(kernel)
    assert warm_up.main(["leapfrog"]) == 2
    assert "unknown scheme 'leapfrog': choose from verlet, located" in capsys.readouterr().err

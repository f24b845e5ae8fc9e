"""The compile-cache guard covers every source the compiled kernels depend on."""

import sys
from pathlib import Path

import numba as nb

from metrosync.integrators import _cache, kernel_oscillators, kernel_runs


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
    for kernel in (kernel_runs, kernel_oscillators):
        for name in modules_compiled_into(kernel):
            path = Path(sys.modules[name].__file__).resolve()
            assert path in stamped, f"{kernel.__name__} uses {name}, which the stamp misses"


def test_every_module_of_the_package_counts_as_ours(tmp_path):
    folder = tmp_path / "__pycache__"
    folder.mkdir()
    for name in ("_physics.pendulum_terms-60.py311.nbi", "kernel_runs.advance-57.py311.1.nbc",
                 "trig.sincos-53.py311.nbi"):  # fmt: skip
        assert _cache._ours(folder / name)
    assert not _cache._ours(folder / "somebody_else.f-1.py311.nbi")

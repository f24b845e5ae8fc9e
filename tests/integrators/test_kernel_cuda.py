"""The GPU kernels (``verlet`` and ``located``), checked in numba's CUDA simulator (no
GPU needed), and the clear refusal of ``backend="gpu"`` on a machine without one."""

import os
import subprocess
import sys

import pytest

from metrosync import ParameterError, simulate
from metrosync.capabilities import runs
from metrosync.integrators import REGISTRY, kernel_cuda, load_backend

SIMULATED_CHECK = """
import math
import sys
# The simulator runs each CUDA thread as a Python thread and busy-polls them at every
# syncthreads(), holding the GIL for a whole switch interval (5 ms) per poll: a short
# interval makes the same check about eight times faster.
sys.setswitchinterval(5e-5)
import threading
import traceback
import numpy as np
from numba import types
from numba.cuda.simulator import kernelapi
from numba.np import numpy_support

# The simulator keys a static shared array by the line that asks for it and creates it on
# first use with no lock, so two threads that ask at once can each get an array of their
# own (a race of the simulator, not of the kernel: CI met it once at this switch
# interval). The same lookup under a lock:
_first_use = threading.Lock()

def shared_array(self, shape, dtype):
    caller = tuple(traceback.extract_stack(sys._getframe(1), limit=1)[0])[:2]
    with _first_use:
        if caller not in self._allocations:
            dtype = numpy_support.as_dtype(dtype) if isinstance(dtype, types.Type) else dtype
            self._allocations[caller] = np.empty(shape, dtype)
        return self._allocations[caller]

kernelapi.FakeCUDAShared.array = shared_array
from metrosync import build_ensemble, get_preset
from metrosync.capabilities import FEATURES as TABLE, UnsupportedFeature, runs
from metrosync.integrators import kernel_cuda, twin
from metrosync.integrators._state import StepState

SCHEME = sys.argv[1]  # verlet or located
ON_GPU, REFERENCE = getattr(kernel_cuda, SCHEME.upper()), getattr(twin, SCHEME.upper())
CONSUMER = f"{SCHEME}/gpu"

def run(advance, **kw):
    st = StepState.start(ens.system, ens.theta0, ens.theta_dot0, ens.phi0, ens.phi_dot0,
                         n_records=13, trajectories=False, group_start=ens.group_start)
    for c in range(2):  # two chunks: the state must survive the round trip to the device
        advance(st, ens.system, dt=0.01, step0=60 * c, n_steps=60, record_every=10,
                overturn_angle=math.pi / 2, **kw)
    return st

# 4 threads for 5 metronomes: each thread strides over two of them; then two groups,
# then the features beyond the paper that the capability table says the GPU runs (its
# kernel compiles the same _physics functions), all at once.
# Last, escapements beyond the start swing of two metronomes: they never fire.
# The platform is one of them: every other feature runs on the disk, and those the board
# has (the disk's own parameters left out) on the board.
from metrosync.model.platform import DISK_FIELDS
FEATURES = {k: v for name, f in TABLE.items() if f.kind == "model" and runs(CONSUMER, name)
            and name != "board" for k, v in f.example.items()}
ON_BOARD = {"platform": "board", **{k: v for k, v in FEATURES.items() if k not in DISK_FIELDS}}
assert runs(CONSUMER, "board")
DEATH = ({"escapement_offset": 0.45}, {"theta0": [0.2, 0.3, 0.5, 0.6, 0.7],
                                        "theta_dot0": [0.0] * 5})
for groups, changes, start in ((None, {}, {}), ([(2, 186.0), (3, 198.0)], {}, {}),
                               (None, FEATURES, {}), (None, ON_BOARD, {}), (None, *DEATH)):
    params = get_preset("default").with_changes(**changes)
    ens = build_ensemble(5, 192.0, params=params, sigma_bpm=2.0, runs=2, seed=3,
                         groups=groups, **start)
    gpu = run(ON_GPU.advance_state, threads=4)
    ref = run(REFERENCE.advance_state)
    assert np.count_nonzero(ref.cross_count) > 0, "no crossing was booked"
    for name in ("theta", "theta_dot", "phi", "phi_dot", "p_phi", "r", "r_group", "cross_count",
                 "last_kick"):
        np.testing.assert_allclose(getattr(gpu, name), getattr(ref, name), rtol=0, atol=1e-9)
    fired = (ref.last_kick >= 0).all(axis=0)
    assert fired.tolist() == ([False, False, True, True, True] if start else [True] * 5)
    for name in ("crossing_order", "group_crossing_order", "group_order"):
        np.testing.assert_allclose(getattr(gpu, name)(), getattr(ref, name)(), atol=1e-9)
    np.testing.assert_array_equal(gpu.status, ref.status)

# A run that diverges at its start records nothing, as in every CPU backend.
theta_dot0 = np.zeros((2, 3))
theta_dot0[1, 0] = 1e200
ens = build_ensemble(3, 192.0, params=get_preset("default"), runs=2, seed=3,
                     theta0=np.full((2, 3), 0.3), theta_dot0=theta_dot0)
gpu = run(ON_GPU.advance_state, threads=4)
ref = run(REFERENCE.advance_state)
assert ref.status[1] & 2 and np.isnan(ref.r[1]).all()
np.testing.assert_array_equal(gpu.status, ref.status)
np.testing.assert_allclose(gpu.r, ref.r, rtol=0, atol=1e-9)  # NaN in the same places

# The model features the table says it lacks, it refuses by name.
for name, f in TABLE.items():
    if f.kind == "model" and not runs(CONSUMER, name):
        params = get_preset("default").with_changes(**f.example)
        ens = build_ensemble(3, 192.0, params=params, runs=2, seed=3)
        try:
            run(ON_GPU.advance_state, threads=4)
        except UnsupportedFeature as refused:
            assert refused.feature == name and f.parameters[0] in str(refused), refused
        else:
            raise AssertionError(f"the GPU kernel ran {name}")
print("ok")
"""


#: Every scheme the registry runs on the GPU.
ON_GPU = [name for name, scheme in REGISTRY.items() if "gpu" in scheme.backends]


@pytest.mark.slow
@pytest.mark.parametrize("scheme", ON_GPU)
def test_gpu_kernel_matches_the_reference_in_the_cuda_simulator(scheme):
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    done = subprocess.run([sys.executable, "-c", SIMULATED_CHECK, scheme], env=env,
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-3000:]


@pytest.mark.skipif(kernel_cuda.gpu_available(), reason="this machine has a GPU")
def test_gpu_backend_without_a_gpu_says_what_is_missing():
    with pytest.raises(ParameterError, match=r"`backend` 'gpu' needs an NVIDIA GPU.*numba"):
        simulate(3, 192, runs=2, duration=1, backend="gpu")


def test_threads_per_block_cover_the_metronomes():
    assert kernel_cuda.threads_for(2) == 32
    assert kernel_cuda.threads_for(100) == 128
    assert kernel_cuda.threads_for(10_000) == kernel_cuda.MAX_THREADS


def test_both_fixed_step_schemes_run_on_the_gpu_each_declared_in_the_table():
    assert ON_GPU == ["verlet", "located"]
    for name in ON_GPU:
        assert load_backend(REGISTRY[name].modules["gpu"]).name == name
        assert runs(f"{name}/gpu", "board") and not runs(f"{name}/gpu", "trajectories")

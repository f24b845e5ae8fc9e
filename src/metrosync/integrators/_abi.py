"""The one argument list of every compiled fixed-step kernel: four NamedTuples.

Every CPU layout and the GPU kernel is called as ``advance(state, constants, settings,
recording)``; numba compiles a NamedTuple of arrays as a plain struct, so this costs
nothing over positional arguments.

``State``      what a step changes, (B, N) and (B,) arrays, updated in place: the
               platform's (B, P) state seen as its one coordinate (views, so that the
               kernels' writes land in `StepState`; `StepState.kernel_state`).
``Constants``  every field of `SystemArrays` (so a new model constant reaches the
               kernels without touching this file), plus what each step reuses:
               ``inv_inertia`` = 1/(m h² + J_i). Nothing here depends on the step:
               a scheme makes its own use of ``drive`` (`layouts`). Per-metronome
               fields are (B, N), per-run fields (B,), the platform's too (the kernels
               run one coordinate, `one_coordinate`); a layout may rearrange them
               (`layout_runs.arrange`), never rename them.
``Settings``   the scalars of one call: step, first step, step count, record spacing,
               overturn angle.
``Recording``  the record buffers, (B, n_rec) and trajectories (B, n_rec, N), or
               (0, 0, 0) placeholders when trajectories are not kept; the
               crossing-phase sums and ``r_group`` are per group, (B, n_rec, G)
               (``r_group`` a (0, 0, 0) placeholder for one group, whose r is ``r``),
               and ``group_start`` (G + 1,) bounds the groups' contiguous metronomes.

numba issues 5872/7135/10338 (open in 0.68): a write through a NamedTuple field inside
``prange`` can be silently lost. A kernel therefore unpacks every array it writes
into a local name before its parallel loop; reading through a field is safe. The
equivalence tests (every layout against the NumPy reference) guard this.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import fields
from typing import NamedTuple

import numpy as np

from ..model.system import SystemArrays


class State(NamedTuple):
    """Integration state, see `StepState` for the meaning of each field."""

    theta: np.ndarray
    theta_dot: np.ndarray
    phi: np.ndarray
    phi_dot: np.ndarray
    acc_theta: np.ndarray
    acc_phi: np.ndarray
    p_phi: np.ndarray
    force_phi: np.ndarray
    last_up: np.ndarray
    status: np.ndarray
    last_kick: np.ndarray
    rest_steps: np.ndarray


#: Fields of `Constants` that are not in `SystemArrays`: derived once per call.
DERIVED_CONSTANTS = ("inv_inertia",)

#: The model's constants as the kernels read them (generated from `SystemArrays`).
Constants = namedtuple(
    "Constants", [f.name for f in fields(SystemArrays)] + list(DERIVED_CONSTANTS)
)


class Settings(NamedTuple):
    dt: float
    step0: int
    n_steps: int
    record_every: int
    overturn_angle: float


class Recording(NamedTuple):
    r: np.ndarray
    cross_re: np.ndarray
    cross_im: np.ndarray
    cross_count: np.ndarray
    traj_theta: np.ndarray
    traj_theta_dot: np.ndarray
    traj_phi: np.ndarray
    traj_phi_dot: np.ndarray
    r_group: np.ndarray
    group_start: np.ndarray


def constants_of(sys: SystemArrays):
    """The kernels' `Constants`: C-contiguous float arrays, the platform's per run (the
    kernels run a platform of one coordinate, `SystemArrays.one_coordinate`)."""
    flat = one_coordinate(sys)
    arrays = {
        f.name: np.ascontiguousarray(getattr(flat, f.name), dtype=float)
        for f in fields(SystemArrays)
    }
    # The same expression as the NumPy twin (1/I is exact to rounding).
    arrays["inv_inertia"] = 1.0 / arrays["inertia"]
    return Constants(**arrays)


def one_coordinate(sys: SystemArrays):
    """``sys`` with the platform's constants per run (`SystemArrays.one_coordinate`).
    Any other platform is refused by name before a kernel is reached
    (`metrosync.capabilities`, feature ``platform-coordinates``)."""
    flat = sys.one_coordinate()
    if flat is None:
        raise ValueError(
            "the kernels' constants are for a platform of one coordinate; "
            "`capabilities.require` refuses any other before a kernel runs"
        )
    return flat


def settings_of(*, dt, step0, n_steps, record_every, overturn_angle) -> Settings:
    return Settings(float(dt), int(step0), int(n_steps), int(record_every), float(overturn_angle))

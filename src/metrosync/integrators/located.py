"""The kick-located fixed-step scheme (``integrator="located"``), compiled with numba.

``verlet`` puts the escapement's impulse into the forces as a torque ±M/dt at the
step's end, so the kick lands up to a step late: first order with kicks. This scheme
takes the same steps (see `verlet`) with no kick torque in the forces, and applies
each impulse where it belongs. In a step where metronome k's escapement fires
(θ_k crosses its escapement angle, `_physics.escapement_angle`):

1. locate   the crossing at σ_k = dt θ_k/(θ_k − θ_k'), linear between the step's
            ends (an O(dt²) error in the instant, as in the crossing phases); the
            step splits there into s_k = σ_k/dt and τ_k = dt − σ_k.
2. impulse  M exactly: angular momentum ±M to pendulum k, the reaction ∓M to the
            disk's momentum p_φ, and the velocity jumps that follow, solved at the
            crossing: pendulum k at its escapement angle, the others' geometry
            (m h cos θ_j and Σ m²h²cos²θ_j/I_j) interpolated between the step's ends.
            Pendulum k jumps by M/I_k, the disk by Δφ̇_k, every pendulum j by
            −R m_j h_j cos θ_j Δφ̇_k / I_j (`_located_parts.kick`).
3. finish   the jumps travel for τ_k: the positions move by τ_k × jump; and the
            velocity-dependent forces (c_θ θ̇, the θ̇² sin θ term, c_φ φ̇) change by the
            jump, evaluated at the step's end: that change J acts for τ_k in this step
            and is part of the accelerations the next step starts from.

Several impulses in one step add up. Every term above is computed to O(dt²) per
impulse, and a run has O(1) impulses per unit time, so the scheme is second order
with kicks (measured: tests/integrators/test_located.py; without kicks it is the
``verlet`` step exactly). One effect is left out: the friction that the other
pendulums' small jumps through the disk add over τ_k. It is first order, but smaller
than the kick's own terms by the coupling R²m²h²/(I (J + R²Σm)) (3×10⁻³ for the
default metronomes) and shows only below dt ≈ 10⁻⁴ s.

The cost is a scalar pass over the impulses of a step and, in a step that has any,
a few more terms in the second pass; the layouts are `kernel_located_runs` and
`kernel_located_oscillators`, picked as for ``verlet``. Its NumPy twin is
`reference_located`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import kernel_located_oscillators, kernel_located_runs
from ._abi import constants_of, settings_of
from ._cache import heal_compile_cache
from ._state import StepState
from .verlet import choose_layout

#: Kernel modules by memory layout, picked as for ``verlet`` (`verlet.choose_layout`).
LAYOUTS = {"runs": kernel_located_runs, "oscillators": kernel_located_oscillators}


class KickState(NamedTuple):
    """What the scheme carries from step to step beyond `State`.

    q : (B, N) m h cos θ at the last force evaluation: the geometry at a step's
        start, between which and its end the impulses interpolate.
    """

    q: np.ndarray


def kick_state(state: StepState, sys) -> KickState:
    """The `KickState` of ``state``, made from its angles on first use."""
    if state.scheme_state is None:
        state.scheme_state = KickState(q=np.ascontiguousarray(sys.mh * np.cos(state.theta)))
    return state.scheme_state


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout=None
):
    """Advance ``state`` by ``n_steps`` steps from ``step0`` with the kernel for
    ``layout`` (default: chosen from the problem's size, as for ``verlet``)."""
    heal_compile_cache()
    kernel = LAYOUTS[layout or choose_layout(state.theta.shape[1], state.theta.shape[0])]
    kernel.advance(
        state.kernel_state(),
        kernel.arrange(constants_of(sys, dt)),
        settings_of(
            dt=dt,
            step0=step0,
            n_steps=n_steps,
            record_every=record_every,
            overturn_angle=overturn_angle,
        ),
        state.kernel_recording(),
        kick_state(state, sys),
    )

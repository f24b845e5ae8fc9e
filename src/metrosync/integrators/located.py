"""The kick-located fixed-step scheme (``integrator="located"``), compiled with numba.

``verlet`` puts the escapement's impulse into the forces as a torque ±M/dt at the
step's end, so a kick lands up to a step late: first order with kicks. This scheme
takes the same steps (see `verlet`) with no kick torque in the forces, and applies
each impulse at its instant. In a step in which metronome k's escapement fires (θ_k
crosses its escapement angle, `_physics.escapement_angle`, 0 in the paper):

1. locate   the crossing at the fraction s_k = θ_k/(θ_k − θ_k') of the step, linear
            between the step's ends (an O(dt²) error in the instant); the step
            splits there, τ_k = (1 − s_k) dt is left after the kick.
2. impulse  M exactly: angular momentum ±M to pendulum k and the reaction ∓M to the
            disk's momentum p_φ. The velocities jump as eqs. (eqm1)–(eqm2)
            integrated over the impulse say: pendulum k by ±M/I_k, the disk by Δφ̇,
            every pendulum j by −R m_j h_j cos θ_j Δφ̇/I_j (`_located_parts.kick`).
3. finish   the jumps travel for τ_k, so the angles move on by τ_k × jump; and the
            jump of pendulum k changes its velocity-dependent forces (c_θ θ̇, and
            through the disk's numerator of φ̈), a change that acts for τ_k in this
            step and is part of the accelerations the next step starts from.

Several impulses in one step add up. Each of these terms is right to O(dt²) per
impulse, and a run has O(1) impulses per unit time, so the scheme is second order
with kicks: its error against ``exact`` falls 100-fold per decade of dt from 0.01 to
10⁻⁵ s (tests/integrators/test_located.py). Without kicks it is the ``verlet`` step.
The velocity jumps through the disk use the geometry at the step's end rather than
at the crossing, and the small changes they make in the other pendulums' friction
are left out: first-order terms, but smaller than the kick's own by the coupling
R²m²h²/(I (J + R²Σm)) (3×10⁻³ for the default metronomes), and they alternate in
sign with the kicks; the measured order stays 2.0 down to dt = 10⁻⁵ s.

The cost is a scalar pass over the impulses of a step and, in a step that has any,
two more terms per metronome in the second pass. The layouts are
`kernel_located_runs` and `kernel_located_oscillators`, picked as for ``verlet``;
`reference_located` is the NumPy twin. The scheme takes the forcing torque and the
escapement's offset and reaction from `_physics` like ``verlet``; it refuses dry
friction on the disk (`metrosync.capabilities` says so): its stick/slip events would
need locating inside the step like the kicks.
"""

from __future__ import annotations

from ..capabilities import require
from . import kernel_located_oscillators, kernel_located_runs
from ._state import StepState
from .verlet import advance_in_layout

#: Kernel modules by memory layout, picked as for ``verlet`` (`verlet.choose_layout`).
LAYOUTS = {"runs": kernel_located_runs, "oscillators": kernel_located_oscillators}


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout=None
):
    """Advance ``state`` by ``n_steps`` steps from ``step0`` with the kernel for
    ``layout`` (default: chosen from the problem's size, as for ``verlet``)."""
    require("located/numba", sys)
    advance_in_layout(
        LAYOUTS, state, sys, dt=dt, step0=step0, n_steps=n_steps, record_every=record_every,
        overturn_angle=overturn_angle, layout=layout,
    )  # fmt: skip

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
two more terms per metronome in the second pass. The scheme is two hooks (`begin`:
the escapement as an impulse, no torque; `impulse`: where in the step it acts and
what it changes, from `_located_parts`) that the same loops as ``verlet``'s call
(`layout_runs`, `layout_metronomes`); `twin` is its NumPy twin. It takes the forcing
torque and the escapement's offset and reaction from `_physics` like ``verlet``; it
refuses dry friction on the disk (`metrosync.capabilities` says so): its stick/slip
events would need locating inside the step like the kicks.
"""

from __future__ import annotations

import numba as nb

from ..capabilities import require
from . import layout_metronomes, layout_runs
from ._kernel_parts import drift
from ._located_parts import crossing_fraction, kick
from ._physics import escapement
from ._state import StepState
from .layouts import advance_in_layout

#: The escapement as impulses inside the step, no torque (`layouts`).
IMPULSIVE = True


@nb.njit(cache=True, inline="always")
def begin(c, m, theta, theta_dot, acc, dt, dt2):
    """The step's start for metronome ``m``: the new angle, the predicted velocity,
    whether the escapement fires (±1, 0), no torque, and its impulse ±M (N m s)."""
    theta_next, predicted = drift(theta, theta_dot, acc, dt, dt2)
    fires = escapement(c, m, theta, theta_next)
    return theta_next, predicted, fires, 0.0, fires * c.drive[m]


@nb.njit(cache=True, inline="always")
def impulse(c, m, r, theta, theta_next, theta_dot, dt):
    """Steps 1–3 of the module docstring for metronome ``m``'s escapement in a step
    from ``theta`` to ``theta_next``: its impulse (N m s; 0, and nothing else, when it
    does not fire), the time left after it, and `_located_parts.kick`'s jumps."""
    fires = escapement(c, m, theta, theta_next)
    if fires == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    given = fires * c.drive[m]
    after = dt - crossing_fraction(c, m, theta, theta_next) * dt
    dv, dnum, dforce, jrest, jnum = kick(c, m, r, given, theta_dot)
    return given, after, dv, dnum, dforce, jrest, jnum


# Reassociated and contracted in both layouts (within 1e-10 of the NumPy twin, as
# tested): without it the scalar impulse pass costs 0.80 of verlet's rate at (100, 7).
@nb.njit(parallel=True, cache=True, fastmath=layout_metronomes.FASTMATH)
def advance_runs(st, c, settings, rec):
    """The scheme in the runs-innermost loop (`layout_runs`)."""
    layout_runs.loop(st, c, settings, rec, begin, impulse, IMPULSIVE)


@nb.njit(parallel=True, cache=True, fastmath=layout_metronomes.FASTMATH)
def advance_metronomes(st, c, settings, rec):
    """The scheme in the metronomes-innermost loop (`layout_metronomes`)."""
    layout_metronomes.loop(st, c, settings, rec, begin, impulse, IMPULSIVE)


#: The compiled kernel of each memory layout.
LAYOUTS = {"runs": advance_runs, "metronomes": advance_metronomes}


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout=None
):
    """Advance ``state`` by ``n_steps`` steps from ``step0`` with the kernel for
    ``layout`` (default: chosen from the problem's size, as for ``verlet``)."""
    require("located/numba", sys)
    advance_in_layout(
        LAYOUTS,
        state,
        sys,
        dt=dt,
        step0=step0,
        n_steps=n_steps,
        record_every=record_every,
        overturn_angle=overturn_angle,
        layout=layout,
    )

"""The memory layouts of the fixed-step loops, which one a problem gets, and the call
of a scheme's compiled kernel.

A fixed-step scheme is two hooks, compiled functions that every layout's loop calls
(numba inlines them, so each scheme gets its own specialised loop):

``begin(c, m, theta, theta_dot, acc, dt, dt2)``
    per metronome ``m`` in the first, vectorized pass: returns the new angle, the
    velocity the forces are evaluated at, whether the escapement fires (±1, 0:
    `_physics.escapement`), the torque it exerts over the step, and the impulse it
    gives inside the step (N m s; 0 for none). A scheme gives one or the other.
``impulse(c, m, r, theta, theta_next, theta_dot, dt)``
    per metronome in the scalar pass of a step that has impulses (never for a scheme
    whose ``begin`` gives none): returns the impulse the step gives metronome ``m``
    (0 for none, and then nothing else), the time left in the step after it, the
    pendulum's velocity jump, its share of φ̈'s numerator and of the disk's torque, and
    what the jump changes in ρ_i and in φ̈'s numerator per unit time
    (`_located_parts.kick`). The loop applies them and the disk's jumps they imply.
``IMPULSIVE``
    a constant of the scheme module, passed to the loops with the hooks: whether the
    escapement is an impulse (``begin`` gives no torque) or a torque (no impulses).
    The loops branch on it where a scheme pays for what it does not use, and numba
    folds those branches: without impulses, the first pass sets the last kick's time
    by a vectorized select and nothing of the impulses is stored; with them, it marks
    each firing escapement as an event, and the scalar pass, which visits those
    anyway, sets the time and applies the impulse, while the escapement torques are
    not summed.

The layouts (`layout_runs`, `layout_metronomes`) own the loops, the memory order, the
crossing and record bookkeeping, the disk's update and its dry friction; the forces
come from `_physics`. A scheme module (`verlet`, `located`) holds its hooks and one
compiled kernel per layout, ``LAYOUTS``.
"""

from __future__ import annotations

from . import layout_metronomes, layout_runs
from ._abi import constants_of, settings_of
from ._cache import compile_kernel, heal_compile_cache
from ._state import StepState

#: The layouts by what goes innermost, with each one's `arrange` of the constants.
ARRANGE = {"runs": layout_runs.arrange, "metronomes": layout_metronomes.arrange}
#: Runs go innermost when a run has too few metronomes to fill vector registers and
#: there are enough runs to fill a block; otherwise metronomes do. Both thresholds
#: were measured with benchmarks/kernel.py on the 2-core AVX-512 machine.
RUNS_INNERMOST_BELOW_N = 10
RUNS_INNERMOST_FROM_B = 16


def choose_layout(n: int, runs: int) -> str:
    """The kernel layout for ``runs`` runs of ``n`` metronomes (a function of the
    problem only, never of the thread count, so results do not depend on it)."""
    if n < RUNS_INNERMOST_BELOW_N and runs >= RUNS_INNERMOST_FROM_B:
        return "runs"
    return "metronomes"


def advance_in_layout(
    kernels, state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout
):
    """Advance ``state`` with the compiled kernel of ``kernels`` (layout name → kernel)
    for ``layout``, or for the layout the problem's size chooses."""
    heal_compile_cache()
    name = layout or choose_layout(state.theta.shape[1], state.theta.shape[0])
    kernel = kernels[name]
    args = (
        state.kernel_state(),
        ARRANGE[name](constants_of(sys)),
        settings_of(
            dt=dt,
            step0=step0,
            n_steps=n_steps,
            record_every=record_every,
            overturn_angle=overturn_angle,
        ),
        state.kernel_recording(),
    )
    compile_kernel(kernel, *args)
    kernel(*args)

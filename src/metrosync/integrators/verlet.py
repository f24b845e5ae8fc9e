"""The paper's fixed-step "velocity Verlet-type" integrator, compiled with numba.

The scheme, per step of length dt (state x = (φ, θ), velocities v, accelerations a):

1. positions   x' = x + v dt + a dt²/2
2. kick        𝕄_i = +M/dt if θ_i < 0 < θ_i', −M/dt if θ_i > 0 > θ_i', else 0
               (the paper's discrete escapement, §4)
3. forces      a' = f(x', v*, 𝕄), eqs. (eqm1)–(eqm2), evaluated with the *predicted*
               velocities v* = v + a dt: that is how the velocity-dependent terms
               (friction, the θ̇² sin θ term, c_φ φ̇) enter the explicit scheme
4. velocities  θ̇' = θ̇ + (a + a') dt/2
5. disk        p_φ' = p_φ + (F + F') dt/2 with F = −c_φ φ̇* − Σ𝕄 the external torque on
               the disk, and φ̇' recovered from p_φ' = (J + R²Σm) φ̇' + R Σ m h cos θ' θ̇'.
               Without friction and drive p_φ is then conserved to rounding.

Because a' carries the kick, the impulse M/I enters the velocities in two halves, one
in this step and one in the next: the total momentum transfer is M, as in the paper.
Without kicks the scheme is second order; kicks quantise the impulse to the step, so
ensemble statistics converge to the ``exact`` integrator at first order in dt.

The same step also records, for each run, the analytic-phase order parameter and the
running sums of the crossing-interpolated phase (docs/model.md §7).

Dry friction on the disk (``disk_dry_friction`` = T > 0; `_physics.disk_friction`,
`_physics.disk_friction_stop`). Coulomb friction is set-valued at φ̇ = 0, so a scheme
that simply evaluates −T sign φ̇ chatters around rest at the step size. Here the
friction torque F_d is part of F in steps 3 and 5, chosen per step:

* At rest (φ̇ = 0 exactly): F_d is first the torque that holds the disk, the one that
  makes φ̈' = 0, H = −(R Σ_i num_i + F) with the step's sums. If |H| ≤ T the disk is
  held: φ̈' = 0, φ' = φ, the pendulums step exactly as on a rigid support, φ̇' = 0
  and p_φ' = R Σ m h cos θ' θ̇' (the disk's angular momentum at rest; the friction took
  the rest). Otherwise it breaks free: F_d = ±T against H.
* Slipping (φ̇ ≠ 0): F_d = −T sign φ̇.
* If the velocity φ̇' the step ends with does not have the direction F_d assumed, the
  disk reached rest within the step. φ̇' is affine in F_d's end value (p_φ' by the
  trapezoid rule, θ̇' through θ̈'), so the end value that makes φ̇' = 0 is solved
  for (an implicit, Moreau-type treatment of the friction's set-valued law): within
  ±T the disk stops, φ̇' = 0 exactly, and the accelerations and torque stored for the
  next step are those at rest; beyond ±T the disk reverses and F_d turns to ±T
  against the new direction. θ̇' and p_φ' are then recomputed with that end value.

So a held disk has exactly zero velocity, sticking never chatters, and stops and
reversals are resolved to the step (first order, like the kicks). Note that the
escapement's kick is a torque ±M/dt here: the disk slips at a kick when that torque
(with the pendulum's recoil) beats T, which, as dt → 0, it always does: `exact` treats
the kick as an impulse, which no finite friction can hold.
"""

from __future__ import annotations

from . import kernel_oscillators, kernel_runs
from ._abi import constants_of, settings_of
from ._cache import compile_kernel, heal_compile_cache
from ._state import StepState

#: Kernel modules by memory layout (see each module's docstring): each has
#: ``arrange(constants)`` and ``advance(state, constants, settings, recording)``.
LAYOUTS = {"runs": kernel_runs, "oscillators": kernel_oscillators}
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
    return "oscillators"


def advance_state(
    state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout=None
):
    """Advance ``state`` by ``n_steps`` steps from ``step0`` with the kernel for
    ``layout`` (default: chosen from the problem's size)."""
    advance_in_layout(
        LAYOUTS, state, sys, dt=dt, step0=step0, n_steps=n_steps, record_every=record_every,
        overturn_angle=overturn_angle, layout=layout,
    )  # fmt: skip


def advance_in_layout(
    layouts, state: StepState, sys, *, dt, step0, n_steps, record_every, overturn_angle, layout
):
    """`advance_state` for a scheme whose kernel modules by layout are ``layouts``."""
    heal_compile_cache()
    kernel = layouts[layout or choose_layout(state.theta.shape[1], state.theta.shape[0])]
    args = (
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
    )
    compile_kernel(kernel.advance, *args)
    kernel.advance(*args)

"""The run stage of `metrosync.simulate`: a request's ensemble advanced to its end.

`run` checks what needs the ensemble (the step against its fastest period, the
averaging window), warns about starts that cannot give a meaningful r, and advances
the ensemble with the request's integrator: a fixed-step scheme in chunks of about
0.25 s each (`metrosync.pacing`: Ctrl-C and the progress bar act promptly), the
whole-run integrator one run after another. It gives `RunRecords`: what was
recorded, each metronome's tick rate, and the spans they were measured over.
"""

from __future__ import annotations

import math
import sys as _sys
import warnings
from dataclasses import dataclass

import numpy as np

from .._words import plural
from ..budget import simulation_budget
from ..ensemble import Ensemble, check_damping_step, check_time_step
from ..errors import EscapementWarning, OverturnWarning
from ..integrators._state import Records, StepState, records_of
from ..observables.death import flag_stopped
from ..observables.ticks import CrossingTally, tail_span, tick_rate
from ..pacing import Pacer
from ..progress import progress_bar
from .request import SimulationRequest

#: How far `run`'s warnings are from the caller of `metrosync.simulate` (``warn`` <-
#: ``_warn_*`` <- ``run`` <- ``simulate`` <- caller): they name the caller's line.
_CALLER_LEVEL = 4


@dataclass
class RunRecords:
    """What a run gives.

    records : the integrator's `Records`, their ``status`` flagging stopped
        escapements too (`observables.death`).
    rates : (B, N) ticks per minute over the last ``tail_steps`` steps; NaN in a
        flagged run, which has no steady tick.
    window : the final window averaged for r_eq, s.
    tail_steps : the steps the tick rates were counted over.
    """

    records: Records
    rates: np.ndarray
    window: float
    tail_steps: int


def run(request: SimulationRequest, ensemble: Ensemble) -> RunRecords:
    """Advance ``ensemble`` as ``request`` says, from its start to its end."""
    check_time_step(request.dt, ensemble)
    if request.scheme.fixed_step:
        check_damping_step(request.dt, ensemble)
    window = request.window()
    show = _sys.stderr.isatty() if request.progress is None else request.progress
    _warn_overturned_start(ensemble, request.amplitude, request.overturn_angle)
    _warn_silent_escapement(ensemble, request.amplitude)
    n_steps, dt = request.n_steps, request.dt
    longest_period = float(2 * np.pi / np.min(ensemble.system.omega))
    tail_steps = min(n_steps, math.ceil(tail_span(window, longest_period) / dt))
    advance = _run_fixed_step if request.scheme.fixed_step else _run_whole
    records, rates = advance(request, ensemble, window, tail_steps, show)
    # A metronome whose escapement stopped firing is dead: its run is flagged too.
    records.status = flag_stopped(
        records.status, records.last_kick, request.simulated_time, ensemble.system.omega
    )
    # A run that overturned, diverged or stopped has no steady tick.
    rates[records.status != 0] = np.nan
    return RunRecords(records, rates, window, tail_steps)


def _run_whole(
    request: SimulationRequest, ensemble: Ensemble, window: float, tail_steps: int, show: bool
) -> tuple[Records, np.ndarray]:
    """Integrate each run whole (`exact`); the tick rates from the crossings after the
    last ``tail_steps`` steps began."""
    end = request.simulated_time
    with progress_bar(total=ensemble.runs, unit="run", enabled=show) as bar:
        records = request.scheme.integrate(
            ensemble.system,
            ensemble.theta0,
            ensemble.theta_dot0,
            ensemble.phi_dot0,
            duration=end,
            grid_dt=request.record_interval,
            n_records=request.n_records,
            trajectories=request.trajectories,
            overturn_angle=request.overturn_angle,
            on_run_done=lambda: bar.update(1),
            group_start=ensemble.group_start,
            rest_since=end - window,
        )
    since = (request.n_steps - tail_steps) * request.dt
    return records, np.stack([tick_rate(run, since) for run in records.crossings])


def _run_fixed_step(
    request: SimulationRequest, ensemble: Ensemble, window: float, tail_steps: int, show: bool
) -> tuple[Records, np.ndarray]:
    """Advance in paced chunks; the last ``tail_steps`` go in segments shorter than half
    the shortest period, to count ticks (`CrossingTally`), and the steps with the disk
    at rest are counted over the final ``window`` (``rest_time``). Returns the
    records and the (B, N) tick rates."""
    kernel = request.scheme.stepper(request.backend, trajectories=request.trajectories)
    n_steps, dt = request.n_steps, request.dt
    window_steps = min(n_steps, int(round(window / dt)))
    state = StepState.start(
        ensemble.system,
        ensemble.theta0,
        ensemble.theta_dot0,
        ensemble.phi0,
        ensemble.phi_dot0,
        n_records=request.n_records,
        trajectories=request.trajectories,
        group_start=ensemble.group_start,
    )
    # Chunks sized from the measured throughput end every ~0.25 s, so that Ctrl-C and
    # the progress bar act promptly whatever the problem size (see `metrosync.pacing`).
    estimate = simulation_budget(
        n=ensemble.n,
        runs=ensemble.runs,
        steps=1,
        records=1,
        trajectories=False,
        backend="numpy" if request.backend == "numpy" else "numba",
    ).seconds
    per_segment = max(1, int(ensemble.shortest_period() / 2 / dt))
    head = n_steps - tail_steps
    with progress_bar(total=round(n_steps * dt, 6), unit="s", enabled=show) as bar:

        def advance(step: int, count: int) -> None:
            kernel.advance_state(
                state,
                ensemble.system,
                dt=dt,
                step0=step,
                n_steps=count,
                record_every=request.stride,
                overturn_angle=request.overturn_angle,
            )
            bar.update(round(count * dt, 6))

        # The tail is within the window: the head is cut where the window starts.
        window_start = min(n_steps - window_steps, head)
        for first, stop in ((0, window_start), (window_start, head)):
            if first == window_start:
                rest_before = state.rest_steps.copy()
            for step, count in Pacer(stop - first, estimate):
                advance(first + step, count)
        tally = CrossingTally(state.last_up)
        for step, count in Pacer(tail_steps, estimate):
            for part in range(0, count, per_segment):
                advance(head + step + part, min(per_segment, count - part))
                tally.see(state.last_up)
    records = records_of(state)
    records.rest_time = (state.rest_steps - rest_before) * dt
    return records, tally.rate()


def _warn_overturned_start(ensemble: Ensemble, amplitude, overturn_angle: float) -> None:
    """Warn when some pendulum starts swinging past ``overturn_angle``: its run will be
    flagged at once and its r means nothing."""
    swing = np.hypot(ensemble.theta0, ensemble.theta_dot0 / ensemble.system.omega)
    if not np.any(swing > overturn_angle):
        return
    runs = int(np.any(swing > overturn_angle, axis=1).sum())
    given = (
        f"`amplitude` = {amplitude!r} rad"
        if amplitude is not None
        else (
            f"the start (`theta0`, `theta_dot0`) swings up to {float(swing.max()):.3g} rad, which"
        )
    )
    warnings.warn(
        f"{given} is beyond `overturn_angle` = {overturn_angle:.4g} rad: {runs} of "
        f"{plural(ensemble.runs, 'run')} start overturned, are flagged in `status`, and their r is "
        f"not meaningful. Start below {overturn_angle:.4g} rad.",
        OverturnWarning,
        stacklevel=_CALLER_LEVEL,
    )


def _warn_silent_escapement(ensemble: Ensemble, amplitude) -> None:
    """Warn when some escapement's angle lies beyond its pendulum's start swing: it
    cannot fire, the pendulum decays ("metronome death", `observables.death`), and the
    run will be flagged `stopped`."""
    swing = np.hypot(ensemble.theta0, ensemble.theta_dot0 / ensemble.system.omega)
    offset = np.abs(ensemble.system.escapement_offset)
    beyond = offset > swing
    if not np.any(beyond):
        return
    runs = int(np.any(beyond, axis=1).sum())
    start = f"`amplitude` = {amplitude!r} rad" if amplitude is not None else "the start swing"
    warnings.warn(
        f"`escapement_offset` = {float(offset[beyond].max()):.4g} rad lies beyond "
        f"{start} ({float(swing[beyond].min()):.3g} rad) of "
        f"{plural(int(beyond.sum()), 'metronome')} in {runs} of "
        f"{plural(ensemble.runs, 'run')}: their escapement never fires, "
        f'the pendulum decays ("metronome death"), and the run is flagged `stopped` in '
        f"`status`. Give an `escapement_offset` below the swing, or start wider (`amplitude`).",
        EscapementWarning,
        stacklevel=_CALLER_LEVEL,
    )

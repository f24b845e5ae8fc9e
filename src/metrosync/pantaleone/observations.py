"""Pantaleone's observations (Am. J. Phys. 70, 992 (2002)), each run on the board.

Each function runs the full model on the ``pantaleone2002`` preset (or a variant of it
that the observation names) and returns what it measured; `report` turns them into
verdicts. The phase measures:

* a pair's final state from its order parameter r = |cos(δ/2)| over the last
  twentieth of the run (δ the phase difference, from the analytic phases of
  `simulate`): in phase when |δ| ≤ 30°, in anti-phase when |δ| ≥ 150° (a damped
  board holds the pair near, not at, anti-phase: the report gives the mean |δ|);
* the time to lock: the first time from which the pair stays within 10° of in phase
  to the end;
* a detuned pair's lag: from the upward zero crossings of the two pendulums over the
  last part of the run, δ = 2π (t₂ − t₁)/T, positive when the first (the faster)
  crosses first; locked when the two cross equally often and δ varies by less than
  `LOCKED_SPREAD`.

``located`` integrates every run (order 2 with the kicks, so a step of 5 ms keeps the
phases to well under a degree over the runs here); a strongly damped board needs a
step below its damping time (`ensemble.check_damping_step`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model import Metronome, get_preset
from ..model.metronome import bpm_to_omega
from ..model.steady_swing import steady_swing
from ..observables.entrainment import upward_crossings
from ..simulate import simulate
from ..theory._coupling_base import tuned_metronome

PRESET = "pantaleone2002"
#: His tick rate, per minute (two ticks a period).
BPM = 208.0
#: r of a pair within 10° of in phase (locked), within 30° (in phase at the end), and
#: within 30° of anti-phase.
LOCKED = math.cos(math.radians(5.0))
IN_PHASE = math.cos(math.radians(15.0))
ANTI_PHASE = math.sin(math.radians(15.0))
#: The largest spread of a locked pair's lag over the measuring window, rad.
LOCKED_SPREAD = 0.05
#: The step of every run but the strongly damped board's, s.
DT = 0.005


def steady_amplitude(params=PRESET, bpm: float = BPM) -> float:
    """The swing of a free metronome of ``params`` marked ``bpm``, rad."""
    return steady_swing(tuned_metronome(bpm, get_preset(params, warn=False))[0]).amplitude


def board(changes: dict | None = None):
    """His board (`PRESET`), with ``changes`` (a heavier board, a damped one)."""
    params = get_preset(PRESET, warn=False)
    return params.with_changes(**changes) if changes else params


@dataclass(frozen=True)
class PairStarts:
    """What became of two metronomes started from ``starts`` (per start): the time at
    which they locked in phase (inf if they did not), and their final state."""

    lock_time: np.ndarray
    final: np.ndarray  # "in-phase", "anti-phase" or "neither"
    duration: float
    final_lag: np.ndarray  # |δ| at the end, rad

    @property
    def in_phase(self) -> int:
        return int(np.sum(self.final == "in-phase"))

    @property
    def anti_phase(self) -> int:
        return int(np.sum(self.final == "anti-phase"))


def _classify(r: np.ndarray, time: np.ndarray) -> tuple[float, str, float]:
    """Lock time, final state and final |δ| of one pair from its r(t)."""
    end = float(np.mean(r[-max(1, len(r) // 20) :]))
    final = "in-phase" if end >= IN_PHASE else "anti-phase" if end <= ANTI_PHASE else "neither"
    lag = 2 * math.acos(min(end, 1.0))
    outside = np.flatnonzero(r < LOCKED)
    if outside.size and outside[-1] == len(r) - 1:
        return math.inf, final, lag
    return (float(time[outside[-1] + 1]) if outside.size else 0.0), final, lag


def steady_tick_bpm(metronome: Metronome) -> float:
    """Ticks a minute of ``metronome`` alone at its steady swing."""
    return steady_swing(metronome).tick_bpm


def pair_starts(
    *,
    starts: int,
    duration: float,
    near_anti_phase: bool,
    changes: dict | None = None,
    seed: int = 0,
    dt: float = DT,
    metronome: Metronome | None = None,
) -> PairStarts:
    """Two identical metronomes on the board from ``starts`` starts at the steady
    swing: at random phases, or within ±30° of anti-phase (``near_anti_phase``); marked
    `BPM`, or two copies of ``metronome`` when it is given."""
    params = board(changes)
    pair: dict[str, Any]
    if metronome is None:
        pair = {"frequencies_bpm": [BPM, BPM]}
        amplitude, omega = steady_amplitude(params), float(bpm_to_omega(BPM))
    else:
        pair = {"metronomes": [metronome, metronome]}
        swing = steady_swing(metronome)
        amplitude, omega = swing.amplitude, float(bpm_to_omega(swing.tick_bpm))
    rng = np.random.default_rng(seed)
    times, finals, lags = [], [], []
    for _ in range(starts):
        first = rng.uniform(0, 2 * math.pi)
        second = first + (math.pi + rng.uniform(-1, 1) * math.radians(30))
        phases = np.array([first, second if near_anti_phase else rng.uniform(0, 2 * math.pi)])
        ds = simulate(
            None, None, **pair, preset=params, integrator="located",
            theta0=list(amplitude * np.cos(phases)),
            theta_dot0=list(-amplitude * omega * np.sin(phases)),
            duration=duration, dt=dt, record_every=max(1, int(round(0.5 / dt))),
        )  # fmt: skip
        lock, final, lag = _classify(ds.r.values[:, 0], ds.time.values)
        times.append(lock)
        finals.append(final)
        lags.append(lag)
    return PairStarts(np.array(times), np.array(finals), duration, np.array(lags))


@dataclass(frozen=True)
class Lag:
    """A detuned pair: ``detuning_bpm`` between their markings, whether they locked,
    and the lag (rad, > 0 when the faster leads) with its spread over the window."""

    detuning_bpm: float
    locked: bool
    lag: float
    spread: float


def pair_lag(
    detuning_bpm: float,
    *,
    duration: float,
    window: float,
    dt: float = DT,
    changes: dict | None = None,
) -> Lag:
    """Two metronomes marked ``BPM ± detuning/2`` (the first the faster), started in
    phase, measured over the last ``window`` seconds."""
    frequencies = [BPM + detuning_bpm / 2, BPM - detuning_bpm / 2]
    params = board(changes)
    amplitude = steady_amplitude(params)
    ds = simulate(
        None, None, frequencies_bpm=frequencies, preset=params, integrator="located",
        theta0=[amplitude, amplitude], theta_dot0=[0.0, 0.0], duration=duration, dt=dt,
        record_every=1, trajectories=True,
    )  # fmt: skip
    time = ds.time.values
    keep = time >= time[-1] - window
    theta = ds.theta.values[keep, 0, :]
    first, second = (upward_crossings(time[keep], theta[:, i]) for i in range(2))
    period = float(np.mean(np.diff(first)))
    if abs(len(first) - len(second)) > 1 or len(first) < 4:
        return Lag(detuning_bpm, False, math.nan, math.nan)
    after = np.searchsorted(second, first)
    usable = after < len(second)
    lag = 2 * math.pi * (second[after[usable]] - first[usable]) / period
    lag = np.angle(np.exp(1j * lag))  # to (−π, π]
    spread = float(np.ptp(lag))
    return Lag(detuning_bpm, spread < LOCKED_SPREAD, float(np.mean(lag)), spread)


def seven_on_a_longer_board(
    *, runs: int, duration: float, sigma_bpm: float, board_mass: float, seed: int = 0
):
    """Seven metronomes with a spread of natural frequencies on a longer board, from
    random phases: their r_eq, per run."""
    ds = simulate(
        7, BPM, sigma_bpm=sigma_bpm, runs=runs, duration=duration, dt=DT, seed=seed,
        preset=PRESET, changes={"board_mass": board_mass}, integrator="located",
        amplitude=steady_amplitude(),
    )  # fmt: skip
    return ds.r_eq.values

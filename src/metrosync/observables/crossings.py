"""Phases, r(t), frequencies and jitter from one kept pass per period (paper §2, eq. (op)).

The experiment's method, shared by every instrument that times a metronome's passes
(light gates, sound, video): each gives, per metronome, the kept pass times and the
number of periods between consecutive ones, and everything below follows from them.

Contract: pure functions over arrays.

* A metronome's phase rises linearly from 0 to 2π between consecutive kept passes
  (by 2πk across a gap of k periods, where passes were missed). It is defined from
  its first to its last kept pass.
* r(t) = |(1/N) Σ_j e^{iΦ_j(t)}| on a uniform grid t = k·dt over the span where
  every channel has a phase.
* A metronome's mean frequency is 120 beats per period over the time between its
  first and last kept pass (two beats per period, docs/model.md §6.1); its period jitter
  is the standard deviation of the single-period intervals.
* σ is the sample standard deviation (ddof=1) of the metronomes' mean frequencies,
  in BPM, and also in the paper's table unit read as beats per logger tick
  (docs/model.md §6.4): σ_tick = σ_BPM / 60 · tick.
"""

from __future__ import annotations

import numpy as np

from ..errors import AnalysisError

TWO_PI = 2.0 * np.pi


def unwrapped_phase(kept: np.ndarray, cycles: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Phase (not wrapped) on ``grid`` from kept passes.

    kept : (P,) kept pass times.   cycles : (P-1,) periods between them.   grid : (T,).
    Returns (T,) phase in rad, 0 at the first kept pass; NaN outside [kept[0], kept[-1]].
    """
    kept = np.asarray(kept, dtype=float)
    grid = np.asarray(grid, dtype=float)
    out = np.full(grid.shape, np.nan)
    if kept.size < 2:
        return out
    turns = np.concatenate([[0.0], np.cumsum(cycles)]) * TWO_PI
    inside = (grid >= kept[0]) & (grid <= kept[-1])
    out[inside] = np.interp(grid[inside], kept, turns)
    return out


def common_grid(spans: list[tuple[float, float]], dt: float) -> np.ndarray:
    """Uniform grid k·dt inside the intersection of ``spans`` [(start, end), ...]."""
    start = max(s for s, _ in spans)
    end = min(e for _, e in spans)
    k0 = int(np.ceil(start / dt - 1e-9))
    k1 = int(np.floor(end / dt + 1e-9))
    if k1 < k0:
        return np.empty(0)
    return np.arange(k0, k1 + 1) * dt


def order_on_grid(passes: list[tuple[np.ndarray, np.ndarray]], grid: np.ndarray) -> np.ndarray:
    """r on ``grid`` from N channels' (kept, cycles); (T,), NaN where a phase is missing."""
    phases = np.stack([unwrapped_phase(k, c, grid) for k, c in passes])
    return np.abs(np.mean(np.exp(1j * phases), axis=0))


def mean_frequency_bpm(kept: np.ndarray, cycles: np.ndarray) -> float:
    """Mean beat frequency between the first and last kept pass, BPM; NaN if < 2 passes."""
    if len(kept) < 2:
        return float("nan")
    return float(120.0 * np.sum(cycles) / (kept[-1] - kept[0]))


def period_jitter(kept: np.ndarray, cycles: np.ndarray) -> float:
    """Standard deviation (ddof=1) of the single-period intervals, s; NaN if < 2."""
    periods = np.diff(kept)[np.asarray(cycles) == 1]
    return float(np.std(periods, ddof=1)) if periods.size >= 2 else float("nan")


def frequency_spread(frequency_bpm: np.ndarray) -> float:
    """σ: sample standard deviation (ddof=1) of the metronomes' frequencies, BPM."""
    f = np.asarray(frequency_bpm, dtype=float)
    f = f[np.isfinite(f)]
    return float(np.std(f, ddof=1)) if f.size >= 2 else float("nan")


def bpm_to_beats_per_tick(bpm: float, tick: float) -> float:
    """A frequency in BPM as beats per logger tick (the unit of the paper's Tables 1–2)."""
    return bpm / 60.0 * tick


def channel_span(kept: np.ndarray, source: str, channel: int) -> tuple[float, float]:
    """(first, last) kept pass of a channel, or an `AnalysisError` naming it."""
    if len(kept) < 2:
        raise AnalysisError(
            f"{source}: gate {channel} has {len(kept)} kept passes after cleaning, too few for "
            f"a phase. Leave it out with `channels=` (CLI: --channels), or check its wiring."
        )
    return float(kept[0]), float(kept[-1])


def kept_from_half_periods(
    times: np.ndarray, half_period: np.ndarray, parity: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """(kept, cycles) from passes counted in half periods, both directions heard.

    A sound (a tick each way) or a camera sees a pendulum pass the vertical twice per
    period; the passes numbered ``half_period`` (P,) (integers, gaps where missed)
    with the given ``parity`` go one way and are kept, as a light gate keeps one
    direction. Returns kept (Q,) times and cycles (Q-1,) periods between them.
    """
    times = np.asarray(times, dtype=float)
    half_period = np.asarray(half_period, dtype=np.int64)
    keep = half_period % 2 == parity % 2
    kept = times[keep]
    cycles = np.diff(half_period[keep]) // 2
    return kept, cycles

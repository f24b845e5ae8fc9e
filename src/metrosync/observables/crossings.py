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

from ..errors import AnalysisError, ParameterError

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


# Passes from a sampled angle (video): the angle θ(t) of each frame, sampled at
# irregular times, gives the passes through the vertical at sub-sample precision.


def zero_crossings(
    time: np.ndarray, angle: np.ndarray, *, upward: bool = True, hysteresis: float = 0.0
) -> np.ndarray:
    """Times where ``angle`` crosses 0 upward (− to +) or downward, at sub-sample precision.

    time : (T,) increasing sample times, s (irregular spacing allowed).
    angle : (T,) angle, rad; NaN where unknown (no crossing is placed across a NaN).
    hysteresis : a crossing counts only once the angle has been below −hysteresis
        (above, for downward) since the last one, so that noise near 0 gives one pass.
    Returns (K,) crossing times. Each is the root of a cubic fitted by least squares
    to the (up to) six samples around the sign change, or of the line through the two
    samples when fewer than four are finite.
    """
    t = np.asarray(time, dtype=float)
    a = np.asarray(angle, dtype=float)
    if not upward:
        a = -a
    if t.size < 2:
        return np.empty(0)
    ok = np.isfinite(a)
    cand = np.flatnonzero(ok[:-1] & ok[1:] & (a[:-1] < 0) & (a[1:] >= 0))
    if hysteresis > 0 and cand.size:
        below = np.flatnonzero(ok & (a < -hysteresis))
        keep, armed_after = [], -1
        for i in cand:
            # armed if some sample since the previous kept crossing went below -h
            j = np.searchsorted(below, armed_after + 1)
            if j < below.size and below[j] <= i:
                keep.append(i)
                armed_after = i
        cand = np.array(keep, dtype=int)
    out = np.empty(cand.size)
    for n, i in enumerate(cand):
        out[n] = _root_near(t, a, ok, int(i))
    return out


def _root_near(t: np.ndarray, a: np.ndarray, ok: np.ndarray, i: int) -> float:
    """Root in [t[i], t[i+1]] of a cubic through the finite samples i−2 .. i+3."""
    lo, hi = max(0, i - 2), min(t.size, i + 4)
    idx = np.arange(lo, hi)
    idx = idx[ok[idx]]
    t0, dt = t[i], t[i + 1] - t[i]
    linear = t0 + dt * (-a[i]) / (a[i + 1] - a[i])
    if idx.size < 4:
        return float(linear)
    x = (t[idx] - t0) / dt
    coef = np.polyfit(x, a[idx], 3)
    roots = np.roots(coef)
    real = roots[np.abs(roots.imag) < 1e-9].real
    real = real[(real >= -0.25) & (real <= 1.25)]
    if real.size == 0:
        return float(linear)
    best = real[np.argmin(np.abs(real - (linear - t0) / dt))]
    return float(t0 + dt * best)


def passes_on_period_grid(crossings: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(kept, cycles) from one direction's crossings, as the light gate keeps passes.

    crossings : (K,) times of one direction's passes, increasing. Intervals are counted
    in whole periods of their median interval, so that a stretch where the metronome
    was lost (k periods missing) counts k + 1 periods. Returns kept (K,) and cycles
    (K − 1,) ≥ 1.
    """
    kept = np.asarray(crossings, dtype=float)
    if kept.size < 2:
        return kept, np.empty(0, dtype=int)
    gaps = np.diff(kept)
    period = float(np.median(gaps))
    cycles = np.maximum(1, np.rint(gaps / period)).astype(int)
    return kept, cycles


def swing_amplitudes(time: np.ndarray, angle: np.ndarray, kept: np.ndarray) -> np.ndarray:
    """(K − 1,) half the peak-to-peak angle between consecutive kept passes, rad.

    time, angle : (T,) the sampled angle (NaN ignored); kept : (K,) pass times.
    NaN for a period with fewer than 3 finite samples.
    """
    t = np.asarray(time, dtype=float)
    a = np.asarray(angle, dtype=float)
    edges = np.searchsorted(t, kept)
    out = np.full(max(kept.size - 1, 0), np.nan)
    for n in range(out.size):
        seg = a[edges[n] : edges[n + 1]]
        seg = seg[np.isfinite(seg)]
        if seg.size >= 3:
            out[n] = 0.5 * (seg.max() - seg.min())
    return out


def beat_asymmetry(up: np.ndarray, down: np.ndarray) -> float:
    """Tick/tock asymmetry: mean (t_down − t_up − (t_up' − t_down)) / (t_up' − t_up), %.

    up, down : (K,), (M,) upward and downward pass times. Each period between
    consecutive upward passes that holds exactly one downward pass counts; the result
    is how much longer the half-swing after an upward pass is than the one before the
    next, as a percentage of the period (0 for a symmetric beat); NaN if none counts.
    """
    up = np.asarray(up, dtype=float)
    down = np.asarray(down, dtype=float)
    if up.size < 2 or down.size == 0:
        return float("nan")
    j = np.searchsorted(down, up[:-1])
    k = np.searchsorted(down, up[1:])
    one = (k - j) == 1
    if not np.any(one):
        return float("nan")
    u0, u1, d = up[:-1][one], up[1:][one], down[j[one]]
    return float(100.0 * np.mean(((d - u0) - (u1 - d)) / (u1 - u0)))


def equilibrium_window(grid: np.ndarray, equilibrium_window: float | None) -> float:
    """The final window r_eq averages over, s: the last quarter of ``grid`` (T,) unless
    given; a `ParameterError` when it does not fit in the grid's span."""
    span = float(grid[-1] - grid[0])
    window = span / 4 if equilibrium_window is None else float(equilibrium_window)
    if not (0 < window <= span):
        raise ParameterError(
            f"`equilibrium_window` must be in (0, {span:g}] s (the span of the r(t) grid), "
            f"got {equilibrium_window!r}."
        )
    return window

"""The acoustic order parameter: how together the ticks of an ensemble fall, by ear.

Contract: `acoustic_order(times, period)` takes the tick times (K,) of all the
metronomes on one channel, sorted, with no idea of who ticked, and returns an
`AcousticOrder` series over sliding windows.

Definition. In a window of length W holding M ticks t_k, with T the beat period there
(`tempo.swing_matches` over the window's ticks),

    R = | (1/M) Σ_k exp(2πi t_k / T) |.

N metronomes ticking together give R = 1 (all ticks share one phase of the beat).
Independent metronomes each keep a nearly fixed phase within a window much shorter
than the time they need to drift a beat apart, so R is the length of the mean of N
random unit vectors: E[R²] = 1/N. That is the floor reported, R_floor = 1/√N, with N
the number of metronomes (given, or the ticks per beat M·T/W of the window), and
R_excess = √((R² − R_floor²) / (1 − R_floor²)) (0 where R < R_floor) estimates the
synchrony above it. Only where the window lasts long enough for each metronome's
phase to wander through the beat (ticks independent from one to the next) does the
floor fall towards 1/√M.

What it cannot tell: a metronome ticks at every zero crossing, in both directions, so
its tick phase is twice the pendulum's phase: R is the second harmonic of the paper's
order parameter, |⟨exp(2iφ_j)⟩|. Two pendulums in anti-phase tick together and give
R = 1, as in-phase ones do. Ticks closer than the detector's refractory time are
heard, and counted, as one.

Clusters: the number of distinct ticks per beat an ear would hear. In each beat, ticks
closer than ``cluster_gap`` (a fraction of the beat) sound as one; the window reports
the median count over its beats, so that a stray sound does not count.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .settings import CLUSTER_GAP
from .tempo import SWING_TOLERANCE

#: Default window, in beats, and step between windows, in beats.
WINDOW_BEATS = 16
STEP_BEATS = 2


@dataclass(frozen=True)
class AcousticOrder:
    """The acoustic order parameter over sliding windows (W,).

    time : window centres, s. r : R. floor : 1/√N. excess : R above the floor (NaN
    for N < 1.5). ticks_per_beat : M·T/W.
    clusters : distinct ticks per beat. period : T in each window, s.
    window, step : window length and step, s.
    """

    time: np.ndarray
    r: np.ndarray
    floor: np.ndarray
    excess: np.ndarray
    ticks_per_beat: np.ndarray
    clusters: np.ndarray
    period: np.ndarray
    window: float
    step: float


def acoustic_order(
    times: np.ndarray,
    period: float,
    *,
    window: float | None = None,
    step: float | None = None,
    cluster_gap: float = CLUSTER_GAP,
    centres: np.ndarray | None = None,
    metronomes: int | None = None,
) -> AcousticOrder:
    """R over windows of ``window`` s (default 16 beats) every ``step`` s (2 beats).

    times : (K,) sorted tick times, s. period : the beat period of the whole train, s,
    used where a window has too few full swings of its own.
    centres : (W,) window centres, s, to compare two trains on the same windows
        (default: every ``step`` from the first tick + window/2 to the last − window/2).
    metronomes : N for the floor 1/√N (default: each window's ticks per beat).
    """
    times = np.asarray(times, dtype=float)
    window = WINDOW_BEATS * period if window is None else float(window)
    step = STEP_BEATS * period if step is None else float(step)
    span = times[-1] - times[0]
    if centres is not None:
        centres = np.asarray(centres, dtype=float)
    elif span <= window:
        centres = np.array([0.5 * (times[0] + times[-1])])
        window = max(span, period)
    else:
        centres = np.arange(times[0] + window / 2, times[-1] - window / 2 + 1e-9, step)
    swing = _swing_of_each(times, period)
    beat_start, beat_count = ticks_per_beat_heard(times, period, cluster_gap)
    lo = np.searchsorted(times, centres - window / 2, side="left")
    hi = np.searchsorted(times, centres + window / 2, side="left")
    n = centres.size
    r, per_beat, clusters, local = (np.full(n, np.nan) for _ in range(4))
    for w in range(n):
        t = times[lo[w] : hi[w]]
        if t.size == 0:
            continue
        s = swing[lo[w] : hi[w]]
        s = s[np.isfinite(s)]
        T = float(np.median(s)) / 2 if s.size >= 3 else period
        z = np.exp(2j * np.pi * t / T)
        r[w] = abs(z.mean())
        per_beat[w] = t.size * T / window
        mine = beat_count[(beat_start >= centres[w] - window / 2)
                          & (beat_start < centres[w] + window / 2)]  # fmt: skip
        clusters[w] = np.median(mine) if mine.size else np.nan
        local[w] = T
    floor, excess = floor_and_excess(r, per_beat if metronomes is None else metronomes)
    return AcousticOrder(centres, r, floor, excess, per_beat, clusters, local, window, step)


def no_common_beat(tempi_bpm, window_beats: float) -> str:
    """Why metronomes of these tempi share no beat for R to measure, or ``""`` if they do.

    R asks whether ticks fall together on one beat over a window of ``window_beats``
    beats. Where, over one window, the fastest metronome gains a whole beat or more on
    the slowest, their ticks slide through every phase of any beat: R then measures
    how far apart the tempi are, not whether the metronomes keep together, and the
    distinct ticks of a beat are no count of anything.

    tempi_bpm : (M,) the metronomes' own tempi, BPM.
    window_beats : the length of R's window, in beats.
    """
    tempi = np.sort(np.asarray(tempi_bpm, dtype=float))
    if tempi.size < 2:
        return ""
    spread = (tempi[-1] - tempi[0]) / float(np.median(tempi))
    gained = spread * window_beats
    if gained < 1.0:
        return ""
    return (
        f"the metronomes keep tempi {100 * spread:.0f} % apart: over one window of R "
        f"({window_beats:.0f} beats) the fastest gains {gained:.1f} beats on the slowest, "
        f"so their ticks share no beat to fall together on"
    )


def floor_and_excess(r: np.ndarray, metronomes) -> tuple[np.ndarray, np.ndarray]:
    """R_floor = 1/√N and R_excess (NaN where N < 1.5) for R (W,) and N (scalar or (W,))."""
    n = np.broadcast_to(np.asarray(metronomes, dtype=float), r.shape)
    floor = np.minimum(1.0, 1.0 / np.sqrt(n))
    with np.errstate(invalid="ignore", divide="ignore"):
        excess = np.sqrt(np.clip((r**2 - floor**2) / (1 - floor**2), 0.0, 1.0))
    excess[~(n >= 1.5)] = np.nan
    return floor, excess


def _swing_of_each(times: np.ndarray, period: float) -> np.ndarray:
    """(K,) for each tick, the time to its nearest tick near t + 2·period, NaN if none."""
    target = times + 2 * period
    j = np.clip(np.searchsorted(times, target), 1, max(times.size - 1, 1))
    nearest = np.where(np.abs(times[j - 1] - target) < np.abs(times[j] - target), j - 1, j)
    d = times[nearest] - times
    return np.where(np.abs(d - 2 * period) < SWING_TOLERANCE * 2 * period, d, np.nan)


def ticks_per_beat_heard(times: np.ndarray, period: float, gap: float):
    """Distinct ticks in each beat [t₀ + bT, t₀ + (b+1)T): ticks closer than ``gap``·T
    (also across the beat's ends, on the beat circle) count as one.

    Returns the beats' start times (B,) and their counts (B,).
    """
    t0 = times[0]
    beat = np.floor((times - t0) / period).astype(np.int64)
    beats = int(beat[-1]) + 1
    ticks = np.bincount(beat, minlength=beats)
    close = (np.diff(times) <= gap * period) & (beat[1:] == beat[:-1])
    merged = np.bincount(beat[1:][close], minlength=beats)
    counts = ticks - merged
    # the first and the last tick of a beat, seen on the circle, may be one cluster
    first = np.searchsorted(beat, np.arange(beats), side="left")
    last = np.searchsorted(beat, np.arange(beats), side="right") - 1
    has = ticks > 0
    wrap = np.zeros(beats, dtype=bool)
    wrap[has] = times[first[has]] + period - times[last[has]] <= gap * period
    counts = counts - (wrap & (counts > 1))
    return t0 + period * np.arange(beats), counts

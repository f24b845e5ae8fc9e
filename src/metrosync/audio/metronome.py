"""One metronome heard alone: tempo, jitter, and whether it is in beat.

Contract: `beat_statistics(times, period)` takes the tick times of one metronome
(K,), sorted, and its beat period (for numbering the beats), and returns
`BeatStatistics`. Ticks may be missing: each tick gets a beat number from the
rounded intervals, and only intervals between consecutive beats are used.

Definitions. A metronome ticks twice per swing, once each way; call the ticks that
start every other beat "tick" and the others "tock" (the louder kind is the tick, when
their loudness differs; otherwise the first tick heard). A full swing (tick to next
tick) holds one beat of each kind, so

- the tempo is 120 / (mean full swing) BPM; its uncertainty is the standard error of
  the mean of the non-overlapping swings, as if each swing were independent (an
  upper bound when the irregularity is in the timing of single ticks);
- the asymmetry is (long beat − short beat) / mean beat, in per cent of a beat: a
  metronome "in beat" ticks evenly, one "out of beat" limps, tick-tock … tick-tock;
- the jitter is the standard deviation of the beats about the mean of their kind, so
  that an uneven beat does not count as jitter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Asymmetries (per cent of a beat) where the words change: barely audible, audible.
SLIGHT, AUDIBLE = 2.0, 5.0


@dataclass(frozen=True)
class BeatStatistics:
    """Statistics of one metronome's ticks.

    ticks : number of ticks used; beats : number of single-beat intervals.
    bpm, bpm_error : tempo and its standard error, BPM (ticks per minute).
    period : mean beat, s. jitter : std of the beats about their kind's mean, s.
    asymmetry, asymmetry_error : (long − short) / mean beat, per cent (≥ 0).
    long_beat : ``"tick→tock"`` or ``"tock→tick"`` (which beat is the long one).
    tick_is_louder : the tick/tock names follow loudness (else: the first tick heard).
    beat_number : (K,) beat number of each tick (0 for the first).
    is_tock : (K,) True for the ticks that start the other kind of beat.
    missed : beats with no tick heard (gaps longer than one beat).
    """

    ticks: int
    beats: int
    bpm: float
    bpm_error: float
    period: float
    jitter: float
    asymmetry: float
    asymmetry_error: float
    long_beat: str
    tick_is_louder: bool
    beat_number: np.ndarray
    is_tock: np.ndarray
    missed: int

    @property
    def in_beat(self) -> bool:
        """True when the asymmetry is within its noise or below `SLIGHT` / 4 per cent."""
        return self.asymmetry < max(3 * self.asymmetry_error, SLIGHT / 4)

    def verdict(self) -> str:
        """The beat described in a musician's words."""
        a = self.asymmetry
        offset_ms = 1e3 * a / 100 * self.period / 2
        if self.in_beat:
            return (
                f"in beat: tick and tock are even (asymmetry {a:.2f} ± "
                f"{self.asymmetry_error:.2f} % of a beat)"
            )
        where = (
            f"the {self.long_beat} beat is {a:.1f} % of a beat longer; the tock falls "
            f"{offset_ms:.1f} ms off the middle of the swing"
        )
        if a < SLIGHT:
            return f"very slightly out of beat: {where}; hardly anyone hears it"
        if a < AUDIBLE:
            return f"slightly out of beat: {where}; a trained ear hears the limp"
        return (
            f"out of beat: {where}; the tick-tock limps audibly. Set it in beat (on a "
            f"level surface; tilt it slightly or adjust its escapement) until tick and "
            f"tock sound even"
        )


def beat_statistics(
    times: np.ndarray, period: float, strength: np.ndarray | None = None
) -> BeatStatistics:
    """Tempo, jitter and asymmetry of one metronome's ticks (see the module docstring).

    times : (K,) sorted tick times, s. period : its beat period, s (any estimate
    within ±25 %). strength : (K,) tick loudness, dB, to name tick and tock.
    """
    times = np.asarray(times, dtype=float)
    gaps = np.diff(times)
    steps = np.maximum(1, np.rint(gaps / period)).astype(np.int64)
    number = np.concatenate([[0], np.cumsum(steps)])
    single = steps == 1
    beat = gaps[single]
    kind = number[:-1][single] % 2  # kind of the tick that starts each beat
    tick_is_louder = False
    tock_parity = 1
    if strength is not None and times.size >= 8:
        loud = [np.asarray(strength)[number % 2 == p] for p in (0, 1)]
        diff = loud[0].mean() - loud[1].mean()
        err = math.hypot(loud[0].std() / math.sqrt(loud[0].size),
                         loud[1].std() / math.sqrt(loud[1].size))  # fmt: skip
        if abs(diff) > max(1.0, 3 * err):
            tick_is_louder = True
            tock_parity = 1 if diff > 0 else 0
    means = [beat[kind == p].mean() if np.any(kind == p) else math.nan for p in (0, 1)]
    varis = [beat[kind == p].var(ddof=1) if np.sum(kind == p) > 1 else math.nan for p in (0, 1)]
    counts = [int(np.sum(kind == p)) for p in (0, 1)]
    mean_beat = 0.5 * (means[0] + means[1])
    asym = 100 * abs(means[0] - means[1]) / mean_beat
    # a kind heard in one beat or none (a train of a few scattered ticks) has no spread
    asym_err = (
        100 * math.sqrt(varis[0] / counts[0] + varis[1] / counts[1]) / mean_beat
        if min(counts) > 1
        else math.nan
    )
    tick_parity = 1 - tock_parity
    long_kind = 0 if means[0] > means[1] else 1
    long_beat = "tick→tock" if long_kind == tick_parity else "tock→tick"
    residual = beat - np.where(kind == 0, means[0], means[1])
    jitter = float(residual.std(ddof=1)) if residual.size > 1 else math.nan
    swing = _swings(times, number)
    period_mean = swing.mean() / 2 if swing.size else mean_beat
    swing_err = swing.std(ddof=1) / math.sqrt(swing.size) / 2 if swing.size > 1 else math.nan
    bpm = 60.0 / period_mean
    return BeatStatistics(
        ticks=int(times.size),
        beats=int(beat.size),
        bpm=bpm,
        bpm_error=bpm * swing_err / period_mean,
        period=float(period_mean),
        jitter=jitter,
        asymmetry=float(asym),
        asymmetry_error=float(asym_err),
        long_beat=long_beat,
        tick_is_louder=tick_is_louder,
        beat_number=number,
        is_tock=(number % 2) == tock_parity,
        missed=int(np.sum(steps - 1)),
    )


def asymmetry_from_offset(offset: float, amplitude: float) -> float:
    """The asymmetry (per cent of a beat) of a metronome that ticks when its pendulum,
    swinging as θ = A sin ωt, passes θ = ``offset`` instead of the vertical.

    It passes θ = ε at ωt = arcsin(ε/A) and π − arcsin(ε/A), so its beats are
    (π ∓ 2 arcsin(ε/A))/ω: (long − short)/mean = (4/π) arcsin(ε/A).
    """
    return 400.0 / math.pi * math.asin(abs(offset) / amplitude)


def _swings(times: np.ndarray, number: np.ndarray) -> np.ndarray:
    """Non-overlapping full swings: t(n + 2) − t(n) for even n where both were heard."""
    where = np.searchsorted(number, number + 2)
    ok = (where < number.size) & (number % 2 == 0)
    ok[ok] &= number[where[ok]] == number[ok] + 2
    return times[where[ok]] - times[ok]

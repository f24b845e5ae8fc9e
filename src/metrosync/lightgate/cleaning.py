"""Cleaning: gate edges → one pass per period, in one direction (paper §2).

Contract: `clean_channel` takes one gate's interrupted/open states over the record
times and returns `ChannelPasses`: the kept passes (one per period, one direction),
the dropped opposite passes, the number of periods between consecutive kept passes,
and a count of every interruption dropped, by reason. `clean_log` does it for every
gate of a `GateLog`.

The steps:

1. *Interruptions.* Each spell of the interrupted state is one interruption; one
   already under way at the first record or still under way at the last is partial
   and dropped (its middle is unknown).
2. *Glitches.* Open spells shorter than ``glitch`` inside an interruption are
   flicker and are closed; interruptions shorter than ``glitch`` are dropped.
   Interruptions longer than ``max_interruption`` times the median are dropped too:
   a missed edge, or a bob at rest in the beam.
3. *Passes* are timed at the middle of each interruption.
4. *Direction.* A gate mounted off-centre (at θ = δ > 0) sees the bob twice a
   period, and the time spent beyond the gate (short, s) differs from the time on
   the other side (long, l). Each interval between passes is classed against the
   local medians of s, l and the period T: short, long, or a gap (missed passes, a
   stop). The pass that *opens* a short interval, or closes a long one, is kept;
   for δ > 0 that is the pass in the direction of increasing θ. The pass that closes
   a short interval, or opens a long one, is the period's second pass and is dropped.
   A pass with contradictory neighbours is dropped as ambiguous, one with no
   classifiable neighbour as isolated.
5. *Periods.* Against the median interval between kept passes (a run's period: most
   intervals are one period), a kept pass closer than 3/4 of it to the previous one
   is an extra (a duplicate), and an interval of about k ≥ 2 periods (missed passes)
   counts as k periods: the k − 1 missed passes are *bridged*. The median is used,
   not a local one, because where passes go missing the local intervals are mostly
   gaps. Intervals more than 1/4 period off a whole number are *irregular* (a gate
   that misses passes near the end of the swing also mixes up their directions).

When s and l differ by less than ``min_asymmetry`` (a centred gate), the direction
cannot be told: the channel is flagged, and every other pass is kept from the
first, so its phase may be off by π against the other channels.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .._words import plural
from ..errors import ParameterError
from .reader import GateLog

#: Default shortest interruption or open spell that is not a glitch, s.
DEFAULT_GLITCH = 5e-4
#: Interruptions longer than this many times the median are not passes.
DEFAULT_MAX_INTERRUPTION = 5.0
#: Smallest relative difference (l - s)/(l + s) that tells the directions apart.
DEFAULT_MIN_ASYMMETRY = 0.03
#: Half-width of the window (in intervals) of the local medians.
_WINDOW = 7

REASONS = (
    "second pass",
    "glitch",
    "too long",
    "partial at start",
    "partial at end",
    "ambiguous",
    "isolated",
    "duplicate",
)


@dataclass(frozen=True)
class ChannelPasses:
    """Passes of one gate after cleaning.

    kept : (P,) times of the kept passes, s.
    second : (Q,) times of the dropped opposite passes, s.
    cycles : (P-1,) periods between consecutive kept passes (1 unless passes were missed).
    dropped : count of dropped interruptions or passes, by reason (see `REASONS`).
    merged : open flickers closed inside interruptions.
    asymmetry : median (l - s)/(l + s) of the pass intervals, NaN if unknown.
    direction_ambiguous : True when the gate is too central to tell the directions apart.
    bridged : missed passes bridged (the sum of ``cycles - 1``).
    irregular : intervals between kept passes more than 1/4 period off a whole number.
    """

    kept: np.ndarray
    second: np.ndarray
    cycles: np.ndarray
    dropped: dict[str, int] = field(default_factory=dict)
    merged: int = 0
    asymmetry: float = float("nan")
    direction_ambiguous: bool = False
    bridged: int = 0
    irregular: int = 0

    def summary(self) -> str:
        """One line: passes kept, dropped by reason, flickers closed, bridged, flags."""
        why = ", ".join(f"{n} {r}" for r, n in self.dropped.items() if n) or "none"
        extra = f", {plural(self.merged, 'flicker')} closed" if self.merged else ""
        if self.bridged:
            extra += f", {plural(self.bridged, 'missed pass', 'missed passes')} bridged"
        if self.irregular:
            extra += f", {plural(self.irregular, 'irregular interval')}"
        flag = " [direction ambiguous: gate too central]" if self.direction_ambiguous else ""
        return f"kept {self.kept.size}, dropped {sum(self.dropped.values())} ({why}){extra}{flag}"


def interruptions(times: np.ndarray, interrupted: np.ndarray):
    """Complete interruptions of one gate.

    times : (R,) record times.   interrupted : (R,) bool state after each record.
    Returns (starts, ends, partial_start, partial_end): arrays of the complete
    interruptions' start and end times, and whether one was under way at the first
    record or still at the last.
    """
    state = np.asarray(interrupted, dtype=bool)
    diff = np.diff(state.astype(np.int8))
    starts = times[1:][diff == 1]
    ends = times[1:][diff == -1]
    partial_start = bool(state[0])
    partial_end = bool(state[-1])
    if partial_start:
        ends = ends[1:]
    if partial_end:
        starts = starts[:-1]
    return starts, ends, partial_start, partial_end


def clean_channel(
    times: np.ndarray,
    interrupted: np.ndarray,
    *,
    glitch: float = DEFAULT_GLITCH,
    max_interruption: float = DEFAULT_MAX_INTERRUPTION,
    min_asymmetry: float = DEFAULT_MIN_ASYMMETRY,
) -> ChannelPasses:
    """Clean one gate: see the module docstring.

    times : (R,) record times, s, non-decreasing.   interrupted : (R,) bool.
    """
    _check(glitch, max_interruption, min_asymmetry)
    dropped = Counter({reason: 0 for reason in REASONS})
    times = np.asarray(times, dtype=float)
    starts, ends, p_start, p_end = interruptions(times, interrupted)
    dropped["partial at start"] += int(p_start)
    dropped["partial at end"] += int(p_end)
    # Close short open spells (flicker inside one interruption) before judging lengths.
    gaps = starts[1:] - ends[:-1]
    flicker = gaps < glitch
    merged = int(flicker.sum())
    if merged:
        keep_start = np.concatenate([[True], ~flicker])
        keep_end = np.concatenate([~flicker, [True]])
        starts, ends = starts[keep_start], ends[keep_end]
    length = ends - starts
    short = length < glitch
    dropped["glitch"] += int(short.sum())
    starts, ends, length = starts[~short], ends[~short], length[~short]
    if length.size:
        long = length > max_interruption * np.median(length)
        dropped["too long"] += int(long.sum())
        starts, ends = starts[~long], ends[~long]
    passes = 0.5 * (starts + ends)
    return _select(passes, dropped, merged, min_asymmetry)


def clean_log(log: GateLog, **options) -> list[ChannelPasses]:
    """`clean_channel` for every gate of ``log``; options as there."""
    states = log.interrupted
    return [clean_channel(log.times, states[:, k], **options) for k in range(log.channels)]


def cleaning_report(channels: list[ChannelPasses], source: str = "") -> str:
    """Human-readable account of the cleaning of every gate of one log."""
    head = f"cleaning {source}".rstrip()
    return "\n".join([head] + [f"  gate {k}: {c.summary()}" for k, c in enumerate(channels)])


def _check(glitch, max_interruption, min_asymmetry) -> None:
    if not (np.isfinite(glitch) and glitch >= 0):
        raise ParameterError(f"`glitch` must be a time >= 0 s, got {glitch!r}.")
    if not (np.isfinite(max_interruption) and max_interruption > 1):
        raise ParameterError(f"`max_interruption` must be a factor > 1, got {max_interruption!r}.")
    if not (np.isfinite(min_asymmetry) and 0 <= min_asymmetry < 1):
        raise ParameterError(f"`min_asymmetry` must be in [0, 1), got {min_asymmetry!r}.")


def _local_median(values: np.ndarray, size: int) -> np.ndarray:
    """Median of ``values`` in a window of ``2*_WINDOW+1`` around each of ``size`` slots."""
    padded = np.concatenate([np.full(_WINDOW, np.nan), values, np.full(_WINDOW + 1, np.nan)])
    windows = sliding_window_view(padded, 2 * _WINDOW + 1)[:size]
    out = np.full(size, np.nan)
    has = np.isfinite(windows).any(axis=1)
    out[has] = np.nanmedian(windows[has], axis=1)
    return out


def _select(
    passes: np.ndarray, dropped: Counter, merged: int, min_asymmetry: float
) -> ChannelPasses:
    empty = np.empty(0)
    if passes.size < 3:
        dropped["isolated"] += int(passes.size)
        return ChannelPasses(empty, empty, np.empty(0, dtype=np.int64), dict(dropped), merged)
    d = np.diff(passes)
    pair_sum = d[:-1] + d[1:]
    pair_min = np.minimum(d[:-1], d[1:])
    pair_max = np.maximum(d[:-1], d[1:])
    period = _local_median(pair_sum, d.size)
    s = _local_median(pair_min, d.size)
    l_ = _local_median(pair_max, d.size)
    asym = float(np.nanmedian((l_ - s) / (l_ + s)))
    if not asym >= min_asymmetry:
        kept, second = passes[0::2], passes[1::2]
        dropped["second pass"] += second.size
        kept, cycles, bridged, irregular = _count_periods(kept, dropped)
        return ChannelPasses(
            kept, second, cycles, dict(dropped), merged, asym, True, bridged, irregular
        )

    # Interval classes: 0 odd (too short), 1 short, 2 long, 3 gap.
    cls = np.full(d.size, 3, dtype=np.int8)
    cls[d < (l_ + period) / 2] = 2
    cls[d < (s + l_) / 2] = 1
    cls[d < s / 2] = 0
    before = np.concatenate([[-1], cls])
    after = np.concatenate([cls, [-1]])
    opens = (after == 1).astype(int) + (before == 2)
    closes = (before == 1).astype(int) + (after == 2)
    is_kept = (opens > 0) & (closes == 0)
    is_second = (closes > 0) & (opens == 0)
    dropped["ambiguous"] += int(((opens > 0) & (closes > 0)).sum())
    dropped["isolated"] += int(((opens == 0) & (closes == 0)).sum())
    dropped["second pass"] += int(is_second.sum())
    kept, cycles, bridged, irregular = _count_periods(passes[is_kept], dropped)
    return ChannelPasses(
        kept, passes[is_second], cycles, dict(dropped), merged, asym, False, bridged, irregular
    )


def _count_periods(kept: np.ndarray, dropped: Counter):
    """Drop extra passes and count the periods between the rest (step 5).

    Returns (kept, cycles (P-1,), bridged, irregular); extras count as "duplicate".
    """
    if kept.size < 2:
        return kept, np.ones(max(kept.size - 1, 0), dtype=np.int64), 0, 0
    period = float(np.median(np.diff(kept)))
    keep = np.ones(kept.size, dtype=bool)
    last = 0
    for j in range(1, kept.size):
        if kept[j] - kept[last] < 0.75 * period:
            keep[j] = False
        else:
            last = j
    dropped["duplicate"] += int((~keep).sum())
    kept = kept[keep]
    ratio = np.diff(kept) / period
    cycles = np.maximum(np.rint(ratio), 1).astype(np.int64)
    irregular = int((np.abs(ratio - cycles) > 0.25).sum())
    return kept, cycles, int((cycles - 1).sum()), irregular

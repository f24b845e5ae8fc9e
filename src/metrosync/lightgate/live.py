"""What the live panel of ``record`` and ``analyze --follow`` shows, from a capture so far.

Contract: `live_status` turns a `GateLog` (the whole capture, or its recent part for
a long run) into a `LiveStatus`: per gate the beam interruptions counted, the current
frequency and how long it has been silent; and r(t) over the gates that pass, on the
grid `analyze` uses, with its last value.

* Current BPM: 120 beats per period over the last `BPM_PERIODS` kept periods.
* Silent: no edge for longer than `SILENT_AFTER` s or three of the gate's own
  periods, whichever is longer; ``idle`` adds the wall-clock time since the last line
  arrived (when nothing at all arrives, the logger's clock does not move).
* Never changed: a gate whose level never changed over the whole capture (an unwired
  gate, or no pendulum in its beam); it is silent too, and left out of r.
* r(t) uses the chosen gates that are not silent and have two kept passes. Because a
  phase is interpolated between passes, r is known only up to the earliest of those
  gates' last passes: its newest point trails the newest record by up to a period
  (``r_lag``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..observables import crossings as ph
from .channels import check_channels, never_changed
from .cleaning import clean_log
from .gatelog import GateLog

#: A gate with no edge for this long (s), or three of its periods if longer, is silent.
SILENT_AFTER = 5.0
#: Kept periods the current frequency is measured over.
BPM_PERIODS = 8


@dataclass(frozen=True)
class GateStatus:
    """One gate: ``passes`` beam interruptions, ``bpm`` now (NaN before two passes),
    ``silent_for`` s since its last edge (inf: none in the part analysed), ``silent``,
    ``never_changed`` over the whole capture."""

    gate: int
    passes: int
    bpm: float
    silent_for: float
    silent: bool
    never_changed: bool = False


@dataclass(frozen=True)
class LiveStatus:
    """The panel's content.

    span : seconds between the first and last record analysed.
    records : records analysed.   gates : per chosen gate.
    r_time, r : r(t) on its grid (s since the first record analysed).
    r_gates : gates r is computed over.   r_lag : newest record time − newest r time, s.
    records_lost, restarts : from the reader.
    never_changed : chosen gates whose level never changed over the whole capture.
    """

    span: float
    records: int
    gates: tuple[GateStatus, ...]
    r_time: np.ndarray
    r: np.ndarray
    r_gates: tuple[int, ...]
    r_lag: float
    records_lost: int = 0
    restarts: int = 0
    never_changed: tuple[int, ...] = ()

    @property
    def r_last(self) -> float:
        """The newest value of r, NaN when none yet."""
        return float(self.r[-1]) if self.r.size else math.nan


def live_status(
    log: GateLog,
    *,
    channels: Sequence[int] | None = None,
    passes: Sequence[int] | None = None,
    changes: Sequence[int] | None = None,
    idle: float = 0.0,
    grid_dt: float = 0.1,
) -> LiveStatus:
    """The live panel's content for ``log``.

    channels : gates to show and use for r (0-based); default all. A list that does not
        fit the log's gates is a `ParameterError` (`channels.check_channels`).
    passes : per gate of the log, beam interruptions counted over the whole capture
        (`LogFollower.interruptions`); default those in ``log``.
    changes : per gate, level changes over the whole capture (`LogFollower.changes`);
        default: a gate never changed if it does not change in ``log``.
    idle : wall-clock seconds since the last line arrived.
    grid_dt : spacing of the r(t) grid, s.
    """
    chosen = check_channels(channels, log.channels)
    dead = (set(never_changed(log.levels)) if changes is None else
            {k for k in range(log.channels) if changes[k] == 0})  # fmt: skip
    cleaned = clean_log(log)
    times = log.times
    end = float(times[-1])
    changed = np.diff(log.levels.astype(np.int8), axis=0) != 0
    gates, usable = [], []
    for k in chosen:
        c = cleaned[k]
        edges = np.flatnonzero(changed[:, k])
        since = end - float(times[edges[-1] + 1]) + idle if edges.size else math.inf
        period = float(np.median(np.diff(c.kept) / c.cycles)) if c.kept.size >= 2 else 0.0
        silent = since > max(SILENT_AFTER, 3 * period)
        count = int(passes[k]) if passes is not None else int(edges.size // 2)
        gates.append(GateStatus(k, count, _bpm(c.kept, c.cycles), since, silent or k in dead,
                                k in dead))  # fmt: skip
        if not silent and k not in dead and c.kept.size >= 2:
            usable.append(k)
    r_time, r = np.empty(0), np.empty(0)
    if len(usable) >= 2:
        spans = [(float(cleaned[k].kept[0]), float(cleaned[k].kept[-1])) for k in usable]
        r_time = ph.common_grid(spans, grid_dt)
        if r_time.size:
            r = ph.order_on_grid([(cleaned[k].kept, cleaned[k].cycles) for k in usable], r_time)
    lag = end - float(r_time[-1]) if r_time.size else math.nan
    return LiveStatus(
        span=end,
        records=len(times),
        gates=tuple(gates),
        r_time=r_time,
        r=r,
        r_gates=tuple(usable),
        r_lag=lag,
        records_lost=log.records_lost,
        restarts=len(log.restarts),
        never_changed=tuple(k for k in chosen if k in dead),
    )


def _bpm(kept: np.ndarray, cycles: np.ndarray) -> float:
    if kept.size < 2:
        return math.nan
    n = min(BPM_PERIODS, cycles.size)
    return float(120.0 * np.sum(cycles[-n:]) / (kept[-1] - kept[-n - 1]))

"""The phase of one metronome's ticks in another's beat.

Contract: `phase_difference(reference, times, period)` gives, for each of ``times``
(K,), the fraction of the reference metronome's beat that has passed since its last
tick, as an angle in (−π, π]: 0 when they tick together. Like the acoustic order
parameter, it sees the ticks, not the swings: the pendulums' phase difference is this
angle halved, or halved plus π (anti-phase pendulums tick together). Which tick
belongs to which metronome is `separation`'s business.
"""

from __future__ import annotations

import numpy as np


def phase_difference(reference: np.ndarray, times: np.ndarray, period: float) -> np.ndarray:
    """(K,) phase (rad, in (−π, π]) of each of ``times`` in the beat of ``reference``
    (sorted tick times); NaN outside it or across a missed beat."""
    idx = np.searchsorted(reference, times, side="right")
    ok = (idx > 0) & (idx < reference.size)
    out = np.full(times.size, np.nan)
    prev = reference[np.clip(idx - 1, 0, reference.size - 1)]
    nxt = reference[np.clip(idx, 0, reference.size - 1)]
    beat = nxt - prev
    ok &= beat < 1.5 * period
    frac = (times - prev) / np.where(beat > 0, beat, 1.0)
    out[ok] = np.angle(np.exp(2j * np.pi * frac[ok]))
    return out

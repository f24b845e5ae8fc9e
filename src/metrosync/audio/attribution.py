"""Telling two metronomes apart: by side (stereo) or by loudness, and their phase.

Contract: `attribute_pair(times, strength, channel_strength, period)` tries to split
one tick train (K,) into two metronomes and returns an `Attribution`, whose
``labels`` (K,) are 0, 1, or −1 for a tick that belongs to neither (two ticks heard as
one, a stray sound); or None with the reason it could not.

The feature is the balance (L − R)/(L + R) of each tick's peak amplitudes in a stereo
recording, where the metronomes stand apart, and else its loudness (dB). The ticks are split in
two by the threshold that minimises the spread within the groups (Otsu). The split
is accepted only when the groups are far apart for their spreads, |μ₀ − μ₁| /
√((σ₀² + σ₁²)/2) ≥ `MIN_SEPARATION`, each holds at least a quarter of the ticks, at
least `MIN_ATTRIBUTED` of the ticks fall in one, and each is a steady train with a tick
in most beats of the recording; a tick more than `OUTLIER` spreads from
its group's mean is left unattributed. Metronome 0 is the left (stereo) or the louder
one.

Phase difference: for each tick of metronome 1, the fraction of metronome 0's beat
that has passed since 0's last tick, as an angle in (−π, π]: 0 when they tick
together. Like the acoustic order parameter, it sees the ticks, not the swings: the
pendulums' phase difference is this angle halved, or halved plus π (anti-phase
pendulums tick together).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_SEPARATION = 3.0
OUTLIER = 4.0
MIN_SHARE = 0.25
MIN_ATTRIBUTED = 0.8


@dataclass(frozen=True)
class Attribution:
    """Two metronomes found in one tick train.

    method : ``"stereo"`` or ``"loudness"``.
    labels : (K,) 0, 1, or −1 (neither).
    separation : distance between the groups in units of their spread.
    phase_difference : (K,) for ticks of metronome 1, their phase in 0's beat, rad
        (NaN elsewhere, and where 0 missed a beat).
    """

    method: str
    labels: np.ndarray
    separation: float
    phase_difference: np.ndarray


def attribute_pair(times, strength, channel_strength, period: float):
    """(Attribution, "") or (None, reason); see the module docstring."""
    times = np.asarray(times, dtype=float)
    reasons = []
    features = []
    if channel_strength.shape[1] == 2:
        left, right = (10 ** (channel_strength[:, c] / 20) for c in (0, 1))
        features.append(("stereo", (left - right) / (left + right)))
    features.append(("loudness", np.asarray(strength, dtype=float)))
    for method, feature in features:
        labels, separation, why = _split(feature)
        if labels is None:
            reasons.append(f"{method}: {why}")
            continue
        if np.mean(labels >= 0) < MIN_ATTRIBUTED:
            reasons.append(
                f"{method}: fewer than {MIN_ATTRIBUTED:.0%} of the ticks fall in a group"
            )
            continue
        beats = (times[-1] - times[0]) / period
        steady = [_is_steady(times[labels == g], period, beats) for g in (0, 1)]
        if not all(steady):
            reasons.append(f"{method}: the two groups are not each a steady tick train")
            continue
        phase = phase_difference(times[labels == 0], times, period)
        phase[labels != 1] = np.nan
        return Attribution(method, labels, separation, phase), ""
    return None, "; ".join(reasons)


def _split(feature: np.ndarray):
    """Otsu's two-group split of ``feature``: (labels or None, separation, reason)."""
    order = np.argsort(feature)
    x = feature[order]
    k = x.size
    if k < 8:
        return None, math.nan, "too few ticks"
    c1, c2 = np.cumsum(x), np.cumsum(x * x)
    n0 = np.arange(1, k)
    s0, q0 = c1[:-1], c2[:-1]
    s1, q1 = c1[-1] - s0, c2[-1] - q0
    within = (q0 - s0**2 / n0) + (q1 - s1**2 / (k - n0))
    cut = int(np.argmin(within)) + 1
    low, high = x[:cut], x[cut:]
    if min(low.size, high.size) < MIN_SHARE * k:
        return None, math.nan, "no two groups of similar size"
    spread = math.sqrt(0.5 * (low.var() + high.var())) or 1e-9
    separation = (high.mean() - low.mean()) / spread
    if separation < MIN_SEPARATION:
        return (
            None,
            separation,
            (f"the groups overlap (separation {separation:.1f} < {MIN_SEPARATION:g} spreads)"),
        )
    labels = np.full(k, -1, dtype=np.int8)
    # metronome 0: the higher feature (louder, or more to the left)
    g0 = np.abs(feature - high.mean()) <= OUTLIER * max(high.std(), 1e-9)
    g1 = np.abs(feature - low.mean()) <= OUTLIER * max(low.std(), 1e-9)
    labels[g0 & ~g1] = 0
    labels[g1 & ~g0] = 1
    return labels, float(separation), ""


def _is_steady(times: np.ndarray, period: float, beats: float) -> bool:
    """A tick in most beats of the recording, one beat apart."""
    if times.size < 4 or times.size < 0.6 * beats:
        return False
    gaps = np.diff(times)
    return bool(abs(np.median(gaps) / period - 1) < 0.25)


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

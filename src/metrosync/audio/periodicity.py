"""Candidate tempi: a periodicity search over the onset times (epoch folding).

The model. Onsets at times t_i with weights w_i (their strength) hold, among clutter,
trains of ticks that recur every beat T of some metronome. Folding the onsets at a
trial beat, each onset gets the phase 2π t_i / T; the onsets of a train at that beat
share a phase, those of anything else spread over the circle. The Rayleigh statistic

    Z(f) = |Σ w_i exp(2πi f t_i)|² / Σ w_i²,        f = 1/T,

measures how much they share (the power of the weighted onset train at frequency f).
For onsets with no period at f it is exponentially distributed with mean 1. The
search sums it over the first `MODEL.harmonics` harmonics, Z²_m(f) = Σ_{h≤m} Z(hf) (the Z²_m
test of pulsar timing, Buccheri et al., A&A 128, 245, 1983): two trains at one beat
half a beat apart cancel at f and add at 2f, and a train of one tempo still peaks
highest at its own f. For clutter Z²_m is a Gamma(m, 1) variable, so a peak above its
(1 − α/F) quantile, F the number of independent frequencies searched, is a train with
a false-alarm probability of about α: the one threshold here has that meaning.

Each segment is tapered (a Hann window on the weights), so that a strong train's
sidelobes stay below the threshold. A train at beat T also peaks at its harmonics
f = n/T (every n-th fold lines up), and a limp moves part of its power to the swing's
frequency 1/(2T); this search lists them all, as candidates: which of them are
metronomes is the timing model's to say (a harmonic predicts beats nobody heard).
Over long recordings the onsets are folded in segments of at most `SEGMENT` seconds
and the powers added, so that the spring's slow drift does not smear a peak, at the
cost of a resolution of about 1/SEGMENT in f.

Contract: `periodogram(times, weights, bpm_range)` returns the tempo grid (BPM, ticks a
minute) and Z on it; `candidate_tempi(...)` the peaks above the threshold, refined.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from .settings import MODEL

#: Longest stretch of the recording folded coherently, s.
SEGMENT = 60.0
#: Frequencies a phasor is stepped over before it is computed afresh.
_RESEED = 64
#: Grid points per independent frequency (1/segment), so that no peak falls between.
OVERSAMPLE = 5


@dataclass(frozen=True)
class Candidate:
    """One peak of the periodogram: ``bpm`` (ticks a minute) and its power ``z``."""

    bpm: float
    z: float


def periodogram(times, weights=None, bpm_range=MODEL.bpm_range, *, segment: float = SEGMENT):
    """The tempo grid (F,) in BPM and the Rayleigh power Z²_m (F,) on it (`MODEL.harmonics`
    harmonics), summed over segments of at most ``segment`` s and normalised so that
    pure clutter gives a mean of `MODEL.harmonics` at every tempo."""
    t = np.asarray(times, dtype=float)
    w = np.ones_like(t) if weights is None else np.asarray(weights, dtype=float)
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    pieces = max(1, math.ceil(span / segment))
    length = max(span / pieces, 1.0)
    lo, hi = (b / 60.0 for b in bpm_range)
    f = np.arange(lo, hi, 1.0 / (OVERSAMPLE * length))
    edges = t[0] + length * np.arange(pieces + 1)
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, pieces - 1)
    z = np.zeros(f.size)
    for p in range(pieces):
        mine = which == p
        # a Hann taper over the segment: a strong train's sidelobes (a plain fold's
        # reach 5 % of its peak) would otherwise rise above the threshold as tempi of
        # their own
        taper = np.sin(np.pi * np.clip((t[mine] - edges[p]) / length, 0.0, 1.0)) ** 2
        tp, wp = t[mine], w[mine] * taper
        if tp.size < 2:
            continue
        power = _rayleigh(float(f[0]), 1.0 / (OVERSAMPLE * length), f.size, tp - tp[0], wp,
                          MODEL.harmonics)  # fmt: skip
        z += power / float(np.sum(wp**2))
    return 60.0 * f, z / pieces


@nb.njit(cache=True)
def _rayleigh(f0: float, df: float, nf: int, t, w, harmonics: int):
    """(nf,) Σ_h |Σ_k w_k exp(2πi h f t_k)|² over h = 1 … ``harmonics``, at f = f0 + j·df:
    each onset's phasor stepped from one frequency to the next by one multiplication
    (set afresh every `_RESEED` steps, so that rounding does not accumulate), and its
    harmonics as its powers."""
    sums = np.zeros((nf, harmonics), dtype=np.complex128)
    for k in range(t.size):
        step = cmath.exp(2j * math.pi * df * t[k])
        phasor = 1.0 + 0j
        for j in range(nf):
            if j % _RESEED == 0:
                phasor = cmath.exp(2j * math.pi * (f0 + j * df) * t[k])
            power = phasor
            for h in range(harmonics):
                sums[j, h] += w[k] * power
                power *= phasor
            phasor *= step
    out = np.zeros(nf)
    for j in range(nf):
        for h in range(harmonics):
            out[j] += sums[j, h].real ** 2 + sums[j, h].imag ** 2
    return out


def candidate_tempi(
    times,
    weights=None,
    bpm_range=MODEL.bpm_range,
    *,
    false_alarm: float = MODEL.false_alarm,
    segment: float = SEGMENT,
) -> list[Candidate]:
    """The periodogram's peaks above the false-alarm threshold, strongest first.

    Each peak's tempo is refined by a parabola through its three grid points. With
    ``P`` segments summed the clutter's power is a Gamma(mP, 1/P) variable (m =
    `MODEL.harmonics`); the threshold is its (1 − α/F) quantile, F the independent
    frequencies searched.
    """
    from scipy.stats import gamma

    bpm, z = periodogram(times, weights, bpm_range, segment=segment)
    t = np.asarray(times, dtype=float)
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    pieces = max(1, math.ceil(span / segment))
    independent = max(1.0, bpm.size / OVERSAMPLE)
    threshold = float(gamma.isf(false_alarm / independent, MODEL.harmonics * pieces,
                                scale=1.0 / pieces))  # fmt: skip
    inside = np.flatnonzero((z[1:-1] > z[:-2]) & (z[1:-1] >= z[2:]) & (z[1:-1] > threshold)) + 1
    found = []
    for i in inside:
        a, b, c = z[i - 1], z[i], z[i + 1]
        bend = a - 2 * b + c
        shift = 0.5 * (a - c) / bend if bend < 0 else 0.0
        found.append(Candidate(float(bpm[i] + shift * (bpm[1] - bpm[0])), float(b)))
    return sorted(found, key=lambda c: -c.z)

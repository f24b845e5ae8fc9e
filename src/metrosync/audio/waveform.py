"""Each metronome's learned waveform, and its ticks timed against it.

A metronome strikes the same impact at every beat of one kind, so its tick's waveform
is the same each time (the room adds the same reverberation); what differs is what
else rings there. The waveform is learned from the recording: the mean of its clean
ticks (no other onset from `MODEL.ring` before to `MODEL.sound_length` after) over
`QUIET` before the onset and `MODEL.sound_length` after it, band-passed as the detector
hears them, each aligned to the first by cross-correlation.

A tick is then timed as pulsar timing times a pulse (Taylor 1992, "Pulsar timing and
relativistic gravity"): by the shift at which the waveform best explains the
recording there. For a waveform s of unit norm and the recording x = a·s(t − τ) + n,
with n the noise and everything else that sounds, the least-squares (and, for white
Gaussian n, the maximum-likelihood) τ is the one that maximises the cross-correlation
⟨x, s(· − τ)⟩ with a > 0. Unlike the rise of the envelope, which sits later the louder
another's ring is under it, that estimate is not pulled by a background that does not
look like the tick. The shift is sought within `REACH` of the onset detected (two
onsets closer than that are one to the detector, so its onset may be either's) and
never past a neighbouring onset; a maximum at the window's edge is no estimate, and
the onset is kept. The waveform's own zero is the median of its clean ticks' detected
onsets less their matched times, so that a clean tick keeps its detected time on
average.

Contract: `learn(recording, scan, times)` returns the waveform of ticks at ``times`` (or
None: too few); `matched(recording, scan, waveform, lower, upper)` the time in each
window that best fits it (with the timing model's prior where given);
`retimed(recording, scan, impacts, heard)` every metronome's ticks so timed.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from . import detection as det
from .settings import MODEL

#: The quiet before a clean tick's onset that is part of its waveform, s: where the
#: sound is silence, so that a match slid late pays for the energy it puts there.
QUIET = 1e-3
#: Most of a metronome's clean ticks averaged into its waveform, and fewest to learn it
#: from.
SOUND_TICKS, MIN_SOUND_TICKS = 48, 8
#: A tick is sought this far either side of its detected onset, s.
REACH = det.RESOLUTION
#: Onsets timed at once.
BLOCK = 256


def is_clean(t: np.ndarray, ticks: np.ndarray, others: np.ndarray) -> np.ndarray:
    """(len(ticks),) whether no onset of ``others`` precedes each of ``ticks`` within
    `MODEL.ring` nor follows it within `MODEL.sound_length`: the metronome's sound alone.
    t : all onsets, s; ticks, others : indices into it."""
    other = np.sort(t[others])
    if not other.size:
        return np.ones(ticks.size, dtype=bool)
    j = np.searchsorted(other, t[ticks])
    before = t[ticks] - other[np.maximum(j - 1, 0)]
    after = other[np.minimum(j, other.size - 1)] - t[ticks]
    before[j == 0] = np.inf
    after[j == other.size] = np.inf
    return (before > MODEL.ring) & (after > MODEL.sound_length)


def bands(recording, scan, starts: np.ndarray, length: int) -> np.ndarray:
    """(K, length) the band-passed channel mix of frames [start, start + length) for each
    of ``starts``, filtered together (each padded by its own length on both sides)."""
    x = recording.segments(np.asarray(starts) - length, 3 * length).mean(axis=2)
    return signal.sosfiltfilt(scan.sos, x, axis=1)[:, length : 2 * length]


def learn(recording, scan, ticks_s: np.ndarray) -> np.ndarray | None:
    """The waveform of the clean ticks at ``ticks_s`` (s): `QUIET` before the onset and
    `MODEL.sound_length` after it, band-passed, aligned, averaged, of mean 0 and norm 1
    (None: fewer than `MIN_SOUND_TICKS`)."""
    if ticks_s.size < MIN_SOUND_TICKS:
        return None
    pick = ticks_s[np.linspace(0, ticks_s.size - 1, min(SOUND_TICKS, ticks_s.size)).astype(int)]
    rate = recording.sample_rate
    n = round((QUIET + MODEL.sound_length) * rate)
    slack = round(det.RESOLUTION * rate)
    starts = np.round(pick * rate).astype(np.int64) - round(QUIET * rate) - slack
    x = bands(recording, scan, starts, n + 2 * slack)
    reference = x[0, slack : slack + n]
    total = reference.copy()
    for row in x[1:]:
        lag = int(np.argmax(np.correlate(row, reference, mode="valid")))
        total += row[lag : lag + n]
    total -= total.mean()
    norm = np.linalg.norm(total)
    return total / norm if norm > 0 else None


def matched(recording, scan, waveform: np.ndarray, lower: np.ndarray, upper: np.ndarray,
            expected: np.ndarray | None = None, spread: np.ndarray | None = None
            ) -> np.ndarray:  # fmt: skip
    """(K,) for each window [lower, upper] (s) the time at which ``waveform`` explains
    the recording best (interpolated between samples by a parabola), or NaN where that
    lies at the window's edge or the waveform would be there upside down. The time is
    that of the waveform's onset (`QUIET` into it).

    With ``expected`` and ``spread`` (K,) s, the time is the posterior's mode: the
    likelihood of the shift, (⟨x, s⟩² / 2σ²) with σ² the residual's variance per sample
    at the best fit, times a Gaussian prior about ``expected`` of that spread."""
    if not np.size(lower):
        return np.zeros(0)
    # in blocks of onsets, so that memory stays that of a few hundred windows
    parts = []
    for first in range(0, np.size(lower), BLOCK):
        block = slice(first, first + BLOCK)
        prior = None if expected is None or spread is None else (expected[block], spread[block])
        parts.append(_matched(recording, scan, waveform, lower[block], upper[block], prior))
    return np.concatenate(parts)


def _matched(recording, scan, waveform, lower, upper, prior) -> np.ndarray:
    """`matched` for one block of windows; ``prior`` (expected, spread) or None."""
    rate = recording.sample_rate
    n, quiet = waveform.size, round(QUIET * rate)
    lo = np.floor(lower * rate).astype(np.int64)
    width = int(np.max(np.ceil(upper * rate).astype(np.int64) - lo)) + 1
    x = bands(recording, scan, lo - quiet, width + n - 1)
    dot = signal.fftconvolve(x, waveform[None, ::-1], mode="valid", axes=1)
    at = (lo[:, None] + np.arange(width)[None, :]) / rate
    inside = (at >= lower[:, None]) & (at <= upper[:, None])
    score = np.where(inside & (dot > 0), dot, -np.inf)
    rows = np.arange(lo.size)
    if prior is not None:
        expected, spread = prior
        top = np.argmax(score, axis=1)
        squares = np.concatenate([np.zeros((lo.size, 1)), np.cumsum(x * x, axis=1)], axis=1)
        energy = squares[rows, top + n] - squares[rows, top]
        noise = np.maximum(energy - dot[rows, top] ** 2, 1e-30) / (n - 1)
        away = (at - expected[:, None]) ** 2 / (2 * spread[:, None] ** 2)
        score = np.where(np.isfinite(score), dot**2 / (2 * noise[:, None]) - away, -np.inf)
    best = np.argmax(score, axis=1)
    i = np.clip(best, 1, width - 2)
    y0, y1, y2 = score[rows, i - 1], score[rows, i], score[rows, i + 1]
    edge = ~(np.isfinite(y0) & np.isfinite(y1) & np.isfinite(y2)) | (best != i)
    curve = np.where(edge, -1.0, y0 - 2 * y1 + y2)
    with np.errstate(invalid="ignore"):
        frac = np.where(curve < 0, 0.5 * (y0 - y2) / curve, 0.0)
    out = (lo + i + np.clip(np.nan_to_num(frac), -0.5, 0.5)) / rate
    return np.where(edge, np.nan, out)


def retimed(recording, scan, impacts: det.Ticks, heard) -> np.ndarray:
    """(K,) the onsets' times (s), each metronome's ticks timed against its learned
    waveform of their kind (tick or tock), the others as detected.

    heard : `decompose.Heard` of each metronome, whose ``ticks`` index the onsets."""
    t = impacts.time
    out = t.copy()
    # never past a neighbouring onset: one onset is one impact
    previous = np.concatenate([[-np.inf], t[:-1]])
    following = np.concatenate([t[1:], [np.inf]])
    sample = 1.0 / recording.sample_rate
    for h in heard:
        others = np.setdiff1d(np.arange(t.size), h.ticks)
        clean = is_clean(t, h.ticks, others)
        kinds = np.mod(h.beats, 2)
        timing = h.followed.timing
        for kind in (0, 1):
            of_kind = kinds == kind
            own, own_clean = h.ticks[of_kind], clean[of_kind]
            waveform = learn(recording, scan, t[own[own_clean]])
            if waveform is None:
                continue
            lower = np.maximum(t[own] - REACH, previous[own] + sample)
            upper = np.minimum(t[own] + REACH, following[own] - sample)
            # the waveform's zero, from the clean ticks, which need no prior
            offsets = t[own[own_clean]] - matched(recording, scan, waveform, lower[own_clean],
                                                  upper[own_clean])  # fmt: skip
            offsets = offsets[np.isfinite(offsets)]
            if offsets.size < MIN_SOUND_TICKS:
                continue
            zero = float(np.median(offsets))
            main = h.followed.structure[kind].main_impact.offset
            expected = timing.predict(h.beats[of_kind]) + main - zero
            spread = np.full(own.size, max(timing.jitter, sample))
            fit = matched(recording, scan, waveform, lower - zero, upper - zero, expected,
                          spread) + zero  # fmt: skip
            ok = np.isfinite(fit)
            out[own[ok]] = fit[ok]
    return out

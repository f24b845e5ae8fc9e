"""Each metronome's tick as this recording hears it, and ticks timed against it where
another metronome's impacts and ring overlap them.

Contract: `learn(recording, scan, times, trains)` returns one `Sound` per train (or
None where too few of its ticks sound alone); `retime(recording, scan, times,
trains, sounds)` returns the tick times (K,) with each tick that sounds in another
metronome's ring timed again, and how much each tick sounds like its train's sound.

A sound. The waveform the detector times (the channels' mix, band-passed forwards and
backwards: no delay) from `BEFORE` before each onset to `AFTER` after it, averaged
over the first `MAX_LEARNED` of the train's ticks that no other train's tick
overlaps (none began in the `AFTER` before, nor in the `AFTER` after), apart for the
ticks and the tocks (a tock can sound different); both together where one kind has
fewer than `MIN_CLEAR`.
It holds the tick's later impacts and the loudest of its ring.

Timing in a ring. A tick that begins within `AFTER` after another train's tick has its
onset timed on a sum of the two: the detector's onset rule reads the other's ring as
its background and times the tick late by a millisecond or two. Over `FIT_BEFORE`
before to `FIT_AFTER` after the detected onset, the waveform is fitted by least
squares as a·(own sound at τ) + Σ b_j·(sound j at its onset t_j), for every τ within
`SEARCH` of the detected onset, whole samples apart; the τ of the smallest residual
(refined on a parabola) is the onset. The other ticks keep their times: their onsets
are the first thing heard, where the detector is exact.

Likeness. The share of the window's energy (less what the other ticks explain) that
the tick's own sound explains at its best onset: above 0.4 for the corpus's ticks,
under 0.1 for a handling bump on a metronome's beat. A tick held by a train that
sounds less like it than `MIN_LIKENESS` is not that metronome's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy import signal

from .detection import _segments
from .trains import Train

#: Sound kept before each onset, s (room for the search below).
BEFORE = 8e-3
#: Sound kept after each onset, s: its later impacts and the loudest of its ring.
AFTER = 0.05
#: Ticks of one kind that sound alone, at least, for a sound of that kind.
MIN_CLEAR = 4
#: Ticks of one kind averaged, at most.
MAX_LEARNED = 64
#: Fit window around a tick's detected onset, s.
FIT_BEFORE = 3e-3
FIT_AFTER = 5e-3
#: Farthest a tick is moved, s.
SEARCH = 3e-3
#: A tick less like its train's sound than this is not its metronome's.
MIN_LIKENESS = 0.35
#: Filtered beyond each end of a segment, s: the band-pass settles there.
MARGIN = 10e-3


@dataclass(frozen=True)
class Sound:
    """One train's tick, sampled at the recording's rate from −`BEFORE` to `AFTER`.

    waves : (2, L) the sound of its even and its odd beats (tick and tock).
    onset : index of the onset in each wave.
    """

    waves: np.ndarray
    onset: int


def _filtered(recording, scan, starts: np.ndarray, length: int) -> np.ndarray:
    """(n, length) the band-passed channel mix from each of ``starts`` (samples, sorted)."""
    margin = round(MARGIN * recording.sample_rate)
    out = np.empty((starts.size, length))
    for first, seg in _segments(recording, starts - margin, length + 2 * margin, 2048):
        mix = seg.mean(axis=2)
        out[first : first + mix.shape[0]] = signal.sosfiltfilt(scan.sos, mix, axis=1)[
            :, margin : margin + length
        ]
    return out


def _others(times: np.ndarray, trains: list[Train]):
    """(owner (K,), parity (K,)) of each tick held by one train: −1 for none."""
    owner = np.full(times.size, -1, dtype=np.int64)
    parity = np.zeros(times.size, dtype=np.int64)
    claims = np.zeros(times.size, dtype=np.int64)
    for t in trains:
        claims[t.index] += 1
    for m, t in enumerate(trains):
        one = claims[t.index] == 1
        owner[t.index[one]] = m
        parity[t.index[one]] = t.beat[one] % 2
    return owner, parity


def learn(recording, scan, times: np.ndarray, trains: list[Train]) -> list[Sound | None]:
    """One `Sound` per train (see the module docstring)."""
    rate = recording.sample_rate
    before, after = round(BEFORE * rate), round(AFTER * rate)
    held = np.sort(np.concatenate([times[t.index] for t in trains])) if trains else times
    out: list[Sound | None] = []
    for train in trains:
        heard = ~train.masked
        index, parity = train.index[heard], train.beat[heard] % 2
        t = times[index]
        # alone: no tick of another train in the AFTER before or after (its own is held
        # too, but never that close)
        j = np.searchsorted(held, t)
        prev = np.where(j > 0, t - held[np.maximum(j - 1, 0)], np.inf)
        nxt = np.where(j + 1 < held.size, held[np.minimum(j + 1, held.size - 1)] - t, np.inf)
        alone = (prev > AFTER) & (nxt > AFTER)
        for kind in (0, 1):  # the first few of each kind: the mean has settled by then
            alone[np.flatnonzero(alone & (parity == kind))[MAX_LEARNED:]] = False
        if alone.sum() < MIN_CLEAR:
            out.append(None)
            continue
        starts = np.round(t[alone] * rate).astype(np.int64) - before
        order = np.argsort(starts)
        waves = _filtered(recording, scan, starts[order], before + after)
        kinds = parity[alone][order]
        both = waves.mean(axis=0)
        two = [waves[kinds == k].mean(axis=0) if (kinds == k).sum() >= MIN_CLEAR else both
               for k in (0, 1)]  # fmt: skip
        out.append(Sound(np.array(two), before))
    return out


def fit(recording, scan, at: np.ndarray, own: list, context: list) -> tuple:
    """(onsets (n,) s, likeness (n,)) of the ticks near ``at`` (n,) s, sorted: each
    fitted as its own wave (``own[i]``: a wave of a `Sound`, its onset at `BEFORE`)
    at the onset within `SEARCH` of at[i] that explains most of the window, plus the
    waves ``context[i]`` ((wave, onset s) pairs: the other ticks that sound there)
    at their onsets. Likeness: the share of the window's energy, less what the
    context explains, that the tick's own wave explains (1: it sounds just like it)."""
    rate = recording.sample_rate
    fit_before, fit_after = round(FIT_BEFORE * rate), round(FIT_AFTER * rate)
    onset = round(BEFORE * rate)
    search = round(SEARCH * rate)
    width = fit_before + fit_after
    cols = np.arange(width)
    centre = np.round(np.asarray(at) * rate).astype(np.int64)
    segments = _filtered(recording, scan, centre - fit_before, width)
    times = np.asarray(at, dtype=float)
    # the own wave at every onset within the search, read over the window: the span of
    # it that the window can see, slid along it
    lo = onset - fit_before - search
    explained = np.empty((times.size, 2 * search + 1))
    energy = np.einsum("nw,nw->n", segments, segments)
    alone = np.array([not c for c in context], dtype=bool)
    # the ticks no other overlaps, a whole sound at a time: one matrix product each
    where = np.array([w.ctypes.data for w in own])  # one sound's rows share their memory
    for address in np.unique(where):
        rows = np.flatnonzero(alone & (where == address))
        wave = own[rows[0]] if rows.size else None
        if rows.size:
            shifted = sliding_window_view(wave[lo : lo + width + 2 * search], width)
            norm = np.einsum("kw,kw->k", shifted, shifted)
            explained[rows] = (segments[rows] @ shifted.T) ** 2 / np.maximum(norm, 1e-30)
    for row in np.flatnonzero(~alone):
        span = own[row][lo : lo + width + 2 * search]
        cumulative = np.concatenate([[0.0], np.cumsum(span * span)])
        norm = cumulative[width:] - cumulative[:-width]
        columns = []
        for other, when in context[row]:
            p = centre[row] - fit_before + cols - (round(when * rate) - onset)
            inside = (p >= 0) & (p < other.size)
            columns.append(np.where(inside, other[np.clip(p, 0, other.size - 1)], 0.0))
        q, _ = np.linalg.qr(np.array(columns).T)
        y = segments[row] - q @ (q.T @ segments[row])
        energy[row] = y @ y
        # what of the own wave the context could explain is not the tick's
        for j in range(q.shape[1]):
            norm = norm - np.correlate(span, q[:, j], "valid") ** 2
        explained[row] = np.correlate(span, y, "valid") ** 2 / np.maximum(norm, 1e-30)
    # index k: the onset `search` − k samples after the window's centre; refined on a
    # parabola through the best and its neighbours
    best = np.argmax(explained, axis=1)
    rows = np.arange(times.size)
    e1 = explained[rows, best]
    e0 = explained[rows, np.maximum(best - 1, 0)]
    e2 = explained[rows, np.minimum(best + 1, explained.shape[1] - 1)]
    denom = e0 - 2 * e1 + e2
    inner = (best > 0) & (best < explained.shape[1] - 1) & (denom < 0)
    frac = np.where(inner, 0.5 * (e0 - e2) / np.where(inner, denom, -1.0), 0.0)
    times = (centre + search - best - frac) / rate
    likeness = e1 / np.maximum(energy, 1e-30)
    return times, likeness


def _context(times, owner, parity, sounds, i, held) -> list:
    """(wave, onset) of the ticks of other trains that sound in tick i's fit window."""
    h = times[held]
    near = held[(h > times[i] - AFTER) & (h < times[i] + FIT_AFTER + SEARCH)]
    return [(sounds[owner[k]].waves[parity[k]], times[k]) for k in near
            if owner[k] != owner[i] and sounds[owner[k]] is not None]  # fmt: skip


def retime(recording, scan, times: np.ndarray, trains: list[Train], sounds):
    """((K,) ``times`` with each tick that sounds in another train's ring timed again on
    the sum of the sounds, (K,) each held tick's likeness to its train's sound (NaN
    for the others)); see the module docstring."""
    times = np.asarray(times, dtype=float)
    out = times.copy()
    likeness = np.full(times.size, np.nan)
    owner, parity = _others(times, trains)
    masked = np.zeros(times.size, dtype=bool)
    for t in trains:
        masked[t.index[t.masked]] = True
    held = np.flatnonzero(owner >= 0)
    held = held[[sounds[owner[i]] is not None for i in held]]
    if held.size == 0:
        return out, likeness
    own = [sounds[owner[i]].waves[parity[i]] for i in held]
    context = [_context(times, owner, parity, sounds, i, held) for i in held]
    fitted, likeness[held] = fit(recording, scan, times[held], own, context)
    h = times[held]
    j = np.searchsorted(h, h)
    in_ring = np.where(j > 0, h - h[np.maximum(j - 1, 0)], np.inf) <= AFTER
    # a masked tick is the onset of the tick that hid it: it keeps that time
    moved = in_ring & ~masked[held]
    out[held[moved]] = fitted[moved]
    return out, likeness

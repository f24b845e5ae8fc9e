"""Telling metronomes apart by their sound: each impact's spectrum, clustered into voices.

Contract: `impact_features(recording, times)` reads the few milliseconds after each
impact onset (K,) and returns `Features`; `cluster_voices(features)` groups the
impacts into voices and returns `Voices`, whose ``labels`` (K,) are 0..V−1, or −1 for
an impact that sounds like none of them (two ticks at once, a bump, a stray sound).

Features. The power spectrum of the first `FEATURE_LENGTH` of sound after the onset
(tapered), less that of as long just before it (the ringing of an earlier tick, which
goes on), is cut into `BANDS` bands spaced evenly in log frequency from `LOW_EDGE` to
16 kHz (or 0.45 × the rate); the feature is each band's level in dB (at least
`BAND_RANGE` below the loudest band: fainter bands hold noise) minus the mean over the
bands: the spectral shape, whatever the loudness. Two metronomes of
different makes differ there more than in loudness, and a microphone, a room or a
phone's filter colours every tick alike. The loudness itself (dB, weighted by
`LEVEL_WEIGHT`) and, with several channels, each channel's level minus their mean
(dB: where the metronome stands relative to the microphones) are added.

Clustering. k-means (k-means++ seeds, the best of `RESTARTS`) for k = 1 ..
`MAX_VOICES`; a grouping is kept when its voices are all far apart for their spreads
(along the line between two centres, |μ_a − μ_b| / √((σ_a² + σ_b²)/2) ≥
`MIN_SEPARATION`, the spread taken as at least `SPREAD_FLOOR`: halves of one voice
split apart come out near 2.7) and each holds at least `MIN_SHARE` of the impacts
(and 8; smaller groups are odd impacts, not voices). `cluster_voices` returns every
grouping kept, the most voices first: the caller keeps the first whose voices each
carry a tick train. An impact farther from its centre than `OUTLIER`
times its voice's median distance is left out (−1). A voice is a sound, not yet a
metronome: a tick and a tock that sound different are two voices of one metronome, and
two metronomes of one make are one voice (`trains` sorts that out).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import fft, signal

from .detection import _segments
from .reader import Recording

FEATURE_LENGTH = 6e-3
#: Sound kept before the onset, s (the onset is timed to a fraction of a sample).
FEATURE_LEAD = 0.3e-3
BANDS = 16
LOW_EDGE = 500.0
HIGH_EDGE = 16000.0
LEVEL_WEIGHT = 0.5
#: Band levels are counted down to this far (dB) below the loudest band.
BAND_RANGE = 30.0
MAX_VOICES = 16
RESTARTS = 4
MIN_SEPARATION = 5.0
MIN_SHARE = 0.02
OUTLIER = 4.0
#: Smallest spread a voice is credited with, dB: identical clicks vary by less, and
#: must not make voices of their rounding.
SPREAD_FLOOR = 1.0
#: Impacts clustered at most (a random sample; the rest go to the nearest centre).
SAMPLE = 4000


@dataclass(frozen=True)
class Features:
    """What each impact sounds like.

    shape : (K, B) band levels minus their mean, dB.
    level : (K,) loudness over the bands, dB.
    channel_level : (K, C) each channel's level minus the channels' mean, dB.
    """

    shape: np.ndarray
    level: np.ndarray
    channel_level: np.ndarray

    def matrix(self) -> np.ndarray:
        """(K, D) the vectors clustered: shape, weighted loudness, channel balance."""
        parts = [self.shape, LEVEL_WEIGHT * (self.level - np.median(self.level))[:, None]]
        if self.channel_level.shape[1] > 1:
            parts.append(self.channel_level)
        return np.column_stack(parts)


@dataclass(frozen=True)
class Voices:
    """Impacts grouped by their sound.

    labels : (K,) voice of each impact, −1 for none.
    count : number of voices V.
    separation : smallest distance between two voices in units of their spread
        (inf for one voice).
    tried : the separations of every k tried, for the record.
    """

    labels: np.ndarray
    count: int
    separation: float
    tried: dict


def _bands(rate: int, nfft: int) -> np.ndarray:
    """(BANDS, nfft//2 + 1) 0/1 matrix summing the power spectrum into bands."""
    top = min(HIGH_EDGE, 0.45 * rate)
    edges = np.geomspace(min(LOW_EDGE, top / 4), top, BANDS + 1)
    freqs = np.fft.rfftfreq(nfft, 1.0 / rate)
    which = np.searchsorted(edges, freqs, side="right") - 1
    m = np.zeros((BANDS, freqs.size))
    inside = (which >= 0) & (which < BANDS)
    m[which[inside], np.flatnonzero(inside)] = 1.0
    return m


def impact_features(recording: Recording, times: np.ndarray, *, chunk: int = 4096) -> Features:
    """`Features` of the impacts at ``times`` (K,), s, sorted (see the module docstring)."""
    rate = recording.sample_rate
    lead = round(FEATURE_LEAD * rate)
    length = lead + round(FEATURE_LENGTH * rate)
    nfft = fft.next_fast_len(max(1024, 2 * length))
    taper = signal.windows.tukey(length, 0.3).astype(np.float32)
    bands = _bands(rate, nfft)
    # the same length before the onset too: what was already sounding is taken off
    starts = np.round(np.asarray(times) * rate).astype(np.int64) - lead - length
    k, c = starts.size, recording.channels
    shape = np.empty((k, BANDS))
    level = np.empty(k)
    channel = np.zeros((k, c))
    if k == 0:
        return Features(shape, level, channel)
    for first, seg in _segments(recording, starts, 2 * length, chunk):
        sl = slice(first, first + seg.shape[0])
        power = []
        for part in (seg[:, :length], seg[:, length:]):
            spectra = np.abs(fft.rfft(part * taper[None, :, None], n=nfft, axis=1)) ** 2
            power.append(np.einsum("bf,nfc->nbc", bands, spectra))
        before, after = power
        per_channel = np.maximum(after - before, 1e-3 * after) + 1e-14
        mixed = 10 * np.log10(per_channel.mean(axis=2))
        # bands far below the loudest hold noise and the rounding of the onset
        mixed = np.maximum(mixed, mixed.max(axis=1, keepdims=True) - BAND_RANGE)
        level[sl] = 10 * np.log10(per_channel.sum(axis=1).mean(axis=1))
        shape[sl] = mixed - mixed.mean(axis=1, keepdims=True)
        if c > 1:
            total = 10 * np.log10(per_channel.sum(axis=1))
            channel[sl] = total - total.mean(axis=1, keepdims=True)
    return Features(shape, level, channel)


def cluster_voices(features: Features, *, seed: int = 0) -> list[Voices]:
    """The ways to group the impacts by their sound that pass the test of the module
    docstring, the most voices first, ending with one voice."""
    x = features.matrix()
    k = x.shape[0]
    if k < 16:
        return [Voices(np.zeros(k, dtype=np.int16), 1, math.inf, {})]
    rng = np.random.default_rng(seed)
    sample = x if k <= SAMPLE else x[rng.choice(k, SAMPLE, replace=False)]
    smallest = max(8, MIN_SHARE * sample.shape[0])
    found = {1: (sample.mean(axis=0, keepdims=True), math.inf)}
    tried = {}
    for v in range(2, MAX_VOICES + 1):
        if sample.shape[0] < v * 8:
            break
        centres, labels = _kmeans(sample, v, rng)
        big = np.flatnonzero(np.bincount(labels, minlength=v) >= smallest)
        if big.size < 2:
            continue
        # a handful of odd impacts (two ticks at once, a bump) is not a voice
        keep = np.isin(labels, big)
        relabel = np.full(v, -1)
        relabel[big] = np.arange(big.size)
        sep = _min_separation(sample[keep], relabel[labels[keep]], centres[big])
        tried[v] = sep
        if sep >= MIN_SEPARATION and sep > found.get(big.size, (None, -1.0))[1]:
            found[big.size] = (centres[big], sep)
    return [_assign(x, *found[n], tried) for n in sorted(found, reverse=True)]


def _assign(x: np.ndarray, centres: np.ndarray, sep: float, tried: dict) -> Voices:
    """Every impact to its nearest centre, or −1 when far from all of them."""
    k = x.shape[0]
    d = np.linalg.norm(x[:, None, :] - centres[None, :, :], axis=2)
    nearest = np.argmin(d, axis=1)
    mine = d[np.arange(k), nearest]
    out = nearest.astype(np.int16)
    for v in range(centres.shape[0]):
        sel = nearest == v
        if sel.any():
            typical = max(float(np.median(mine[sel])), SPREAD_FLOOR)
            out[sel & (mine > OUTLIER * typical)] = -1
    return Voices(out, int(centres.shape[0]), float(sep), dict(tried))


def _kmeans(x: np.ndarray, v: int, rng, iterations: int = 30):
    """(centres (v, D), labels (K,)): Lloyd's k-means from k-means++ seeds, the best of
    `RESTARTS`."""
    best, best_cost = None, math.inf
    norms = np.einsum("ij,ij->i", x, x)
    for _ in range(RESTARTS):
        centres = _plus_plus(x, norms, v, rng)
        labels = np.zeros(x.shape[0], dtype=np.int64)
        for _ in range(iterations):
            new = np.argmin(_distances2(x, norms, centres), axis=1)
            if _ > 0 and np.array_equal(new, labels):
                break
            labels = new
            for j in range(v):
                mine = labels == j
                if mine.any():  # an empty cluster keeps its centre; judged by its size
                    centres[j] = x[mine].mean(axis=0)
        cost = float(np.sum((x - centres[labels]) ** 2))
        if cost < best_cost:
            best, best_cost = (centres, labels), cost
    return best


def _distances2(x: np.ndarray, norms: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(K, v) squared distances. einsum, not a matrix product: these products are too
    small for BLAS, whose threads only cost time on a busy machine."""
    cross = np.einsum("kd,vd->kv", x, centres)
    return norms[:, None] - 2 * cross + np.einsum("vd,vd->v", centres, centres)[None, :]


def _plus_plus(x: np.ndarray, norms: np.ndarray, v: int, rng) -> np.ndarray:
    """k-means++ seeds: each next centre drawn with probability ∝ squared distance."""
    centres = [x[rng.integers(x.shape[0])]]
    d2 = _distances2(x, norms, centres[0][None, :])[:, 0]
    for _ in range(1, v):
        p = np.maximum(d2, 0)
        total = p.sum()
        pick = rng.choice(x.shape[0], p=p / total) if total > 0 else rng.integers(x.shape[0])
        centres.append(x[pick])
        d2 = np.minimum(d2, _distances2(x, norms, x[pick][None, :])[:, 0])
    return np.array(centres, dtype=float)


def _min_separation(x: np.ndarray, labels: np.ndarray, centres: np.ndarray) -> float:
    """Smallest separation of two clusters along the line between their centres."""
    out = math.inf
    v = centres.shape[0]
    for a in range(v):
        for b in range(a + 1, v):
            u = centres[a] - centres[b]
            norm = np.linalg.norm(u)
            if norm == 0:
                return 0.0
            u = u / norm
            pa, pb = x[labels == a] @ u, x[labels == b] @ u
            spread = max(math.sqrt(0.5 * (pa.var() + pb.var())), SPREAD_FLOOR)
            out = min(out, abs(pa.mean() - pb.mean()) / spread)
    return out

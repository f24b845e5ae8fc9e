"""What each metronome's tick sounds like, learned from its ticks, and whose an onset's
sound is.

The model. An onset's sound is its features x (`voices.Features.matrix`: the spectral
shape in bands, the loudness, the balance between microphones). For metronome m's
ticks of one kind (tick or tock: different pallets strike them) x ~ N(μ, diag σ²),
learned from the ticks it times that no other onset crowds (none within `CLEAR` s
before, nor after: what sounds there is two ticks' sound at once), each σ at least
`voices.SPREAD_FLOOR` (identical clicks vary by less than their rounding), both
estimated robustly (median, 1.4826 × median absolute deviation); a
metronome's sound is the even mixture of its two kinds. Its log-likelihood ℓ_m(x) is
that mixture's density.

Whose it is. An onset clear of others is another metronome's **by its sound** where
that one's log-likelihood exceeds this one's by ln `MODEL.sound_apart` (a likelihood
ratio of 1000): two metronomes of different makes differ there by hundreds, two of one
make by chance alone. Where a metronome has too few clear ticks to learn its sound (fewer than
`MIN_TICKS`), nothing is said by sound about it.

Contract: `learn_sounds(features, heard_ticks, kinds, times)` returns `Sounds`, whose
`loglik` is (M, K) ℓ_m of each onset and `others(m)` (K,) which onsets are another's
by their sound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .settings import MODEL
from .voices import FEATURE_LEAD, FEATURE_LENGTH, SPREAD_FLOOR

#: The natural log of `MODEL.sound_apart`, the margin an onset's log-likelihoods need.
_APART = math.log(MODEL.sound_apart)
#: Ticks a kind's sound is learned from at least.
MIN_TICKS = 8
#: No other onset this near a tick (s) for its sound to be learned from it, or judged:
#: the features read the sound from just before the onset to 6 ms after it, less as
#: long before (another's onset in those windows makes it two sounds at once).
CLEAR = FEATURE_LEAD + FEATURE_LENGTH


@dataclass(frozen=True)
class Sounds:
    """Each metronome's learned sound and each onset's log-likelihood under it.

    loglik : (M, K) ℓ_m of each onset's features (NaN for a metronome not learned).
    learned : (M,) whether each metronome's sound was learned.
    clear : (K,) whether each onset is clear of others (`CLEAR`).
    margin : (M, K) ℓ_m less the largest ℓ of the other learned metronomes (NaN where
        m or no other was learned): positive where the onset sounds likelier m's.
    """

    loglik: np.ndarray
    learned: np.ndarray
    clear: np.ndarray
    margin: np.ndarray

    def others(self, m: int) -> np.ndarray:
        """(K,) clear onsets another learned metronome's sound explains `MODEL.sound_apart`
        times better (a crowded onset's sound is two at once: nothing is said of it)."""
        return self.clear & (self.margin[m] < -_APART)

    def told_apart(self, m: int, ticks: list[np.ndarray]) -> bool:
        """Whether every other metronome's ticks (``ticks[j]``, indices of onsets) sound,
        in most of them, like that one's and not like m's (`others`)."""
        if not self.learned[m] or np.sum(self.learned) < 2:
            return False
        theirs = self.others(m)
        return all(theirs[own].mean() > 0.5 for j, own in enumerate(ticks)
                   if j != m and own.size)  # fmt: skip

    def mine(self, m: int) -> np.ndarray:
        """(K,) clear onsets whose sound is m's, `MODEL.sound_apart` times better than every
        other learned one."""
        return self.clear & (self.margin[m] > _APART)


def learn_sounds(x: np.ndarray, ticks: list[np.ndarray], kinds: list[np.ndarray],
                 times: np.ndarray) -> Sounds:  # fmt: skip
    """The `Sounds` of metronomes whose ticks are the onsets ``ticks[m]`` (indices into
    the onsets), of kinds ``kinds[m]`` (0 tick, 1 tock), among onsets at ``times`` (K,
    sorted, s) with features ``x`` (K, D)."""
    x = np.asarray(x, dtype=float)
    t = np.asarray(times, dtype=float)
    clear = _clear(t)
    loglik = np.full((len(ticks), t.size), np.nan)
    learned = np.zeros(len(ticks), dtype=bool)
    for m, (own, kind) in enumerate(zip(ticks, kinds, strict=True)):
        parts = []
        for k in (0, 1):
            use = own[(kind == k) & clear[own]]
            if use.size < MIN_TICKS:
                continue
            # robustly: where the pursuit let it follow another's ticks for a while,
            # its sound is still its own (the median and the spread of the most)
            mean = np.median(x[use], axis=0)
            spread = np.maximum(1.4826 * np.median(np.abs(x[use] - mean), axis=0), SPREAD_FLOOR)
            z = (x - mean) / spread
            parts.append(-0.5 * np.sum(z * z, axis=1) - np.sum(np.log(spread))
                         - 0.5 * x.shape[1] * math.log(2 * math.pi))  # fmt: skip
        if len(parts) == 2:
            loglik[m] = np.logaddexp(parts[0], parts[1]) - math.log(2.0)
            learned[m] = True
        elif len(parts) == 1:  # one kind heard clearly enough: its sound stands for both
            loglik[m] = parts[0]
            learned[m] = True
    return Sounds(loglik, learned, clear, _margins(loglik, learned))


def _margins(loglik: np.ndarray, learned: np.ndarray) -> np.ndarray:
    """(M, K) each learned metronome's ℓ less the largest of the other learned ones'."""
    margin = np.full(loglik.shape, np.nan)
    index = np.flatnonzero(learned)
    for m in index if index.size > 1 else ():
        margin[m] = loglik[m] - loglik[index[index != m]].max(axis=0)
    return margin


def _clear(t: np.ndarray) -> np.ndarray:
    """(K,) onsets with no other within `CLEAR` s on either side."""
    gap = np.full(t.size, np.inf)
    if t.size > 1:
        d = np.diff(t)
        gap[1:] = d
        gap[:-1] = np.minimum(gap[:-1], d)
    return gap > CLEAR

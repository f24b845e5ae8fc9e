"""Scoring an analysis against the truth of a synthetic recording.

The yardstick is fixed here, apart from the analysis it measures, so that a change to
the analysis cannot move it:

- a true tick and an analysed one match when they lie within ``tolerance`` (1 ms by
  default) of each other; each true tick is matched to its nearest analysed tick, and
  each analysed tick is used once at most (`match`);
- a tick is *hearable* on one microphone when no other metronome's tick began in the
  `HIDDEN_BEFORE` (40 ms: its impacts and the loudest of its ring) before it, nor
  within `RESOLVED` (5 ms) after it, and the file had begun at least `RESOLVED` before
  it (a tick is heard as a rise over what came before it) (`hearable`);
- for each true metronome, the analysed metronome that holds most of its hearable
  ticks is its own; recall counts the hearable ticks it holds, precision the ticks
  given to it that are true ticks of that metronome, the timing error is the largest
  error of the matched ticks, the tempo error the difference between its BPM and the
  true mean (`scores`).

A tick's true time is the time of its loud (most regular) impact
(`metrosync.synthetic.recording`).
"""

from __future__ import annotations

import numpy as np

#: A tick is hearable when no other metronome's tick began this long before it, s.
HIDDEN_BEFORE = 0.04
#: ... nor this long after it, s: two onsets closer than this are one sound to a single
#: microphone (the resolution of the detector the yardstick was set with, 5 ms; a
#: number of the yardstick's own, so that it stays put when the analysis changes).
RESOLVED = 0.005
#: Tolerance of a match, s.
TOLERANCE = 1e-3


def match(truth, found, tolerance: float = TOLERANCE):
    """(recall, precision, errors (s) of the matched): each true onset is matched to
    the nearest detection within ``tolerance``, each detection used once at most.

    truth : (K,) true times, s.   found : (L,) found times, s (L ≥ 1).
    errors : (M,) found − true of the M matched onsets."""
    truth, found = np.sort(truth), np.sort(found)
    j = np.clip(np.searchsorted(found, truth), 1, max(found.size - 1, 1))
    nearest = np.where(np.abs(found[j - 1] - truth) < np.abs(found[j] - truth), j - 1, j)
    err = found[nearest] - truth
    ok = np.abs(err) <= tolerance
    used = np.unique(nearest[ok])
    return ok.sum() / truth.size, used.size / found.size, err[ok]


def resolvable(trains, gap):
    """All onsets (sorted), and a mask of those with no onset of another train within
    ``gap`` (s). trains : list of (K_i,) times, s."""
    times = np.concatenate(trains)
    owner = np.concatenate([np.full(len(t), i) for i, t in enumerate(trains)])
    order = np.argsort(times)
    times, owner = times[order], owner[order]
    d_prev = np.concatenate([[np.inf], np.diff(times)])
    d_next = np.concatenate([np.diff(times), [np.inf]])
    return times, (d_prev > gap) & (d_next > gap)


def hearable(truth: list[np.ndarray], k: int) -> np.ndarray:
    """(K,) True for the ticks of train k that no other train's tick hides.

    truth : the true times of each train, s (list of (K_i,))."""
    mine = truth[k]
    begun = mine > RESOLVED
    if len(truth) == 1:
        return begun
    others = np.sort(np.concatenate([t for j, t in enumerate(truth) if j != k]))
    j = np.searchsorted(others, mine)
    before = np.where(j > 0, mine - others[np.maximum(j - 1, 0)], np.inf)
    after = np.where(j < others.size, others[np.minimum(j, others.size - 1)] - mine, np.inf)
    return begun & (before > HIDDEN_BEFORE) & (after > RESOLVED)


def scores(ds, truth: list[np.ndarray], tolerance: float = TOLERANCE) -> np.ndarray:
    """(N, 4) per true train: recall over its hearable ticks, precision, largest timing
    error (s), BPM error of the analysed metronome that holds most of its ticks (0, 0,
    inf, inf where none holds any).

    ds : what `metrosync.audio.analyze_audio` returns (``tick_time``,
        ``tick_metronome``, ``bpm``).
    truth : the true times of each train, s (list of (K_i,))."""
    found, label = ds.tick_time.values, ds.tick_metronome.values
    out = []
    for k, times in enumerate(truth):
        ok = hearable(truth, k)
        best = (0.0, 0.0, np.inf, np.inf)
        for m in range(ds.sizes.get("metronome", 0)):
            mine = found[label == m]
            if mine.size == 0:
                continue
            recall, _, errors = match(times[ok], mine, tolerance)
            _, precision, _ = match(times, mine, tolerance)
            bpm = 60 * (times.size - 1) / (times[-1] - times[0])
            if recall > best[0]:
                timing = np.abs(errors).max() if errors.size else np.inf
                best = (recall, precision, timing, abs(float(ds.bpm[m]) - bpm))
        out.append(best)
    return np.array(out).reshape(len(truth), 4)

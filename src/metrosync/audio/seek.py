"""Beats no onset was detected at, sought where the timing model puts them.

The detector's threshold is set for onsets that may fall anywhere: a rise as large
as it arises by chance in hardly any beat of the recording. A metronome's beat the
timing model has followed is known to within its jitter, so there a far smaller rise
is as unlikely to be chance: a quieter tick in another metronome's ring, under the
detector's threshold, can be heard there (track before detect). The method is a
constant-false-alarm detector in the window of each unheard beat: the window is the
main impact's predicted time ± `WINDOW_JITTERS` of the metronome's jitter; the
threshold is the level the detection curve's maximum over such a window exceeds, by
chance, in a share `FALSE_TICK` of windows, read off the recording's own curve away
from its onsets; the largest rise in the window above it is the tick.

Contract: `seek(recording, scan, impacts, heard)` returns the `detection.Ticks` found
(timed by `detection.refine`) and (L,) the metronome of each.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from . import detection as det
from .decompose import Heard

#: Half-width of the window of an unheard beat, in the metronome's jitters ...
WINDOW_JITTERS = 3.0
#: ... and at least this, s (the detector's timing noise and the timing's own error).
MIN_WINDOW = 1e-3
#: Share of windows with no tick in which the curve's maximum passes the threshold.
FALSE_TICK = 0.01
#: Onsets this close (s) are kept out of the chance level, and a window holding one is
#: left alone: that beat's onset is another's, which hid this one.
CLEAR = det.RESOLUTION


def seek(recording, scan: det.Scan, impacts: det.Ticks, heard: list[Heard]):
    """(the ticks found at the metronomes' unheard beats, (L,) their metronomes)."""
    hop = scan.hop / recording.sample_rate
    onset_hops = np.round(impacts.time / hop).astype(np.int64)
    near_onset = np.zeros(scan.curve.size, dtype=bool)
    clear = int(np.ceil(CLEAR / hop))
    for shift in range(-clear, clear + 1):
        near_onset[np.clip(onset_hops + shift, 0, scan.curve.size - 1)] = True
    found_hops, whose = [], []
    for m, h in enumerate(heard):
        timing = h.followed.timing
        half = max(1, int(np.ceil(max(WINDOW_JITTERS * timing.jitter, MIN_WINDOW) / hop)))
        chance = _chance_level(scan.curve, near_onset, 2 * half + 1)
        beats = np.setdiff1d(np.arange(h.beats.min(), h.beats.max() + 1), h.beats)
        if not beats.size or not np.isfinite(chance):
            continue
        kinds = np.mod(beats, 2)
        offsets = np.array([s.main_impact.offset for s in h.followed.structure])[kinds]
        centre = np.round((timing.predict(beats) + offsets) / hop).astype(np.int64)
        for c in centre:
            lo, hi = c - half, c + half + 1
            if lo < 0 or hi > scan.curve.size or near_onset[lo:hi].any():
                continue
            window = scan.curve[lo:hi]
            best = int(np.argmax(window))
            if window[best] > chance:
                found_hops.append(lo + best)
                whose.append(m)
    order = np.argsort(found_hops, kind="stable")  # refine reads the file once, in order
    hops = np.array(found_hops, dtype=np.int64)[order]
    owners = np.array(whose, dtype=np.int64)[order]
    if not hops.size:
        none = np.zeros(0)
        return det.Ticks(none, none, np.zeros((0, recording.channels)), none), owners
    return det.refine(recording, scan, hops), owners


def _chance_level(curve: np.ndarray, near_onset: np.ndarray, width: int) -> float:
    """The level the curve's maximum over ``width`` hops passes in `FALSE_TICK` of the
    windows clear of onsets (NaN where there are too few)."""
    maxima = ndimage.maximum_filter1d(curve, size=width, mode="nearest")
    clear = ~ndimage.maximum_filter1d(near_onset.astype(np.uint8), size=width).astype(bool)
    pool = maxima[clear][:: max(1, width)]  # windows side by side, not overlapping
    if pool.size < 10 / FALSE_TICK:
        return float("nan")
    return float(np.quantile(pool, 1.0 - FALSE_TICK))

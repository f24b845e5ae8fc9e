"""Beats no onset was detected at, sought where the timing model puts them.

The detector's threshold is set for onsets that may fall anywhere: a rise as large
as it arises by chance in hardly any beat of the recording. A metronome's beat the
timing model has followed is known to within its jitter, so there a far smaller rise
is as unlikely to be chance: a quieter tick in another metronome's ring, under the
detector's threshold, can be heard there (track before detect). The method is a
constant-false-alarm detector in the window of each unheard beat: the window is the
main impact's predicted time ± `MODEL.seek_window[0]` of the metronome's jitter; the
threshold is the level the detection curve's maximum over such a window exceeds, by
chance, in a share `MODEL.seek_false_tick` of windows, read off the recording's own curve away
from its onsets; the largest rise in the window above it is the tick.

Where the curve's rise is not enough (a tick in another's ring rises little over what
rings there already), the beat is sought by the metronome's own sound, as pulsar timing
times a pulse by a template learned from the data: the metronome's sound is its learned
waveform (`waveform.learn`), and the statistic is the largest normalised
cross-correlation of that sound with the recording over the beat's window. Its chance level is
read where the confusion lies: the same statistic at windows in the rings of the onsets
that are not this metronome's ticks; the threshold is passed by chance in
`MODEL.seek_false_tick` of them.

Contract: `seek(recording, scan, impacts, heard)` returns the `detection.Ticks` found
(timed by `detection.refine`, or by the best match of the sound) and (L,) the metronome
of each; the analysis then times every tick against its waveform (`waveform.retimed`).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, signal

from . import detection as det
from .decompose import Heard
from .settings import MODEL
from .waveform import QUIET, bands, is_clean, learn

#: Onsets this close (s) are kept out of the curve's chance level, and a window near one
#: is left to the sound: the onset hides the beat from the curve.
CLEAR = det.RESOLUTION
#: Windows in others' rings the sound's chance level is read from: four of them pass
#: it by chance.
CHANCE_WINDOWS = round(4 / MODEL.seek_false_tick)


def seek(recording, scan: det.Scan, impacts: det.Ticks, heard: list[Heard]):
    """(the ticks found at the metronomes' unheard beats, (L,) their metronomes)."""
    hop = scan.hop / recording.sample_rate
    onset_hops = np.round(impacts.time / hop).astype(np.int64)
    near_onset = np.zeros(scan.curve.size, dtype=bool)
    clear = int(np.ceil(CLEAR / hop))
    for shift in range(-clear, clear + 1):
        near_onset[np.clip(onset_hops + shift, 0, scan.curve.size - 1)] = True
    in_order = np.sort(onset_hops)
    found_hops, whose, unfound = [], [], []
    for m, h in enumerate(heard):
        timing = h.followed.timing
        jitters, least = MODEL.seek_window
        half = max(1, int(np.ceil(max(jitters * timing.jitter, least) / hop)))
        chance = _chance_level(scan.curve, near_onset, 2 * half + 1)
        main_offset = np.array([s.main_impact.offset for s in h.followed.structure])
        off = _off_their_beat(impacts.time, h, main_offset, MODEL.seek_window[1])
        for beat in h.beats[off]:
            # the onset heard on the beat may not be the strike but a sound whose rise
            # hid it (a knock's crack, a coder's pre-echo): the strike is sought by its
            # sound too, and the timing model takes the likelier of the two
            kind = int(beat % 2)
            at = float(timing.predict(np.array([beat]))[0]) + main_offset[kind]
            onset = float(impacts.time[h.ticks[h.beats == beat][0]])
            unfound.append((m, kind, at, half * hop, onset))
        beats = np.setdiff1d(np.arange(h.beats.min(), h.beats.max() + 1), h.beats)
        if not beats.size or not np.isfinite(chance):
            continue
        kinds = np.mod(beats, 2)
        offsets = main_offset[kinds]
        centre = np.round((timing.predict(beats) + offsets) / hop).astype(np.int64)
        for c, kind in zip(centre, kinds, strict=True):
            lo, hi = c - half, c + half + 1
            if lo < 0 or hi > scan.curve.size:
                continue
            if near_onset[lo:hi].any():
                # an onset just before hides the beat from the curve, not from its sound;
                # one inside the window is another's, which hid this one
                first = np.searchsorted(in_order, lo)
                if first == in_order.size or in_order[first] >= hi:
                    unfound.append((m, int(kind), c * hop, half * hop, np.nan))
                continue
            window = scan.curve[lo:hi]
            best = int(np.argmax(window))
            if window[best] > chance:
                found_hops.append(lo + best)
                whose.append(m)
            else:
                unfound.append((m, int(kind), c * hop, half * hop, np.nan))
    order = np.argsort(found_hops, kind="stable")  # refine reads the file once, in order
    hops = np.array(found_hops, dtype=np.int64)[order]
    owners = np.array(whose, dtype=np.int64)[order]
    found = (
        det.Ticks.none(recording.channels) if not hops.size else det.refine(recording, scan, hops)
    )
    by_sound, sound_owners = _by_sound(recording, scan, impacts, heard, unfound)
    new = _apart_from(by_sound.time, impacts.time, MODEL.seek_window[1])  # not an onset found again
    by_sound, sound_owners = by_sound.taken(new), sound_owners[new]
    if by_sound.time.size:
        found = found.joined(by_sound)
        owners = np.concatenate([owners, sound_owners])
    return found, owners


def _by_sound(recording, scan, impacts: det.Ticks, heard: list[Heard], unfound):
    """(the ticks found by each metronome's sound at the beats ``unfound`` — (metronome,
    kind, predicted time s, half-window s, the onset heard there s or NaN) — and their
    metronomes). Where a beat's onset was heard, the sound's best match in the window is
    a tick only where it matches better than at the onset (within a hop)."""
    rate = recording.sample_rate
    times, whose = [], []
    rng = np.random.default_rng(0)  # where the chance level is read: fixed, repeatable
    for m, h in enumerate(heard):
        mine = [u for u in unfound if u[0] == m]
        if not mine:
            continue
        others = np.setdiff1d(np.arange(impacts.time.size), h.ticks)
        clean = h.ticks[is_clean(impacts.time, h.ticks, others)]
        half = mine[0][3]
        null = _ring_windows(impacts.time, others, h, half, rng)
        for kind in (0, 1):
            beats = [u for u in mine if u[1] == kind]
            ticks = clean[np.mod(h.followed.beat[np.searchsorted(h.pool, clean)], 2) == kind]
            sound = learn(recording, scan, impacts.time[ticks])
            if not beats or sound is None or null.size < CHANCE_WINDOWS:
                continue
            chance = _match(recording, scan, sound, null, half)[0]
            level = np.quantile(chance, 1 - MODEL.seek_false_tick)
            centres = np.array([u[2] for u in beats])
            score, at = _match(recording, scan, sound, centres, half)
            found = score > level
            onsets = np.array([u[4] for u in beats])
            heard_there = np.isfinite(onsets)
            if heard_there.any():
                # where the onset heard matches the sound as well, it is the strike
                own, _ = _match(recording, scan, sound, onsets[heard_there], scan.hop / rate)
                found[heard_there] &= score[heard_there] > own
            times += list(at[found])
            whose += [m] * int(np.sum(found))
    if not times:
        return det.Ticks.none(recording.channels), np.zeros(0, dtype=np.int64)
    order = np.argsort(times)
    t = np.array(times)[order]
    hops = np.round(t * rate / scan.hop).astype(np.int64)
    found = det.refine(recording, scan, hops)  # its strength and levels; its time is the match's
    return det.Ticks(t, found.strength, found.channel_strength, found.rise), np.array(whose)[order]


def _apart_from(t: np.ndarray, onsets: np.ndarray, gap: float) -> np.ndarray:
    """(len(t),) whether each time is further than ``gap`` (s) from every onset."""
    if not onsets.size or not t.size:
        return np.ones(t.size, dtype=bool)
    order = np.sort(onsets)
    j = np.clip(np.searchsorted(order, t), 1, order.size - 1)
    nearest = np.minimum(np.abs(order[j] - t), np.abs(order[j - 1] - t))
    return (nearest > gap) if order.size > 1 else (np.abs(order[0] - t) > gap)


def _off_their_beat(t: np.ndarray, h: Heard, main_offset: np.ndarray, half: float
                    ) -> np.ndarray:  # fmt: skip
    """(ticks,) whether each of the metronome's ticks is timed further than ``half`` (s)
    from where its timing puts its strike."""
    beats = h.beats
    predicted = h.followed.timing.predict(beats) + main_offset[np.mod(beats, 2)]
    return np.abs(t[h.ticks] - predicted) > half


def _ring_windows(t, others, h: Heard, half: float, rng) -> np.ndarray:
    """Centres of windows in the rings of the onsets ``others`` (from `half` to `MODEL.ring`
    after one), clear of every onset and of this metronome's beats; where those are too
    few, in the rings of its own ticks too (from `CLEAR` past the window to `MODEL.ring`)."""
    timing = h.followed.timing
    keep = np.zeros(0)
    if others.size:
        pick = rng.choice(others, size=4 * CHANCE_WINDOWS)
        centre = t[pick] + rng.uniform(half, MODEL.ring, pick.size)
        beat = np.round((centre - timing.phase) / timing.period)
        off_beat = np.abs(centre - timing.predict(beat)) > MODEL.ring
        keep = centre[(_gap_to_onsets(t, centre) > half) & off_beat]
    if keep.size < CHANCE_WINDOWS and h.ticks.size:
        # too few others (one metronome, a few bumps): its own ticks' rings too, where
        # its sound rings on as another's would
        pick = rng.choice(h.ticks, size=4 * CHANCE_WINDOWS)
        own = t[pick] + rng.uniform(half + CLEAR, MODEL.ring, pick.size)
        keep = np.concatenate([keep, own[_gap_to_onsets(t, own) > half]])
    return keep[:CHANCE_WINDOWS]


def _gap_to_onsets(t: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """The time from each of ``centre`` to the nearest of the sorted onsets ``t``, s."""
    j = np.searchsorted(t, centre)
    return np.minimum(np.abs(t[np.minimum(j, t.size - 1)] - centre),
                      np.abs(t[np.maximum(j - 1, 0)] - centre))  # fmt: skip


def _match(recording, scan, sound: np.ndarray, centres, half: float):
    """(the largest normalised cross-correlation of ``sound`` with the recording over
    each window centre ± half (s), and the time (s) where it is)."""
    rate = recording.sample_rate
    n, w, quiet = sound.size, round(half * rate), round(QUIET * rate)
    starts = np.round(np.asarray(centres, dtype=float) * rate).astype(np.int64) - w - quiet
    if not starts.size:
        return np.zeros(0), np.zeros(0)
    x = bands(recording, scan, starts, 2 * w + n)
    dot = signal.fftconvolve(x, sound[None, ::-1], mode="valid", axes=1)
    s1 = np.concatenate([np.zeros((x.shape[0], 1)), np.cumsum(x, axis=1)], axis=1)
    s2 = np.concatenate([np.zeros((x.shape[0], 1)), np.cumsum(x * x, axis=1)], axis=1)
    sums, squares = s1[:, n:] - s1[:, :-n], s2[:, n:] - s2[:, :-n]
    spread = np.sqrt(np.maximum(squares - sums * sums / n, 1e-30))
    ncc = dot / spread  # the sound has mean 0 and norm 1
    best = np.argmax(ncc, axis=1)
    score = ncc[np.arange(ncc.shape[0]), best]
    return score, (starts + best + quiet) / rate


def _chance_level(curve: np.ndarray, near_onset: np.ndarray, width: int) -> float:
    """The level the curve's maximum over ``width`` hops passes in `MODEL.seek_false_tick` of the
    windows clear of onsets (NaN where there are too few)."""
    maxima = ndimage.maximum_filter1d(curve, size=width, mode="nearest")
    clear = ~ndimage.maximum_filter1d(near_onset.astype(np.uint8), size=width).astype(bool)
    pool = maxima[clear][:: max(1, width)]  # windows side by side, not overlapping
    if pool.size < 10 / MODEL.seek_false_tick:
        return float("nan")
    return float(np.quantile(pool, 1.0 - MODEL.seek_false_tick))

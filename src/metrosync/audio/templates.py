"""Each metronome's tick as this recording hears it, and ticks timed against it where
another metronome's impacts and ring overlap them.

Contract: `learn(recording, scan, times, trains)` returns one `Sound` per train (or
None where too few of its ticks sound alone); `retime(recording, scan, times,
trains, sounds)` returns the tick times (K,) with each tick that sounds in another
metronome's ring timed again, and how much each tick sounds like its train's sound.

A sound. The waveform the detector times (the channels' mix, band-passed forwards and
backwards: no delay) from `BEFORE` before each onset to `AFTER` after it, averaged
over the first `MAX_LEARNED` of the train's ticks that no other train's tick
overlaps (none began in the `HEAD` before, nor in the `HEAD` after), apart for the
ticks and the tocks (a tock can sound different); both together where one kind has
fewer than `MIN_CLEAR`. It holds the tick's later impacts and its ring. The ring's
tail, beyond `HEAD`, is averaged over the ticks no other overlaps for all of `AFTER`
(fewer, with four metronomes ticking), or left silent where fewer than `MIN_CLEAR`
were: a tick that begins late in another's ring is still timed a millisecond late by
the detector.

Timing in a ring. A tick that begins within `AFTER` after another train's tick has its
onset timed on a sum of the two: the detector's onset rule reads the other's ring as
its background and times the tick late by a millisecond or two. Over `FIT_BEFORE`
before to `FIT_AFTER` after the detected onset, the waveform is fitted by least
squares as a·(own sound at τ) + Σ b_j·(sound j at its onset t_j), for every τ within
`SEARCH` of the detected onset, whole samples apart; the τ of the smallest residual
(refined on a parabola) is the onset; a is the tick's scale (`Fitted.scale`: 1 for a
tick as loud as those its sound was learned from). The sounds j are those of the
other trains' ticks (`sounding`: a tick two trains hold as hidden behind each other
sounds as both). Where the tick's own sound alone explains the window better, by
`ALONE_BETTER`, the others did not sound there as learned, and the tick is timed
alone. The other ticks keep their times
(their onsets are the first thing heard, where the detector is exact), unless their
own sound fits more than `CRACK` away: something began just before them. A tick that
another train holds as hidden behind it is fitted again with that train's sound at
the onset among the b_j, and timed so where its own sound then fits more than `CRACK`
away: two metronomes a millisecond apart make one onset, the first's
(`_beside_a_hidden_tick`). Where the other's ring timed the onset later than the
fit reaches, the fit's best lies at the early end of its search, and is sought
again around there (`_before_the_reach`); or the tick lies farther off the beat its
neighbours of its kind put it at than `SEARCH`, and is fitted again there
(`_toward_the_beat`). Either is taken only where the tick sounds more like itself.

Behind a crack. A tick that begins within the detector's resolution after a louder
sound (a handling bump's crack, another metronome's later impact) has no onset of its
own; its train holds the crack. Where that onset sounds too unlike the tick to stay
and the first search found only the crack, the end of its reach or nothing like a
tick, the tick is sought `LATE` after the onset (see `_behind_a_crack`).
A tick whose own sound fits more than `CRACK` from its onset is timed by that fit
where it sounds enough like itself there (`CRACK_LIKENESS`; `MIN_LIKENESS` where no
other metronome's tick sounds in its window).

Likeness. The share of the window's energy (less what the other ticks explain) that
the tick's own sound explains at its best onset: above 0.4 for the corpus's ticks,
under 0.1 for a handling bump on a metronome's beat. A tick held by a train that
sounds less like it than `MIN_LIKENESS` is not that metronome's; in another's ring
past its later impacts, than `RING_LIKENESS`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy import signal

from .detection import _segments
from .trains import Train, holders

#: Sound kept before each onset, s (room for the search below).
BEFORE = 8e-3
#: Sound kept after each onset, s: its later impacts and its ring.
AFTER = 0.1
#: The start of it learned from ticks no other overlaps this long, s: its impacts and
#: the loudest of its ring.
HEAD = 0.05
#: Ticks of one kind that sound alone, at least, for a sound of that kind.
MIN_CLEAR = 4
#: Ticks of one kind averaged, at most.
MAX_LEARNED = 64
#: Fit window around a tick's detected onset, s.
FIT_BEFORE = 3e-3
FIT_AFTER = 5e-3
#: Farthest a tick is moved, s.
SEARCH = 3e-3
#: How much more alike (a share of the window) a tick's own sound must be alone than
#: beside the other ticks' sounds to be timed alone (`_alone_where_it_fits_better`).
ALONE_BETTER = 0.05
#: A tick less like its train's sound than this is not its metronome's ...
MIN_LIKENESS = 0.35
#: ... unless the ticks of its kind (tick or tock) are all less alike: then one less
#: like it than this share of their median is not its, nor one under `BUMP_LIKENESS`
#: (a handling bump on the beat: under 0.1).
LIKENESS_SHARE = 0.6
BUMP_LIKENESS = 0.15
#: A tick that begins in another metronome's ring past its later impacts (its ring
#: varies from tick to tick, and what the fit leaves of it counts against the
#: likeness) is not its train's below this: 0.24-0.26 for true ticks 41 ms after
#: another's (corpus seeds 4/24, 4/138). Among the later impacts a tick that unlike
#: may be timed by them (1.2-1.6 ms off 32-35 ms after another's: seeds 3/99, 4/75).
RING_LIKENESS = 0.2
#: How long after a tick its later impacts last, s. The analysis's own assumption about
#: a tick, not a measurement: it was set just past the 15-35 ms of the later impacts
#: the synthetic voices are drawn with (`metrosync.synthetic.ticks.SUB_DELAY_RANGE`),
#: and says nothing of an impact before the loud one (a real Neewer's comes 10-45 ms
#: early). The coming timing model is to learn a metronome's impacts from the recording.
LATER_IMPACTS = 0.04
#: A tick whose own sound fits this much away from its detected onset is timed by the
#: fit, in a ring or not, s: a tick alone fits within 0.2 ms of its onset (0.6 ms at
#: most in four corpus recordings of 650 ticks alone).
CRACK = 0.7e-3
#: ... where it sounds at least this much like it there (a crack 1-2.6 ms ahead:
#: 0.57-0.92 in the corpus; a tick moved onto another's on one onset, 0.46).
CRACK_LIKENESS = 0.5
#: Ticks of its kind each side of a tick that say where its beat is.
NEIGHBOURS = 4
#: A fit's best this near the end of its `SEARCH` is at the end of its reach, s.
EDGE = 0.25e-3
#: Where a tick too unlike its sound is looked for again, after its detected onset,
#: s: over `SEARCH` either side, a tick found between the first search's reach and
#: here is taken (past the detector's `RESOLUTION` a tick has an onset of its own).
LATE = 6e-3
#: ... and taken where it sounds at least this much like it: a tick found behind a
#: crack or another's later impact, 0.79-0.98 in the corpus.
BEHIND_LIKENESS = 0.7
#: Filtered beyond each end of a segment, s: the band-pass settles there.
MARGIN = 3e-3
#: Farthest a learned tick is moved to line up with the others of its kind, s: the
#: detector's onsets wander by a few tenths of a millisecond, a period of a 3 kHz
#: resonance, and an average of ticks so placed is smeared.
ALIGN = 0.5e-3


@dataclass(frozen=True)
class Sound:
    """One train's tick, sampled at the recording's rate from −`BEFORE` to `AFTER`.

    waves : (2, L) the sound of its even and its odd beats (tick and tock).
    onset : index of the onset in each wave.
    learned : whether each kind was heard often enough to be learned on its own (a
        kind that was not is the mean of both, and its ticks' likeness is unknown).
    """

    waves: np.ndarray
    onset: int
    learned: tuple[bool, bool] = (True, True)


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


def learn(recording, scan, times: np.ndarray, trains: list[Train]) -> list[Sound | None]:
    """One `Sound` per train (see the module docstring)."""
    rate = recording.sample_rate
    before, after, head = round(BEFORE * rate), round(AFTER * rate), round(HEAD * rate)
    held = np.sort(np.concatenate([times[t.index] for t in trains])) if trains else times
    out: list[Sound | None] = []
    for train in trains:
        heard = ~train.masked
        index, parity = train.index[heard], train.beat[heard] % 2
        t = times[index]
        # alone: no tick of another train in the HEAD before or after (its own is held
        # too, but never that close)
        j = np.searchsorted(held, t)
        prev = np.where(j > 0, t - held[np.maximum(j - 1, 0)], np.inf)
        nxt = np.where(j + 1 < held.size, held[np.minimum(j + 1, held.size - 1)] - t, np.inf)
        alone = (prev > HEAD) & (nxt > HEAD)
        # a kind that is never alone (a tock that keeps falling just before another
        # metronome's tick) is learned where none follows within the fit window: the
        # start of its sound, which the fit reads, is its own
        nearly = (prev > HEAD) & (nxt > FIT_AFTER + SEARCH)
        # the ring's tail from the ticks alone that long too
        long = (prev > AFTER) & (nxt > AFTER)
        use = np.zeros(t.size, dtype=bool)
        tail = np.zeros(t.size, dtype=bool)
        for kind in (0, 1):
            pick = alone if (alone & (parity == kind)).sum() >= MIN_CLEAR else nearly
            # the first few of each kind: the mean has settled by then
            use[np.flatnonzero(pick & (parity == kind))[:MAX_LEARNED]] = True
            tail[np.flatnonzero(long & (parity == kind))[:MAX_LEARNED]] = True
        if use.sum() < MIN_CLEAR:
            out.append(None)
            continue
        either = use | tail
        starts = np.round(t[either] * rate).astype(np.int64) - before
        order = np.argsort(starts)
        kinds = parity[either][order]
        use, tail = use[either][order], tail[either][order]
        waves = _filtered(recording, scan, starts[order], before + after)
        shift = _lined_up(waves, kinds, use, before, rate)
        if shift.any():
            waves = _filtered(recording, scan, starts[order] + shift, before + after)
        learned = tuple(bool((use & (kinds == k)).sum() >= MIN_CLEAR) for k in (0, 1))
        both = waves[use].mean(axis=0)
        two = np.array([waves[use & (kinds == k)].mean(axis=0) if learned[k] else both
                        for k in (0, 1)])  # fmt: skip
        # the tail: of each kind where heard alone often enough, else of both, else none
        end = before + head
        both_tail = waves[tail, end:].mean(axis=0) if tail.sum() >= MIN_CLEAR else 0.0
        for k in (0, 1):
            mine = tail & (kinds == k)
            two[k, end:] = waves[mine, end:].mean(axis=0) if mine.sum() >= MIN_CLEAR else both_tail
        out.append(Sound(two, before, (learned[0], learned[1])))
    return out


def _lined_up(waves: np.ndarray, kinds: np.ndarray, use: np.ndarray, onset: int, rate: float):
    """(n,) samples to move each of the ``use`` waves (onset at index ``onset``) so that
    its first milliseconds, the part a fit reads, best match the mean of its kind (up
    to `ALIGN`); their median move is 0, so a learned onset stays where the detector
    puts a tick that sounds alone."""
    reach = round(ALIGN * rate)
    lo, hi = onset - round(FIT_BEFORE * rate), onset + round(FIT_AFTER * rate)
    shift = np.zeros(kinds.size, dtype=np.int64)
    for kind in (0, 1):
        rows = np.flatnonzero(use & (kinds == kind))
        if rows.size < MIN_CLEAR:
            continue
        for _ in range(2):  # against the mean of the ticks as moved so far
            moved = [waves[r, lo + s : hi + s] for r, s in zip(rows, shift[rows], strict=True)]
            mean = np.mean(moved, axis=0)
            reads = [waves[r, lo - reach : hi + reach] for r in rows]
            lags = np.array([np.argmax(np.correlate(x, mean, "valid")) for x in reads]) - reach
            shift[rows] = lags - int(np.median(lags))
    return shift


class Fitted(NamedTuple):
    """What `fit` found of each tick: its onset (s), its likeness, and the factor its
    own sound is scaled by there (1: as loud as the ticks it was learned from)."""

    onset: np.ndarray
    likeness: np.ndarray
    scale: np.ndarray


def fit(recording, scan, at: np.ndarray, own: list, context: list) -> Fitted:
    """`Fitted` (n,) of the ticks near ``at`` (n,) s, sorted: each
    fitted as the sound ``own[i]`` (a `Sound`: whichever of its two kinds fits better,
    so that a train's beats counted one off after a gap do not matter) at the onset
    within `SEARCH` of at[i] that explains most of the window, plus the sounds
    ``context[i]`` ((Sound, onset s) pairs: the other ticks that sound there, each as
    any mix of its two kinds) at their onsets. Likeness: the share of the window's
    energy, less what the context explains, that the tick's own sound explains (1: it
    sounds just like it)."""
    rate = recording.sample_rate
    fit_before, fit_after = round(FIT_BEFORE * rate), round(FIT_AFTER * rate)
    onset = round(BEFORE * rate)
    search = round(SEARCH * rate)
    width = fit_before + fit_after
    cols = np.arange(width)
    centre = np.round(np.asarray(at) * rate).astype(np.int64)
    segments = _filtered(recording, scan, centre - fit_before, width)
    # each sound at every onset within the search, read over the window: the span of
    # it that the window can see, slid along it
    lo = onset - fit_before - search
    explained = np.empty((centre.size, 2 * search + 1))
    scale = np.zeros_like(explained)  # the own sound's factor at each onset
    energy = np.einsum("nw,nw->n", segments, segments)
    alone = np.array([not c for c in context], dtype=bool)
    # the ticks no other overlaps, a whole sound at a time: one matrix product each
    which = np.array([id(sound) for sound in own])
    for key in np.unique(which):
        rows = np.flatnonzero(alone & (which == key))
        if rows.size == 0:
            continue
        best = np.zeros((rows.size, explained.shape[1]))
        gain = np.zeros_like(best)
        for wave in own[rows[0]].waves:
            shifted = sliding_window_view(wave[lo : lo + width + 2 * search], width)
            norm = np.einsum("kw,kw->k", shifted, shifted)
            best, gain = _better(best, gain, segments[rows] @ shifted.T, norm)
        explained[rows] = best
        scale[rows] = gain
    for row in np.flatnonzero(~alone):
        columns = []
        for other, when in context[row]:
            p = centre[row] - fit_before + cols - (round(when * rate) - onset)
            inside = (p >= 0) & (p < other.waves.shape[1])
            for wave in other.waves:
                columns.append(np.where(inside, wave[np.clip(p, 0, wave.size - 1)], 0.0))
        q, _ = np.linalg.qr(np.array(columns).T)
        y = segments[row] - q @ (q.T @ segments[row])
        energy[row] = y @ y
        explained[row] = 0.0
        for wave in own[row].waves:
            span = wave[lo : lo + width + 2 * search]
            cumulative = np.concatenate([[0.0], np.cumsum(span * span)])
            norm = cumulative[width:] - cumulative[:-width]
            # what of the own sound the context could explain is not the tick's
            norm = norm - np.sum([np.correlate(span, c, "valid") ** 2 for c in q.T], axis=0)
            explained[row], scale[row] = _better(
                explained[row], scale[row], np.correlate(span, y, "valid"), norm
            )
    # index k: the onset `search` − k samples after the window's centre; refined on a
    # parabola through the best and its neighbours
    best = np.argmax(explained, axis=1)
    rows = np.arange(centre.size)
    e1 = explained[rows, best]
    e0 = explained[rows, np.maximum(best - 1, 0)]
    e2 = explained[rows, np.minimum(best + 1, explained.shape[1] - 1)]
    denom = e0 - 2 * e1 + e2
    inner = (best > 0) & (best < explained.shape[1] - 1) & (denom < 0)
    frac = np.where(inner, 0.5 * (e0 - e2) / np.where(inner, denom, -1.0), 0.0)
    times = (centre + search - best - frac) / rate
    likeness = e1 / np.maximum(energy, 1e-30)
    return Fitted(times, likeness, scale[rows, best])


def _better(best, gain, product, norm):
    """(best, gain) where the sound's product with the window at each onset explains
    more of it (product²/norm) than ``best`` does: that share and the sound's factor
    there (product/norm)."""
    norm = np.maximum(norm, 1e-30)
    explains = product**2 / norm
    better = explains > best
    return np.where(better, explains, best), np.where(better, product / norm, gain)


def sounding(times: np.ndarray, trains: list[Train], sounds=None) -> tuple[np.ndarray, np.ndarray]:
    """((J,) tick indices, (J,) trains) of the held ticks (with ``sounds``, those whose
    train's sound is known), in time order, each with the train whose sound it is: the
    train that holds it as its own (`holders`), or, for a tick two or more trains hold
    and none as its own alone, each of them. Two metronomes a millisecond or two apart
    make one onset that each train takes as hidden by the other; both sound there
    (corpus seeds 4/85, 4/127: a third metronome's tick 31-36 ms later, fitted without
    their rings, was timed 1.4-1.6 ms off)."""
    owner = holders(times.size, trains)
    tick = [np.flatnonzero(owner >= 0)]
    by = [owner[tick[0]]]
    claims = np.zeros(times.size, dtype=np.int64)
    for t in trains:
        claims[t.index] += 1
    together = (owner < 0) & (claims > 1)
    for m, t in enumerate(trains):
        shared = t.index[together[t.index]]
        tick.append(shared)
        by.append(np.full(shared.size, m))
    ticks, whose = np.concatenate(tick), np.concatenate(by)
    if sounds is not None:
        known = np.array([sounds[m] is not None for m in whose], dtype=bool)
        ticks, whose = ticks[known], whose[known]
    order = np.lexsort((whose, times[ticks]))
    return ticks[order], whose[order]


def context(times, sources, sounds, at, whose) -> list:
    """For each fit window centred on ``at`` (s) for a tick of train ``whose`` (one each),
    the (Sound, onset) of the ticks of other trains that sound in it (``sources``: the
    sounding ticks and their trains, `sounding`)."""
    ticks, by = sources
    h = times[ticks]
    first = np.searchsorted(h, at - AFTER, side="right")
    stop = np.searchsorted(h, at + FIT_AFTER + SEARCH)
    return [[(sounds[by[q]], times[ticks[q]]) for q in range(a, b) if by[q] != w]
            for w, a, b in zip(whose, first, stop, strict=True)]  # fmt: skip


def ringing(times: np.ndarray, sources, at: np.ndarray) -> np.ndarray:
    """(n,) True where ``at`` (s) lies within `AFTER` after a sounding tick of
    ``sources`` (`sounding`, in the order of these ``times``) that begins before it:
    in its ring."""
    h = times[sources[0]]
    if h.size == 0:  # no tick sounds: nothing rings (a video's sound track with no train)
        return np.zeros(np.shape(at), dtype=bool)
    j = np.searchsorted(h, at, side="left")
    return (j > 0) & (at - h[np.maximum(j - 1, 0)] <= AFTER)


def retime(recording, scan, times: np.ndarray, trains: list[Train], sounds):
    """((K,) ``times`` with each tick that sounds in another train's ring timed again on
    the sum of the sounds, (K,) each held tick's likeness to its train's sound (NaN
    for the others)); see the module docstring."""
    times = np.asarray(times, dtype=float)
    out = times.copy()
    likeness = np.full(times.size, np.nan)
    owner = holders(times.size, trains)
    held = np.flatnonzero(owner >= 0)
    held = held[[sounds[owner[i]] is not None for i in held]]
    if held.size == 0:
        return out, likeness
    own = [sounds[owner[i]] for i in held]
    sources = sounding(times, trains, sounds)
    around = context(times, sources, sounds, times[held], owner[held])
    fitted, alike, _ = fit(recording, scan, times[held], own, around)
    _alone_where_it_fits_better(recording, scan, times[held], own, around, fitted, alike)
    likeness[held] = alike
    _beside_a_hidden_tick(recording, scan, times, trains, sounds, owner, held, own, around,
                          fitted, likeness)  # fmt: skip
    likeness[held[[not all(sound.learned) for sound in own]]] = np.nan
    h = times[held]
    _before_the_reach(recording, scan, times, fitted, likeness, owner, sounds, sources, held)
    # masked ticks too: each is timed by its owner's sound, and a tick that only the
    # train that took it as masked holds is that train's own, its sound read in the
    # ring as another's (corpus seed 58, two metronomes: kept 1.4 ms late)
    in_ring = ringing(times, sources, h)
    # and a tick whose own sound begins well away from its onset: the detector timed
    # something just before it (a handling bump's crack 1-2.6 ms ahead, corpus seeds
    # 3/172, 3/231, 4/181, 4/98), or the tick late in the bump's thump
    moved = np.abs(fitted - h)
    behind = _begins_away(fitted, h, likeness[held], alone=np.array([not c for c in around]))
    out[held[in_ring | behind]] = fitted[in_ring | behind]
    _toward_the_beat(recording, scan, times, out, likeness, owner, trains, sounds, sources,
                     held[in_ring])  # fmt: skip
    # where the first search's best is the onset itself (the crack), the end of its
    # reach, or nothing like a tick, the tick may lie beyond; one found in between is
    # there, only sounding less like itself (another metronome's tick on its onset:
    # corpus seeds 3/78, 4/25, moved 1.2-2.3 ms, 0.26-0.29 alike; nothing like a
    # tick: under `RING_LIKENESS`, what no tick sounds like even in a ring, as seeds
    # 4/55 and 4/27 found in between, 0.03 and 0.17, their ticks 4.2-4.7 ms after
    # another's later impact)
    reach = (moved <= CRACK) | (moved >= SEARCH - EDGE) | (likeness[held] < RING_LIKENESS)
    _behind_a_crack(recording, scan, times, out, likeness, trains, sounds, owner, held,
                    sources, np.flatnonzero(reach))  # fmt: skip
    return out, likeness


def _before_the_reach(
    recording, scan, times, fitted, likeness, owner, sounds, sources, held
) -> None:
    """Held ticks (``held``; ``fitted`` (n,) their fits, ``likeness`` (K,), both changed
    in place) whose own sound fits best at the early end of the search (`EDGE`), fitted
    again around there and timed so where they sound more like it within that search's
    reach: another's ring can time a tick's onset more than `SEARCH` late (corpus seed
    3/477: the first tick of a metronome, sought by sound from a prediction 7.6 ms
    late, fitted 2.9 ms before its found onset, 0.89 alike; it was 2.1 ms earlier
    still). Only earlier: a tick that begins well after its onset would have been heard
    as an onset of its own."""
    early = fitted - times[held] <= -(SEARCH - EDGE)
    rows = np.flatnonzero(early & ~np.isnan(likeness[held]))
    if rows.size:
        fitted[rows], likeness[held[rows]] = _refitted(
            recording, scan, times, fitted[rows], likeness[held[rows]],
            owner[held[rows]], sounds, sources)  # fmt: skip


def _toward_the_beat(
    recording, scan, times, out, likeness, owner, trains, sounds, sources, ticks
) -> None:
    """Ticks in another's ring (``ticks``, held; ``owner``: `holders`) timed farther off
    their beat than a fit reaches (`SEARCH`), fitted again where their train's beat puts
    them (``out``, ``likeness`` changed in place) and timed there where they sound more
    like themselves: another's later impacts and ring can hide a tick's first
    milliseconds from the detector (corpus seed 4/360: ticks 45-54 ms after another's,
    their onsets 8-12 ms late, fitted within 3 ms of them). The beat: where the tick's
    neighbours of its kind (`NEIGHBOURS` each side) put it, by their median line
    (robust to neighbours so timed too)."""
    place = np.full(ticks.size, np.nan)
    for m, train in enumerate(trains):
        mine = np.flatnonzero(owner[ticks] == m)
        for row, k in zip(mine, np.searchsorted(train.index, ticks[mine]), strict=True):
            kind = np.flatnonzero(train.beat % 2 == train.beat[k] % 2)
            pos = int(np.searchsorted(kind, k))
            near = np.concatenate([kind[max(pos - NEIGHBOURS, 0) : pos],
                                   kind[pos + 1 : pos + 1 + NEIGHBOURS]])  # fmt: skip
            if near.size < 4:
                continue
            t, b = out[train.index[near]], train.beat[near].astype(float)
            i, j = np.triu_indices(near.size, 1)
            slope = np.median((t[j] - t[i]) / (b[j] - b[i]))
            place[row] = np.median(t + slope * (train.beat[k] - b))
    rows = np.flatnonzero((np.abs(out[ticks] - place) > SEARCH) & ~np.isnan(likeness[ticks]))
    if rows.size:
        out[ticks[rows]], likeness[ticks[rows]] = _refitted(
            recording, scan, times, place[rows], likeness[ticks[rows]], owner[ticks[rows]],
            sounds, sources, kept=out[ticks[rows]])  # fmt: skip


def _refitted(recording, scan, times, at, likeness, whose, sounds, sources, kept=None):
    """((n,) onsets, (n,) likeness): each tick of train ``whose`` fitted again around
    ``at`` (s), beside the other ticks that sound there (``sources``, `sounding`), where
    the fit lands within that search's reach (short of `EDGE`) and sounds more like the
    tick than its ``likeness`` now; elsewhere ``kept`` (default ``at``) and its
    likeness."""
    again = fit(recording, scan, at, [sounds[m] for m in whose],
                context(times, sources, sounds, at, whose))  # fmt: skip
    better = (np.abs(again.onset - at) < SEARCH - EDGE) & (again.likeness > likeness)
    kept = at if kept is None else kept
    return np.where(better, again.onset, kept), np.where(better, again.likeness, likeness)


def _begins_away(
    fitted: np.ndarray, onset: np.ndarray, likeness: np.ndarray, alone: np.ndarray | None = None
) -> np.ndarray:
    """Whether each tick's own sound, fitted at ``fitted`` (s), begins more than `CRACK`
    from its detected ``onset`` and sounds like it there (`CRACK_LIKENESS`; where no
    other train's tick sounds in its window (``alone``), `MIN_LIKENESS`: no other
    metronome's onset can have drawn it there, and a bump's thump under a tick leaves
    it less alike, corpus seed 4/466: 0.41, its crack 2.8 ms ahead): something else
    made the onset."""
    bar = np.where(alone, MIN_LIKENESS, CRACK_LIKENESS) if alone is not None else CRACK_LIKENESS
    return (np.abs(fitted - onset) > CRACK) & (likeness >= bar)


def _alone_where_it_fits_better(recording, scan, at, own, around, fitted, likeness) -> None:
    """Ticks whose own sound alone explains their window better than beside the other
    ticks' sounds, timed alone (``fitted``, ``likeness`` changed in place): the others
    did not sound there as learned (a later impact that came at another moment). In
    corpus seed 3/187 a tick 32 ms after another's was fitted 1.1 ms late beside it,
    0.45 alike, and 0.53 alike alone on its onset. Only by a margin (`ALONE_BETTER`):
    of 3,357 ticks fitted beside others in seeds 3/180-191 and 4/180-187, 27 more
    sound a little more alike alone (up to 0.05), each timed within 0.01 ms of the fit
    beside the others, and one in seed 4/24, 50.8 ms after another's, as alike either
    way to 0.01, is on time beside it and 1.4 ms late alone."""
    rows = np.flatnonzero([bool(c) for c in around])
    if rows.size == 0:
        return
    alone = fit(recording, scan, at[rows], [own[r] for r in rows], [[] for _ in rows])
    better = alone.likeness >= likeness[rows] + ALONE_BETTER
    fitted[rows[better]] = alone.onset[better]
    likeness[rows[better]] = alone.likeness[better]


def _beside_a_hidden_tick(
    recording, scan, times, trains, sounds, owner, held, own, around, fitted, likeness
) -> None:
    """Ticks another train holds as hidden behind them, timed again beside that
    train's sound at the onset (``fitted``, ``likeness`` changed in place): it ticked
    there too, and two metronomes a millisecond apart make one onset, the first's
    (corpus seeds 3/90, 4/202: the second's tick timed at it, 1.1 ms early). Taken
    only where the tick's own sound then fits more than `CRACK` from the onset and
    sounds like it there (`CRACK_LIKENESS`): a train that jumps between two hidden
    metronomes takes ticks as hidden that are not its own, and its sound beside a
    tick would only make the tick sound less like itself (corpus seed 4/1)."""
    row = {int(k): r for r, k in enumerate(held)}
    rows, beside = [], []
    for m, t in enumerate(trains):
        if sounds[m] is None:
            continue
        for k in t.index[t.masked]:
            if int(k) in row and owner[k] != m:
                rows.append(row[int(k)])
                beside.append(around[row[int(k)]] + [(sounds[m], times[k])])
    if not rows:
        return
    order = np.argsort(rows, kind="stable")  # in time order, as `fit` reads the file
    where = np.array(rows)[order]
    beside = [beside[i] for i in order]
    again = fit(recording, scan, times[held[where]], [own[r] for r in where], beside)
    take = _begins_away(again.onset, times[held[where]], again.likeness)
    fitted[where[take]] = again.onset[take]
    likeness[held[where[take]]] = again.likeness[take]


def _behind_a_crack(
    recording, scan, times, out, likeness, trains, sounds, owner, held, sources, rows
) -> None:
    """Ticks heard just behind a louder sound, timed and judged again in place (``out``,
    ``likeness``): a handling bump opens with a broadband crack, and a tick that begins
    a few milliseconds after it is no onset of its own (the detector's `RESOLUTION`);
    its train holds the crack, which sounds unlike it (corpus seeds 3/176, 4/40, 3/5:
    likeness 0.07-0.21, the tick 3.9-4.5 ms later). Each tick too unlike its sound to
    stay (`unlike`, with its lower bar in another's ring: a tick there, 0.34 alike,
    was moved onto a later sound, corpus seed 4/110) is fitted again `LATE` after its
    onset; where its own sound is there, beyond the first fit's `SEARCH`, it is the
    tick. ``held[rows]``: the ticks to look at."""
    low = rows[unlike(likeness, trains, times)[held[rows]]]
    if low.size == 0:
        return
    at = times[held[low]] + LATE
    own = [sounds[owner[i]] for i in held[low]]
    around = context(out, sources, sounds, at, owner[held[low]])
    later, alike, _ = fit(recording, scan, at, own, around)
    # beyond the first search only, where it has not judged already (a different
    # context there is no reason to move a tick: corpus seed 3/17), and not at the
    # far end, where a tick would have been heard as an onset of its own; and plainly
    # its sound: a tick 1-3 ms after another metronome's, on one onset, fits itself a
    # millisecond late at 0.36-0.64 (corpus seeds 3/18, 3/29, 4/3, 4/25)
    moved = later - times[held[low]]
    found = (alike >= BEHIND_LIKENESS) & (moved > SEARCH) & (moved < LATE)
    out[held[low[found]]] = later[found]
    likeness[held[low[found]]] = alike[found]


def unlike(likeness: np.ndarray, trains: list[Train], times=None) -> np.ndarray:
    """(K,) True for the ticks that sound too little like their train's sound to be
    its metronome's (see `MIN_LIKENESS`; NaN: unknown, never unlike). A kind of beat
    whose every tick the sound explains less well (a softer tock, its first
    milliseconds more the broadband crack of its impact than its resonances: 0.25-0.3
    in corpus seed 147) is judged against its own median. Given the tick ``times``
    (s), a tick in another train's ring is judged against `RING_LIKENESS` at most."""
    ring = _in_anothers_ring(times, trains) if times is not None else None
    out = likeness < MIN_LIKENESS
    if ring is not None:
        out[ring] = likeness[ring] < RING_LIKENESS
    for t in trains:
        for kind in (0, 1):
            of_kind = t.beat % 2 == kind
            mine = t.index[of_kind]
            typical = likeness[t.index[of_kind & ~t.masked]]
            typical = typical[np.isfinite(typical)]
            if typical.size < MIN_CLEAR:
                continue
            limit = np.clip(LIKENESS_SHARE * np.median(typical), BUMP_LIKENESS, MIN_LIKENESS)
            if ring is not None:
                limit = np.where(ring[mine], min(limit, RING_LIKENESS), limit)
            out[mine] = likeness[mine] < limit
    return out


def _in_anothers_ring(times: np.ndarray, trains: list[Train]) -> np.ndarray:
    """(K,) True for the ticks held by a train that begin in the ring of another train's
    tick past its later impacts: `LATER_IMPACTS` to `AFTER` after it (a tick two trains
    hold as hidden behind each other sounds as both, `sounding`)."""
    ticks, whose = sounding(times, trains)
    out = np.zeros(times.size, dtype=bool)
    for m, t in enumerate(trains):
        others = times[ticks[whose != m]]
        if others.size == 0 or t.index.size == 0:
            continue
        mine = times[t.index]
        j = np.searchsorted(others, mine, side="right") - 1
        since = np.where(j >= 0, mine - others[np.maximum(j, 0)], np.inf)
        out[t.index] = (since > LATER_IMPACTS) & (since <= AFTER)
    return out

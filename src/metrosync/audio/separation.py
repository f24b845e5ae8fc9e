"""Several metronomes on one recording, told apart: impacts → ticks → one train each.

Contract: `separate(recording, impacts)` takes every impact the detector heard
(`detection.Ticks`, sorted, several per real tick) and returns a `Separation`: which
impacts start a tick (``head``), and each metronome's tick train (indices into the
impacts), or none with the reason.

Steps: the impacts are grouped into voices by their sound (`voices`: the grouping with
the most voices in which every voice carries tick trains of its own, but a voice of a
few odd sounds with none (all such under `ODD_VOICE` of the ticks); where none does
and there is a grouping whose trains each hold `trains.MIN_COVERAGE` of their beats
(else `LAST_COVERAGE`) and borrow at most `LAST_BORROWED` of their ticks from other
voices, the first such grouping rather than tempo alone; where a
grouping of fewer voices makes more metronomes than the first whose trains each hold
`trains.MIN_COVERAGE` of their beats, the latter: a metronome whose sounds share
voices with others' falls into pieces its voices no longer join);
within each voice the impacts of one tick become one tick, timed at its first
impact, and the voice's ticks are followed as trains, one per metronome that sounds
like it, told apart by tempo (`trains`); a tick and a tock that sound different are
joined into one metronome. An impact that sounds like no voice and that no train
took is an odd sound, not a tick. Metronomes are numbered by loudness, the loudest
first.

How sure. `confidence` in [0, 1] is the product of the share of ticks placed in a
train, the smallest coverage (share of a train's beats heard) and, when voices were
told apart, min(1, separation / (2 × `voices.MIN_SEPARATION`)); words for it in
`sureness`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._words import plural
from . import trains as tr
from .voices import MIN_SEPARATION, Voices, cluster_voices, impact_features

#: Share of a voice's ticks that its trains must hold for the voice to stand.
CARRIED = 0.5
#: Voices of fewer than this share of the ticks together, with no train of their own,
#: are odd sounds, not a metronome's (corpus seed 28: one tick's later impact heard
#: alone on every fourth beat, 4 % of the ticks, kept every finer grouping from
#: standing; seed 8 of three metronomes: three such voices, 9 %, were a grouping that
#: split a metronome).
ODD_VOICE = 0.05
#: Largest share of a train's ticks taken from other voices.
MOST_BORROWED = 0.25
#: ... in the groupings kept in case tempo alone would make more metronomes: where
#: four metronomes tick, a quarter of one's ticks can be hidden by the others' (corpus
#: seed 76: 0.253, and tempo alone made seven metronomes of four).
LAST_BORROWED = 1 / 3
#: Smallest share of its beats a metronome's train holds.
MIN_JOINED_COVERAGE = 0.55
#: ... in the last grouping tried before tempo alone: four metronomes can hide most
#: of one's beats before its beats are sought again (`recovery`).
LAST_COVERAGE = 0.3


@dataclass(frozen=True)
class Separation:
    """What `separate` found.

    head : (K,) True for the impacts that start a tick.
    voices : the `Voices` of the impacts.
    trains : one `trains.Train` per metronome (indices into the impacts).
    train_voices : the voices of each train.
    gaps : (V,) how far a tick of each voice reaches, s.
    method : how they were told apart (``"sound"``, ``"tempo"``, ``"sound and tempo"``,
        ``"one metronome"`` or ``"none"``).
    confidence : see the module docstring.
    note : why nothing (more) was told apart, or "".
    """

    head: np.ndarray
    voices: Voices
    trains: list = field(default_factory=list)
    train_voices: list = field(default_factory=list)
    gaps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    method: str = "none"
    confidence: float = 0.0
    note: str = ""

    def labels(self) -> np.ndarray:
        """(K,) metronome of each impact that starts a tick: the one train that took it;
        −1: none, or two trains share it (their ticks fell together)."""
        out = np.full(self.head.size, -1, dtype=np.int8)
        claims = np.zeros(self.head.size, dtype=np.int64)
        for t in self.trains:
            claims[t.index] += 1
        for m, t in enumerate(self.trains):
            own = t.index[claims[t.index] == 1]
            out[own] = m
        return out


def sureness(confidence: float) -> str:
    """Words for a `Separation.confidence`."""
    if confidence >= 0.9:
        return "sure"
    if confidence >= 0.7:
        return "fairly sure"
    return "unsure: check the plot"


def separate(recording, impacts, *, bpm: float | None = None, seed: int = 0) -> Separation:
    """Tell the metronomes of ``recording`` apart (see the module docstring).

    bpm : the metronomes' setting: their beats are sought within ±15 % of it (or of
        twice it, for a tick and a tock that sound different).
    """
    beat_range = tr.BEAT_RANGE if bpm is None else (0.85 * 60 / bpm, 2.3 * 60 / bpm)
    times = impacts.time
    features = impact_features(recording, times)
    weak = {}  # coverage: the first grouping whose trains each hold that much
    for voices in cluster_voices(features, seed=seed):
        head, gaps, found, groups = _trains(times, impacts.strength, voices, beat_range)
        if voices.count == 1 or _all_voices_carry(head, voices, found, groups):
            break
        for least in (tr.MIN_COVERAGE, LAST_COVERAGE):
            if least not in weak and _all_voices_carry(
                head, voices, found, groups, least, LAST_BORROWED
            ):
                weak[least] = voices, head, gaps, found, groups
    fallback = weak.get(tr.MIN_COVERAGE, weak.get(LAST_COVERAGE))
    if voices.count == 1 and fallback is not None:
        # tempo alone would make more metronomes than the sounds: a faint metronome,
        # a third of its beats unheard, is one metronome, not pieces of several; or as
        # many: two of nearly one tempo, their ticks meeting again and again, are told
        # apart by their sounds, where tempo alone swaps them (corpus seed 96); or
        # fewer: it left a metronome whose ticks were heard to no one (seed 3/355: one
        # of 121 BPM, in two pieces of every third beat where sounds were told apart)
        voices, head, gaps, found, groups = fallback
    elif tr.MIN_COVERAGE in weak and len(found) > len(weak[tr.MIN_COVERAGE][3]):
        # so would fewer voices: a metronome whose tick and tock were two voices, its
        # tocks half hidden by a metronome 2 % from its tempo, holds half its beats
        # (0.53) as one train there, and is three pieces at a quarter and a half of
        # its tempo where its sounds share a voice with others' (unseen corpus 4/250)
        voices, head, gaps, found, groups = weak[tr.MIN_COVERAGE]
    if not found:
        return Separation(head, voices, gaps=gaps, note="no steady tick train was found")
    loud = [float(np.mean(impacts.strength[t.index])) for t in found]
    order = np.argsort(loud)[::-1]
    found = [found[i] for i in order]
    groups = [groups[i] for i in order]
    sets = [frozenset(g) for g in groups]
    shared = sum(a & b != frozenset() for i, a in enumerate(sets) for b in sets[i + 1 :])
    pairs = len(sets) * (len(sets) - 1) // 2
    if len(found) == 1:
        method = "one metronome"
    elif shared == 0:
        method = "sound"
    elif shared == pairs and len(set(sets)) == 1:
        method = "tempo"
    else:
        method = "sound and tempo"
    distinct = len(set().union(*sets))
    placed = np.zeros(times.size, dtype=bool)
    for t in found:
        placed[t.index] = True
    # an odd sound (no voice) that no metronome took is not a tick: a bump, a pre-echo
    head &= placed | (voices.labels >= 0)
    share = placed[head].mean() if head.any() else 0.0
    coverage = min(t.coverage for t in found)
    conf = share * coverage
    if distinct > 1:
        conf *= min(1.0, voices.separation / (2 * MIN_SEPARATION))
    return Separation(head, voices, found, groups, gaps, method, float(conf), "")


def _trains(times, strength, voices: Voices, beat_range):
    head, gaps = tr.group_impacts(times, voices.labels, strength)
    found, of_voice = [], []
    for v in range(voices.count):
        own = np.flatnonzero(head & (voices.labels == v))
        others = np.flatnonzero(head & (voices.labels != v))
        for t in tr.trains_of_voice(times, own, others=others, beat_range=beat_range):
            found.append(t)
            of_voice.append(v)
    found, of_voice = tr.drop_shared(found, of_voice)
    found = tr.own_again(found, of_voice, voices.labels)
    found, of_voice, folded = tr.fold_parts(times, found, of_voice, strength)
    for index in folded:
        head[index] = False
    found, groups = tr.join_fragments(times, found, of_voice)
    found = tr.first_impacts(times, strength, found, head)
    return head, gaps, found, groups


def _all_voices_carry(
    head,
    voices: Voices,
    found,
    groups,
    coverage: float = MIN_JOINED_COVERAGE,
    borrowed: float = MOST_BORROWED,
) -> bool:
    """Each voice has at least `CARRIED` of its ticks in trains of its own, or in trains
    of other voices as ticks that hid theirs (a voice of ticks that fall together), and
    no train borrows more than ``borrowed`` (`MOST_BORROWED`) of its ticks from other
    voices (a voice split in two by chance leaves each half with holes that the other
    fills) or has fewer than ``coverage`` of its beats (`MIN_JOINED_COVERAGE`). A voice
    of odd sounds, no train's, need carry nothing while all such voices together hold
    under `ODD_VOICE` of the ticks."""
    if any(t.masked.mean() > borrowed or t.coverage < coverage for t in found):
        return False
    odd = 0  # ticks of voices of odd sounds, left out
    for v in range(voices.count):
        mine = head & (voices.labels == v)
        if not mine.any():  # folded into another voice's ticks
            continue
        if not any(v in g for g in groups):
            odd += int(mine.sum())
            if odd < ODD_VOICE * head.sum():
                continue  # a few odd sounds: a tick's later impact on some beats, bumps
        placed = np.zeros(head.size, dtype=bool)
        shared = np.zeros(head.size, dtype=bool)
        for t, g in zip(found, groups, strict=True):
            if v in g:
                placed[t.index[~t.masked]] = True
            else:
                shared[t.index[t.masked]] = True
        if placed[mine].mean() < CARRIED and shared[mine].mean() < CARRIED:
            return False
    return True


def tick_length_words(sep: Separation) -> str:
    """The ticks' structure in words, e.g. "grouped into 120 ticks (2.0 impacts each)"."""
    ticks = int(sep.head.sum())
    per = sep.head.size / max(ticks, 1)
    if per < 1.05:
        return f"{plural(ticks, 'tick')}, one impact each"
    return f"grouped into {plural(ticks, 'tick')} ({per:.1f} impacts each, a tick counted once)"

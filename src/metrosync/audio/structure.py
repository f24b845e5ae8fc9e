"""A metronome's tick as the recording shows it: its impacts, learned, and its timing.

The model (docs/sound.md, "The timing model"). A tick is several impacts: the pallet
striking, a quieter one before it on some makes (10–45 ms ahead, wandering from tick to
tick), bounces after it. Relative to the metronome's beat (`timing.Timing`), impact j of
a tick falls at offset o_j with spread s_j, and is heard in a share p_j of the beats;
onsets that belong to no impact are clutter, spread evenly over the beat. So the offsets
d = t − τ_k of the onsets near a metronome's beats τ_k are a one-dimensional mixture:
Gaussians N(o_j, s_j²) weighted p_j, plus a uniform component. It is fitted by
expectation–maximisation, with the number of impacts chosen by the Bayesian
information criterion (BIC); nothing about how many impacts a tick has, in which order
or how far apart, is assumed. A component whose onsets come in runs of beats rather
than all along is another metronome's beat sliding past, and is clutter (`_passing`);
so is one whose onsets keep to one residue of the beat's number modulo a small m,
another metronome ticking in a whole-number ratio with this one (`_locked`). Each
beat's onsets are then paired one-to-one with the impacts (`_assigned`: an impact is
struck once a beat at most), the strike's timing taken as Student-t (`MODEL.jitter_dof`).

The tick's time is the time of its most regular impact, the one of smallest spread
among those heard in at least `MODEL.heard_share` of the beats: the escapement's impact,
whose timing is the metronome's; a precursor wanders more. A bounce is struck by the
strike and keeps its jitter: of impacts within `MODEL.strike_spread` of the most regular
one's spread, the loudest is the strike. The timing
model is refitted to those impacts alone, and the two steps repeat.

Contract: `follow(times, bpm)` finds, from a candidate tempo, the metronome whose ticks
best explain the onsets ``times``: its `Timing`, its `Structure`, and for each onset
which beat and impact explain it (or none). Times in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy import special
from scipy.stats import kstwo

from ..errors import AnalysisError
from .periodicity import SEGMENT
from .settings import MODEL
from .timing import Timing, fit_timing

#: Most impacts a tick or a tock is learned with: a bound on the search, not an
#: assumption of the model (BIC chooses how many).
MAX_IMPACTS = 4
#: Refits of the timing on the ticks' main impacts, and of the impacts on the timing.
ROUNDS = 4
#: Length of the first stretch the timing is fitted on, s; each next one doubles it, so
#: that a tempo known to the periodicity search's resolution never loses count of beats.
FIRST_STRETCH = 10.0
#: Newton steps from t/T to the beat number the timing model puts nearest an onset (each
#: squares the error: three take a guess whole beats off to the right beat).
NEWTON_STEPS = 3
#: Bin and window of the offsets' density where the main impact is sought, s: finer
#: than the gap between two impacts, wider than an escapement's jitter.
BIN, WINDOW = 0.5e-3, 3e-3
#: Fewest onsets per impact fitted: with fewer, a mixture splits one impact's jitter
#: into narrow impacts of its own, each fitting a handful of onsets.
ONSETS_PER_IMPACT = 5
#: Fewest ticks on which the drift is fitted: a spring unwinding changes the tempo by up
#: to a BPM a minute, a millisecond's shift in twenty seconds, as much as the jitter,
#: and a fit without it extrapolates the first stretch's tempo too far.
DRIFT_TICKS = 12
#: Largest m of the m-to-n ratios of beats in which another metronome is sought among a
#: tick's impacts (`_locked`): the ratios of two tempi in 30-300 BPM that put the
#: other's ticks near this one's offsets often enough to be learned as an impact.
LOCKED_MAX = 6


@dataclass(frozen=True)
class Impact:
    """One impact of a tick: ``offset`` (s, from the beat; negative: before),
    ``spread`` (s, its std tick to tick), ``presence`` (share of beats heard in),
    ``level`` (dB, how loud)."""

    offset: float
    spread: float
    presence: float
    level: float = math.nan  # dB, the mean strength of its onsets (nan: not given)


@dataclass(frozen=True)
class Structure:
    """A tick's impacts, by offset, and which of them is the main one (the tick's time)."""

    impacts: tuple[Impact, ...]
    main: int
    clutter: float  # share of the onsets near the beats that no impact explains

    @property
    def main_impact(self) -> Impact:
        return self.impacts[self.main]

    def log_density(self, j: int, offset) -> np.ndarray:
        """log of impact j's rate at ``offset`` (s from the beat): presence × its density
        (1/s); the main impact's timing is Student-t (`MODEL.jitter_dof`), as the timing model
        takes it, the others' Gaussian."""
        impact = self.impacts[j]
        z = (np.asarray(offset, dtype=float) - impact.offset) / impact.spread
        main = j == self.main
        shape = _student_t_logpdf(z, MODEL.jitter_dof) if main else -0.5 * z * z - _LOG_ROOT_2PI
        return math.log(max(impact.presence, 1e-300)) + shape - math.log(impact.spread)


@dataclass(frozen=True)
class Followed:
    """A metronome found from a candidate tempo.

    timing : its timing model, fitted to the main impacts, whose offset is 0.
    structure : the impacts of its tick and of its tock (even and odd beats), offsets
        relative to that timing.
    beat : (K,) for each onset, the beat it lies nearest (−1 beyond `MODEL.reach`).
    impact : (K,) the impact that most probably explains it, −1 for clutter or beyond.
    main : (K,) True for the onset that times its beat (one a beat at most).
    """

    timing: Timing
    structure: tuple[Structure, Structure]
    beat: np.ndarray
    impact: np.ndarray
    main: np.ndarray

    @property
    def ticks(self) -> np.ndarray:
        """Indices of the onsets that time the ticks."""
        return np.flatnonzero(self.main)

    def intensity(self, times) -> np.ndarray:
        """(K,) how many of this metronome's onsets the model expects per second at each
        of ``times`` (1/s): Σ_j p_j N(t − τ_k − o_j; 0, s_j²) over the impacts j of the
        nearest beat's kind, 0 beyond `MODEL.reach` of a beat."""
        t = np.asarray(times, dtype=float)
        beat, offset = _nearest_beats(t, self.timing)
        near = np.abs(offset) <= MODEL.reach * self.timing.period
        out = np.zeros(t.size)
        for kind, structure in enumerate(self.structure):
            mine = near & (np.mod(beat, 2) == kind)
            for j in range(len(structure.impacts)):
                out[mine] += np.exp(structure.log_density(j, offset[mine]))
        return out


def learn_structure(offsets, beats, reach: float, strengths=None) -> tuple[Structure, np.ndarray]:
    """The impacts that explain ``offsets`` (s, onsets about their beats, within ±reach)
    at beat numbers ``beats``, with the onsets' ``strengths`` (dB, optional); and (K,)
    each offset's impact (−1: clutter).

    The main impact is found first, as the sharpest bump of the offsets heard in at
    least `MODEL.heard_share` of the beats (`_main_bump`); the mixture starts from it, so
    that a few ticks cannot split its jitter, and fits the other impacts around it.
    """
    d = np.asarray(offsets, dtype=float)
    b = np.asarray(beats)
    v = None if strengths is None else np.asarray(strengths, dtype=float)
    span = int(b.max() - b.min()) // 2 + 1 if b.size else 0  # beats of this kind
    centre, width = _main_bump(d, b, span)
    best = None
    for count in range(1, MAX_IMPACTS + 1):
        if d.size < ONSETS_PER_IMPACT * count:
            break
        fitted = _mixture(d, count, reach, centre, width)
        if count > 1 and np.min(fitted[3]) * d.size < ONSETS_PER_IMPACT:
            # an impact fitted to a handful of onsets is the tail of another's jitter
            # (an escapement's 4-sigma tick), not an impact of its own
            continue
        if best is None or fitted[0] < best[0]:
            best = fitted
    if best is None:
        raise AnalysisError(f"too few onsets ({d.size}) to learn a tick's impacts")
    _, means, spreads, shares, resp = best
    # a component wider than an impact wanders is no impact: the onsets of another
    # metronome whose beat slides past this one's (clutter, left for it to be found);
    # nor is one whose onsets come in a few runs of beats, not all along (`_passing`)
    label = np.argmax(resp, axis=1)
    wide = ((spreads > MODEL.impact_spread[1]) | _passing(b, label, means.size)
            | _locked(b, label, means.size))  # fmt: skip
    if wide.all():
        wide[np.argmin(spreads)] = False
    if wide.any():
        resp = np.column_stack([resp[:, :-1][:, ~wide],
                                resp[:, -1] + resp[:, :-1][:, wide].sum(axis=1)])  # fmt: skip
        means, spreads, shares = means[~wide], spreads[~wide], shares[~wide]
    presence = shares * d.size / max(span, 1)
    order = np.argsort(means)
    means, spreads, presence = means[order], spreads[order], presence[order]
    resp = resp[:, np.append(order, means.size)]
    levels = (
        np.full(means.size, np.nan)
        if v is None
        else (resp[:, :-1] * v[:, None]).sum(axis=0) / np.maximum(resp[:, :-1].sum(axis=0), 1e-12)
    )
    main = _main(means, spreads, presence, max(span, 1), levels, centre)
    impacts = tuple(
        Impact(float(m), float(s), float(min(p, 1.0)), float(v))
        for m, s, p, v in zip(means, spreads, presence, levels, strict=True)
    )
    label = np.argmax(resp, axis=1)
    label[label == means.size] = -1
    clutter = float(resp[:, -1].mean())
    return Structure(impacts, main, clutter), label


def _passing(beats: np.ndarray, label: np.ndarray, count: int) -> np.ndarray:
    """(count,) which components of a tick's mixture are another metronome's beat passing
    this one's, not an impact: an impact is struck at every beat it is heard at, so the
    beat numbers of its onsets are spread evenly over the recording's beats; a train
    sliding past at another tempo crosses a given offset only now and then, in runs.
    Kolmogorov–Smirnov test of each component's beat numbers against the uniform over
    the beats, at false-alarm probability `MODEL.false_alarm`; the first component (started on
    the main impact) is not tested."""
    out = np.zeros(count, dtype=bool)
    if beats.size == 0:
        return out
    lo, width = float(beats.min()), float(beats.max() - beats.min()) + 1.0
    for j in range(1, count):
        mine = beats[label == j]
        if mine.size >= ONSETS_PER_IMPACT:
            out[j] = _uniformity_p(np.clip((mine - lo) / width, 0.0, 1.0)) < MODEL.false_alarm
    return out


def _locked(beats: np.ndarray, label: np.ndarray, count: int) -> np.ndarray:
    """(count,) which components of a tick's mixture are another metronome ticking in a
    ratio of small whole numbers with this one (m beats of this kind to n of its): an
    impact is struck at each beat of its kind by chance (its presence), whatever the
    beat's number, but such a neighbour falls near the same offset only every m-th
    beat, in one residue of the beat's number modulo m. A χ² test of each component's
    residues modulo m = 2 … `LOCKED_MAX` against the beats available in each, at
    false-alarm probability `MODEL.false_alarm` over the m tried; the first component (started
    on the main impact) is not tested."""
    out = np.zeros(count, dtype=bool)
    if beats.size == 0:
        return out
    index = (beats - beats.min()) // 2  # the beat's number among those of its kind
    available = np.arange(int(index.max()) + 1)
    tried = LOCKED_MAX - 1
    for j in range(1, count):
        mine = index[label == j]
        if mine.size < ONSETS_PER_IMPACT:
            continue
        for m in range(2, LOCKED_MAX + 1):
            expected = np.bincount(available % m, minlength=m) * mine.size / available.size
            seen = np.bincount(mine % m, minlength=m)
            statistic = float(np.sum((seen - expected) ** 2 / np.maximum(expected, 1e-12)))
            if special.chdtrc(m - 1, statistic) < MODEL.false_alarm / tried:  # χ² survival
                out[j] = True
                break
    return out


def _student_t_logpdf(z, dof: float):
    """log of Student's t density with ``dof`` degrees of freedom at ``z`` (what
    `scipy.stats.t.logpdf` returns, without its per-call checks)."""
    norm = special.gammaln((dof + 1) / 2) - special.gammaln(dof / 2) - 0.5 * math.log(dof * math.pi)
    return norm - (dof + 1) / 2 * np.log1p(np.square(z) / dof)


def _uniformity_p(u: np.ndarray) -> float:
    """The Kolmogorov–Smirnov test's p-value of values ``u`` in [0, 1] against the
    uniform: the exact distribution of D_n (`scipy.stats.kstwo`), as `scipy.stats.kstest`
    computes it, without its per-call set-up."""
    x = np.sort(u)
    n = x.size
    rank = np.arange(1, n + 1) / n
    d = max(float(np.max(rank - x)), float(np.max(x - (rank - 1.0 / n))))
    return float(kstwo.sf(d, n))


def _main(means, spreads, presence, beats: int, levels, centre: float) -> int:
    """The main impact, the strike: of those heard in `MODEL.heard_share` of the
    ``beats``, the loudest of those whose spread is within `MODEL.strike_spread` times
    the most regular one's. A bounce is struck by the strike and keeps its jitter, so
    which of them is the more regular is down to how well each onset is timed; a
    precursor's lead wanders, several times more. The mixture, started on the bump at
    ``centre``, has the last word, so that a first timing locked on a bounce corrects
    itself."""
    heard = np.flatnonzero(presence >= MODEL.heard_share)
    if not heard.size:
        return int(np.argmin(np.abs(means - centre)))
    sharpest = heard[np.argmin(spreads[heard])]
    alike = heard[spreads[heard] <= MODEL.strike_spread * spreads[sharpest]]
    if alike.size > 1 and np.all(np.isfinite(levels[alike])):
        return int(alike[np.argmax(levels[alike])])
    return int(sharpest)


def _main_bump(d: np.ndarray, beats: np.ndarray, span: int) -> tuple[float, float]:
    """Offset and spread (s) of the most regular impact heard in `MODEL.heard_share` of the
    beats: of the bumps of the offsets' density (a histogram of `BIN` smoothed over
    `WINDOW`), those that hold an onset in enough beats, the one of smallest robust
    spread."""
    if not d.size:
        raise AnalysisError("no onset near the beats: not a metronome's beat")
    edges = np.arange(d.min() - WINDOW, d.max() + WINDOW + BIN, BIN)
    count, _ = np.histogram(d, edges)
    smooth = np.convolve(count, np.ones(round(WINDOW / BIN)), mode="same")
    centres = 0.5 * (edges[1:] + edges[:-1])
    peaks = np.flatnonzero((smooth >= np.roll(smooth, 1)) & (smooth > np.roll(smooth, -1)))
    best = None
    for p in peaks:
        near = np.abs(d - centres[p]) <= WINDOW
        heard = np.unique(beats[near]).size / max(span, 1)
        if heard < MODEL.heard_share:
            continue
        centre = float(np.median(d[near]))
        spread = max(1.4826 * float(np.median(np.abs(d[near] - centre))), MODEL.impact_spread[0])
        if best is None or spread < best[1]:
            best = (centre, spread)
    if best is None:
        raise AnalysisError("no impact is heard in half the beats: not a metronome's beat")
    return best


def _mixture(d: np.ndarray, count: int, reach: float, centre: float, width: float,
             iterations: int = 60):  # fmt: skip
    """EM of ``count`` Gaussians and a uniform on [−reach, reach] over the offsets ``d``,
    the first started on the main impact (``centre``, ``width``), the others at the
    quantiles of the rest: (BIC, means, spreads, shares, responsibilities (K, count+1))."""
    rest = d[np.abs(d - centre) > 3 * width]
    others = (
        np.quantile(rest, (np.arange(count - 1) + 0.5) / max(count - 1, 1)) if rest.size else []
    )
    means = np.array([centre, *others][:count], dtype=float)
    if means.size < count:
        means = np.append(means, np.linspace(-reach, reach, count - means.size))
    spreads = np.full(count, max(float(np.std(rest)) / count if rest.size else width, width))
    spreads[0] = width
    shares = np.full(count + 1, 1.0 / (count + 1))
    resp, total = _em(d, means, spreads, shares, 1.0 / (2.0 * reach), iterations,
                      MODEL.impact_spread[0])  # fmt: skip
    loglik = float(np.log(np.maximum(total, 1e-300)).sum())
    parameters = 3 * count  # mean, spread, share each (the clutter's share is the rest)
    bic = -2.0 * loglik + parameters * math.log(d.size)
    return bic, means, spreads, shares[:count], resp


@nb.njit(cache=True)
def _em(d, means, spreads, shares, uniform, iterations, narrowest):
    """`_mixture`'s EM iterations, in place on ``means``, ``spreads`` and ``shares``
    (the last the uniform clutter's): (responsibilities (K, count+1), each onset's
    total density). Stops early once an iteration moves no parameter by more than
    `_SETTLED` (then every later one would repeat it); no spread below ``narrowest``
    (s)."""
    k, count = d.size, means.size
    resp = np.empty((k, count + 1))
    total = np.empty(k)
    scale = 1.0 / math.sqrt(2.0 * math.pi)
    for _ in range(iterations):
        for i in range(k):
            sum_i = 0.0
            for j in range(count):
                z = (d[i] - means[j]) / spreads[j]
                resp[i, j] = shares[j] * math.exp(-0.5 * z * z) * scale / spreads[j]
                sum_i += resp[i, j]
            resp[i, count] = shares[count] * uniform
            sum_i += resp[i, count]
            total[i] = sum_i
            inv = 1.0 / max(sum_i, 1e-300)
            for j in range(count + 1):
                resp[i, j] *= inv
        moved = 0.0
        for j in range(count + 1):
            weight = 0.0
            for i in range(k):
                weight += resp[i, j]
            share = max(weight / k, 1e-9)
            moved = max(moved, abs(share - shares[j]))
            shares[j] = share
            if j == count:
                continue
            held = weight > 1e-9
            safe = weight if held else 1.0
            mean = means[j]
            if held:
                mean = 0.0
                for i in range(k):
                    mean += resp[i, j] * d[i]
                mean /= safe
            var = 0.0
            for i in range(k):
                var += resp[i, j] * (d[i] - mean) ** 2
            spread = max(math.sqrt(var / safe), narrowest)
            moved = max(moved, abs(mean - means[j]), abs(spread - spreads[j]))
            means[j], spreads[j] = mean, spread
        if moved < _SETTLED:
            break
    return resp, total


_LOG_ROOT_2PI = 0.5 * math.log(2.0 * math.pi)

#: A change of an EM parameter (s, or a share) below which it has settled.
_SETTLED = 1e-12


def follow(times, bpm: float, strengths=None, *, drift: bool = True,
           start: Timing | None = None, refind: bool = False) -> Followed:  # fmt: skip
    """The metronome at about ``bpm`` whose ticks best explain the onsets ``times``
    (their ``strengths``, dB, tell a strike from a bounce as regular as it); from the
    timing ``start`` where one is known over the whole recording (then ``bpm`` is its).
    ``refind``: where the ticks are lost for a while, they are found again after
    (`_found_again`), for onsets that hold no other metronome's ticks (told apart by
    their sound): among others', what comes out of the gap may be another's train.

    The timing is first fitted on the first `FIRST_STRETCH` seconds, then on longer
    stretches, each as far as the last fit predicts well (`_reach_of`) and numbered by
    that prediction (its wander included: `wander`); on each, the impacts of
    the tick and of the tock (even and odd beats: struck by different pallets, they
    sound and fall differently) are learned and the timing refitted to the main ones
    (`ROUNDS` times).
    """
    t = np.asarray(times, dtype=float)
    level = None if strengths is None else np.asarray(strengths, dtype=float)
    if start is None:
        timing = _start(t, 60.0 / float(bpm))
        end = t[0] + max(FIRST_STRETCH, MODEL.min_beats * timing.period)
    else:
        timing, end = start, t[-1]
    first, lost_at = True, -math.inf
    while True:
        inside = np.flatnonzero(t <= end)
        last, settled, rounds = None, False, 0
        while rounds < ROUNDS:
            try:
                explained = _explain(t[inside], timing, None if level is None else level[inside])
            except AnalysisError:
                if not first or last is not None or end >= t[-1]:
                    raise
                # other metronomes' ticks can hide a kind's for seconds on end: the
                # first stretch is doubled until its ticks are heard in half its beats
                end = t[0] + 2.0 * (end - t[0])
                inside = np.flatnonzero(t <= end)
                continue
            rounds += 1
            mains = inside[explained[2]]
            beats = explained[0][explained[2]]
            if (
                last is not None
                and np.array_equal(mains, last[0])
                and np.array_equal(beats, last[1])
            ):
                settled = True  # the same ticks refit the same timing
                break
            last = (mains, beats)
            enough = drift and mains.size >= DRIFT_TICKS
            timing = fit_timing(t[mains], beats, drift=enough, wander=drift)
        first = False
        again = None
        if refind and mains.size and t[mains].max() > lost_at:  # each gap crossed once
            again = _found_again(t, level, timing, mains, beats, end, drift)
        if again is not None:  # refitted with the ticks after the gap; the stretch again
            lost_at = float(t[mains].max())
            timing, end = again
            continue
        if end >= t[-1]:
            break
        end = max(_reach_of(timing, end), t[0] + 1.25 * (end - t[0]))
    if not (settled and inside.size == t.size):  # else the last round's is this one
        explained = _explain(t, timing, level)
    beat, impact, main, structures = explained
    return Followed(timing, structures, beat, impact, main)


def _found_again(t, level, timing: Timing, mains, beats, end: float, drift: bool):
    """(the timing refitted, the stretch's new end) where the ticks were lost before
    ``end``, or None. Another metronome's ticks can hide this one's for seconds (two
    falling into step sound as one), and the timing, carried past them, then misses
    the ticks where they come out: with `MODEL.min_beats` beats' time of onsets after the
    last tick, a timing is started afresh on them (`_start`) and its beats numbered by
    the old timing's prediction, where that is sure to the beat (its spread under a
    quarter of one); refitted as `follow` fits (``drift``)."""
    period = float(timing.period_at(beats.max()))
    t_last = float(t[mains].max())
    if end - t_last < MODEL.min_beats * period:
        return None
    after = np.flatnonzero(t > t_last + MODEL.reach * period)
    if after.size < MODEL.min_beats // 2:
        return None
    local = _start(t[after], period)
    stretch = after[t[after] <= t[after[0]] + max(FIRST_STRETCH, MODEL.min_beats * period)]
    try:
        explained = _explain(t[stretch], local, None if level is None else level[stretch])
    except AnalysisError:
        return None  # nothing regular after the gap
    k0 = int(_nearest_beats(np.array([local.phase]), timing)[0][0])
    if _spread_at(timing, k0) > period / 4:
        return None  # the gap is too long to count its beats
    more = stretch[explained[2]]
    numbers = explained[0][explained[2]] + k0
    later = numbers > beats.max()
    if not later.any():
        return None
    joined = np.concatenate([mains, more[later]])
    refit = fit_timing(t[joined], np.concatenate([beats, numbers[later]]),
                       drift=drift and joined.size >= DRIFT_TICKS, wander=drift)  # fmt: skip
    return refit, max(end, float(t[more].max()))


def _spread_at(timing: Timing, k: float) -> float:
    """The standard deviation of the timing's prediction of beat ``k``, s: its
    parameters' errors and the wander's random walk past its last tick."""
    sp, st, _, sd = timing.errors
    wander = 0.0
    if timing.wander is not None:
        wander = timing.wander.spread_after(k - float(timing.wander.beats[-1]))
    return math.sqrt(sp**2 + (k * st) ** 2 + (0.5 * k * k * sd) ** 2 + wander**2)


def _reach_of(timing: Timing, end: float) -> float:
    """How far past ``end`` the timing predicts a beat within a third of `WINDOW`, by its
    parameters' errors (at most twice as far from the start as ``end``): beyond, the
    main impact's offsets would smear past the bump that finds it."""
    k_end = (end - timing.phase) / timing.period
    for k in np.arange(k_end, 2 * k_end + 1, 1.0):
        if _spread_at(timing, k) > WINDOW / 3:
            return float(timing.predict(k))
    return float(timing.predict(2 * k_end))


def _explain(t: np.ndarray, timing: Timing, level=None):
    """For onsets ``t`` about ``timing``'s beats: (K,) beat (−1 beyond reach), impact
    (−1: none), main (bool), and the (tick, tock) `Structure`s."""
    beat, offset = _nearest_beats(t, timing)
    reach = MODEL.reach * timing.period
    near = np.abs(offset) <= reach
    impact = np.full(t.size, -1)
    main = np.zeros(t.size, dtype=bool)
    structures = []
    for kind in (0, 1):
        mine = np.flatnonzero(near & (np.mod(beat, 2) == kind))
        strengths = None if level is None else level[mine]
        structure, _ = learn_structure(offset[mine], beat[mine], reach, strengths)
        label = _assigned(offset[mine], beat[mine], structure, reach)
        main[mine[label == structure.main]] = True
        impact[mine] = label
        structures.append(structure)
    return np.where(near, beat, -1), impact, main, tuple(structures)


def explained_by(times, followed: Followed) -> Followed:
    """``followed``'s timing and learned ticks, unchanged, explaining the onsets
    ``times`` instead of those it was fitted on: each onset's beat, impact and whether
    it times its beat, as `follow` decides them."""
    t = np.asarray(times, dtype=float)
    beat, offset = _nearest_beats(t, followed.timing)
    reach = MODEL.reach * followed.timing.period
    near = np.abs(offset) <= reach
    impact = np.full(t.size, -1)
    main = np.zeros(t.size, dtype=bool)
    for kind, structure in enumerate(followed.structure):
        mine = np.flatnonzero(near & (np.mod(beat, 2) == kind))
        label = _assigned(offset[mine], beat[mine], structure, reach)
        main[mine[label == structure.main]] = True
        impact[mine] = label
    return Followed(followed.timing, followed.structure, np.where(near, beat, -1), impact, main)


def _start(t: np.ndarray, period: float) -> Timing:
    """A first timing near ``period``: of trial beats within the periodicity search's
    resolution of it, the one at which the onsets of the first stretch, folded at the
    swing (two beats), put an onset within ±`WINDOW` of one phase in the most swings;
    that phase is beat 0's.

    A candidate's frequency is known to about one independent frequency of the search,
    1/L for a stretch L of the recording folded at once (`periodicity.SEGMENT` at most),
    so its beat to T·T/L: 2 % for a slow metronome in 40 s. Over the first stretch S that
    error alone would smear the main impact's offsets over far more than its jitter;
    the trials step by 2·`WINDOW`/S of the beat, so that the nearest misses by `WINDOW`
    at most over the stretch.
    """
    stretch = t[t <= t[0] + max(FIRST_STRETCH, MODEL.min_beats * period)]
    folded_at_once = min(max(float(t[-1] - t[0]), period), SEGMENT)
    search = period / folded_at_once
    step = 2.0 * WINDOW / max(float(stretch[-1] - stretch[0]), period)
    trials = 2 * math.ceil(search / step) + 1
    best = (-1, 0.0, period)
    for trial in period * (1 + np.linspace(-search, search, trials)):
        swing = 2.0 * trial
        fold = np.mod(stretch - stretch[0], swing)
        edges = np.arange(0.0, swing + BIN, BIN)
        for shift in (0.0, swing / 2):  # a bump across the fold's ends is whole in one
            folded = np.sort(np.mod(fold + shift, swing))
            lo = np.searchsorted(folded, edges - WINDOW)
            hi = np.searchsorted(folded, edges + WINDOW)
            held = hi - lo  # onsets within ±WINDOW: about one a swing on the main impact
            at = int(np.argmax(held))
            if held[at] > best[0]:
                centre = float(np.median(folded[lo[at] : hi[at]])) - shift
                best = (int(held[at]), float(stretch[0] + np.mod(centre, swing)), trial)
    _, phase, trial = best
    # refined by a line through the onsets near that phase, swing after swing: the trial
    # beats' step alone leaves the last swings of the stretch milliseconds off
    for reach in (4 * WINDOW, 2 * WINDOW):
        number = np.round((stretch - phase) / (2 * trial))
        miss = np.abs(stretch - phase - number * 2 * trial)
        order = np.lexsort((miss, number))  # the nearest onset of each swing first
        first = np.ones(order.size, dtype=bool)
        first[1:] = number[order][1:] != number[order][:-1]
        near = order[first & (miss[order] <= reach)]
        if near.size < 4:
            break
        slope, line = np.polyfit(number[near], stretch[near], 1)
        # kept only where it holds as many onsets within ±WINDOW as the fold did: a
        # line through the nearest onsets of a precursor whose lead wanders (or a
        # codec's pre-echo) runs off the beat
        if _held(stretch, line, slope) < _held(stretch, phase, 2 * trial):
            break
        phase, trial = line, slope / 2
    phase -= trial * math.floor((phase - t[0]) / trial)
    return Timing(float(phase), float(trial), 0.0, 0.0, 0.0, (0.0,) * 4, 0)


def _held(t: np.ndarray, phase: float, swing: float) -> int:
    """How many onsets ``t`` lie within ±`WINDOW` of phase + k·swing."""
    miss = t - phase - np.round((t - phase) / swing) * swing
    return int(np.sum(np.abs(miss) <= WINDOW))


def _nearest_beats(t: np.ndarray, timing: Timing) -> tuple[np.ndarray, np.ndarray]:
    """(K,) the beat number whose predicted time is nearest each onset, and the offset."""
    guess = np.round((t - timing.phase) / timing.period)
    # Newton steps on the model's own time of a beat: the drift's ½·Ṫ·k² moves a beat
    # number away from t/T by whole beats over a long recording (1.5 beats after 1,250
    # beats of a metronome speeding up by 0.05 BPM a minute)
    for _ in range(NEWTON_STEPS):
        local = np.maximum(timing.period_at(guess), 0.5 * timing.period)
        guess = np.round(guess + (t - timing.predict(guess)) / local)
    guess = guess.astype(np.int64)
    best = guess
    offset = t - timing.predict(guess)
    for step in (-1, 1):  # the drift and the limp can move the nearest beat by one
        other = guess + step
        off = t - timing.predict(other)
        closer = np.abs(off) < np.abs(offset)
        best = np.where(closer, other, best)
        offset = np.where(closer, off, offset)
    return best, offset


def _assigned(offset: np.ndarray, beat: np.ndarray, structure: Structure, reach: float):
    """(K,) the impact of each onset about its beat (−1: clutter), assigned beat by beat:
    an impact is struck once a beat at most, so within a beat the onsets and impacts are
    paired to maximise Σ log(p_j f_j(d_i) / c) over the pairs (f_j the impact's density,
    c the clutter's), an onset left unpaired being clutter. The main impact's timing is
    Student-t (`MODEL.jitter_dof`), as the timing model takes it: an escapement's rare large
    error should not hand a tick to a precursor, nor the precursor of the same beat."""
    clutter = math.log(max(structure.clutter, 1e-3) / (2.0 * reach))
    gain = np.empty((offset.size, len(structure.impacts)))
    for j in range(len(structure.impacts)):
        gain[:, j] = structure.log_density(j, offset) - clutter
    order = np.argsort(beat, kind="stable")
    label = np.full(offset.size, -1, dtype=np.int64)
    label[order] = _pair_by_beat(np.ascontiguousarray(gain[order]), beat[order].astype(np.int64))
    return label


@nb.njit(cache=True)
def _pair_by_beat(gain, beat):
    """`_assigned`'s pairing: for onsets sorted by ``beat``, their (K, J) gains, the best
    one-to-one pairing of each beat's onsets with impacts (a dynamic programme over the
    set of impacts used), −1 for an onset paired with none."""
    k, impacts = gain.shape
    masks = 1 << impacts
    label = np.full(k, -1, dtype=np.int64)
    start = 0
    while start < k:
        stop = start
        while stop < k and beat[stop] == beat[start]:
            stop += 1
        m = stop - start
        score = np.full(masks, -np.inf)
        score[0] = 0.0
        choice = np.full((m, masks), -1, dtype=np.int64)
        for i in range(m):
            new = score.copy()  # the onset is clutter
            for used in range(masks):
                if score[used] == -np.inf:
                    continue
                for j in range(impacts):
                    bit = 1 << j
                    g = gain[start + i, j]
                    if used & bit or g <= 0.0:
                        continue
                    if score[used] + g > new[used | bit]:
                        new[used | bit] = score[used] + g
                        choice[i, used | bit] = j
            score = new
        used = int(np.argmax(score))
        for i in range(m - 1, -1, -1):
            j = choice[i, used]
            if j >= 0:
                label[start + i] = j
                used ^= 1 << j
        start = stop
    return label

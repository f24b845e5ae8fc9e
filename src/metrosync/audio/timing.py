"""A metronome's timing model: where its k-th beat falls, and how well it keeps it.

The model (docs/sound.md, "The timing model"). A metronome ticks twice a swing; its
beats alternate in length, (1 + λ/2)·T then (1 − λ/2)·T (the limp λ), its period
lengthens or shortens slowly as the spring unwinds (the drift), and the escapement
places each tick with a small independent error (the jitter s). Beat k then falls at

    t_k = φ + k·T + (λ·T/2)·[k odd] + ½·Ṫ·k² + ε_k,    ε_k ~ N(0, s²)

with φ the time of beat 0, T the mean beat (s), Ṫ the change of the beat per beat
(dimensionless: seconds of period gained per beat) and [k odd] 1 for odd beats. The
model is linear in (φ, T, λT/2, Ṫ/2), so it is fitted to the heard ticks by weighted
least squares; the weights are each tick's probability of being this metronome's
(an assignment's posterior), and a tick far off its predicted time is down-weighted
by the Student-t likelihood (iteratively reweighted least squares, `MODEL.jitter_dof` degrees of
freedom), so that one mistimed tick cannot bend the model.

This is the pulsar-timing picture (PINT, tempo2): times of arrival, a timing model of
phase, frequency and its derivative fitted to them, and residuals that say how well it
explains them; a metronome is a pulsar with a limp.

Contract: `fit_timing(times, beats, weights=None)` returns a `Timing`, whose
`predict(beats)` gives the model's times and `residuals(times, beats)` the misfit;
`number_beats(times, period)` gives beat numbers to ticks of one metronome from their
intervals, missing beats included. All times are in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import AnalysisError
from .settings import MODEL
from .wander import Wander, smooth_wander

#: Passes of iteratively reweighted least squares (the weights settle in a few).
PASSES = 8
#: Smoothings of the wander, each followed by a refit of the model to the ticks less it.
WANDER_PASSES = 3
#: Fewest ticks that determine the four parameters with a jitter to spare.
MIN_TICKS = 6


@dataclass(frozen=True)
class Timing:
    """One metronome's fitted timing model (see the module docstring).

    phase : φ, the time of beat 0, s.
    period : T, s: the beat from beat 0 to beat 1 is T + Ṫ/2 (T itself without drift).
    limp : λ, (long beat − short beat) / mean beat; positive when the beat from an even
        to an odd beat number is the long one.
    drift : Ṫ, the change of the beat per beat (s/s); the tempo changes by
        −60·Ṫ/T² BPM per beat.
    jitter : s, the standard deviation of a tick about the model, s, estimated robustly
        (1.4826 times the median absolute residual of the ticks more likely this
        metronome's than not), so that a few mistimed ticks do not inflate it.
    errors : (4,) standard errors of (φ, T, λ, Ṫ).
    ticks : the number of ticks the fit used (weight > 0).
    wander : the beat's smooth wander about the model (`wander.Wander`), or None: what
        coupled metronomes pulling each other's phase add to it; `predict` includes it.
    """

    phase: float
    period: float
    limp: float
    drift: float
    jitter: float
    errors: tuple[float, float, float, float]
    ticks: int
    wander: Wander | None = None

    @property
    def bpm(self) -> float:
        """The tempo at beat 0 (drift aside), ticks per minute."""
        return 60.0 / self.period

    def mean_bpm(self, first: int, last: int) -> float:
        """The mean tempo from beat ``first`` to beat ``last``, ticks per minute: beats
        counted over the time the model puts between them (the drift included)."""
        span = float(self.predict(last) - self.predict(first))
        return 60.0 * (last - first) / span

    def period_at(self, beats) -> np.ndarray:
        """The mean beat around beat number ``beats``, s (the drift included)."""
        return self.period + self.drift * (np.asarray(beats, dtype=float) + 0.5)

    def predict(self, beats) -> np.ndarray:
        """The model's time of each beat number in ``beats`` (any shape), s."""
        k = np.asarray(beats, dtype=float)
        odd = np.mod(k, 2.0)
        limp = 0.5 * self.limp * self.period * odd
        model = self.phase + k * self.period + limp + 0.5 * self.drift * k**2
        return model if self.wander is None else model + self.wander.at(k)

    def doubled(self) -> Timing:
        """The timing at twice the tempo whose even beat 2k is this one's beat k (the
        limp at twice the tempo unknown, taken as none): where a metronome was followed
        at half its tempo, its other beats fall between."""
        wander = self.wander
        if wander is not None:
            wander = Wander(2 * wander.beats, wander.offset, wander.rate / 2, wander.q / 2**1.5)
        half = self.period / 2
        # the drift per beat of half the length is a quarter: ½(Ṫ/4)(2k)² = ½Ṫk²
        return Timing(self.phase, half, 0.0, self.drift / 4, self.jitter,
                      (self.errors[0], self.errors[1] / 2, 0.0, self.errors[3] / 4),
                      self.ticks, wander)  # fmt: skip

    def residuals(self, times, beats) -> np.ndarray:
        """Heard minus predicted time of each tick, s."""
        return np.asarray(times, dtype=float) - self.predict(beats)


def _design(beats: np.ndarray, drift: bool) -> np.ndarray:
    """(K, 4) columns of t_k's linear parameters (φ, T, λT/2, Ṫ/2); (K, 3) without drift."""
    k = beats.astype(float)
    columns = [np.ones_like(k), k, np.mod(k, 2.0)] + ([k**2] if drift else [])
    return np.column_stack(columns)


def fit_timing(times, beats, weights=None, *, drift: bool = True, wander: bool = False) -> Timing:
    """The `Timing` that best explains ``times`` at beat numbers ``beats``.

    times : (K,) tick times, s.
    beats : (K,) integer beat numbers (gaps for missed beats; any offset).
    weights : (K,) probabilities that each tick is this metronome's (default 1).
    drift : fit Ṫ; without it Ṫ = 0 (a short recording cannot tell drift from jitter).
    wander : also smooth the beat's wander about the model (`wander.smooth_wander`),
        kept where the residuals ask for it; the model is then refitted to the ticks
        less their wander, and the jitter is the ticks' spread about both.

    Raises `AnalysisError` with fewer than `MIN_TICKS` ticks of positive weight, or
    beat numbers that leave the limp or the drift undetermined (all even, say).
    """
    t = np.asarray(times, dtype=float)
    k = np.asarray(beats)
    if t.shape != k.shape or t.ndim != 1:
        raise ValueError(f"times {t.shape} and beats {k.shape} must be one equal shape")
    w = np.ones_like(t) if weights is None else np.asarray(weights, dtype=float)
    keep = w > 0
    if keep.sum() < MIN_TICKS:
        raise AnalysisError(
            f"a timing model needs at least {MIN_TICKS} ticks, got {int(keep.sum())}"
        )
    t, k, w = t[keep], k[keep], w[keep]
    x = _design(k, drift)
    norm = np.linalg.norm(x, axis=0)  # columns of like size: k² reaches 10⁶ and more
    if np.any(norm == 0) or np.linalg.matrix_rank(x / norm) < x.shape[1]:
        raise AnalysisError("the beat numbers leave the limp or the drift undetermined")
    robust = np.ones_like(t)
    coef, r, scale = _reweighted(x, norm, t, w, robust)
    wandering = None
    if wander:
        order = np.argsort(k, kind="stable")
        for _ in range(WANDER_PASSES):
            about_model = (t - x @ coef)[order]  # the wander is what the model leaves
            wandering = smooth_wander(k[order], about_model, (w * robust)[order], _jitter(r, w))
            if wandering is None:
                break
            g = wandering.at(k)
            coef, r, scale = _reweighted(x, norm, t - g, w, robust)
    err = np.sqrt(np.maximum(np.diag(_covariance(x / norm, w, r, scale)), 0.0)) / norm
    if not drift:
        coef, err = np.append(coef, 0.0), np.append(err, 0.0)
    phase, period, half_limp, half_drift = coef
    jitter = _jitter(r, w)
    return Timing(
        phase=float(phase),
        period=float(period),
        limp=float(2.0 * half_limp / period),
        drift=float(2.0 * half_drift),
        jitter=jitter,
        errors=(float(err[0]), float(err[1]), float(2.0 * err[2] / period), float(2.0 * err[3])),
        ticks=int(t.size),
        wander=wandering,
    )


def _reweighted(x, norm, t, w, robust):
    """Iteratively reweighted least squares of ``t`` on ``x`` (columns scaled by
    ``norm``) under the Student-t likelihood: (coefficients, residuals, scale), the
    robust weights updated in ``robust`` in place."""
    scale = 0.0
    for _ in range(PASSES):
        sw = np.sqrt(w * robust)
        scaled, *_ = np.linalg.lstsq((x / norm) * sw[:, None], t * sw, rcond=None)
        coef = scaled / norm
        r = t - x @ coef
        scale = _t_scale(r, w, robust)
        if scale == 0:
            break
        dof = MODEL.jitter_dof
        robust[:] = (dof + 1.0) / (dof + (r / scale) ** 2)
    return coef, r, scale


def _jitter(r: np.ndarray, w: np.ndarray) -> float:
    """1.4826 times the median absolute residual of the ticks more likely this
    metronome's than not (of all, if none is), s."""
    mine = w >= 0.5
    return 1.4826 * float(np.median(np.abs(r[mine] if mine.any() else r)))


def _t_scale(r: np.ndarray, w: np.ndarray, robust: np.ndarray) -> float:
    """The Student-t scale that the reweighted residuals imply (its EM update)."""
    total = float(w.sum())
    return math.sqrt(float(np.sum(w * robust * r**2)) / total) if total > 0 else 0.0


def _covariance(x: np.ndarray, w: np.ndarray, r: np.ndarray, scale: float) -> np.ndarray:
    """The parameters' covariance, by the M-estimator's sandwich A⁻¹ B A⁻¹ with
    A = Xᵀ diag(w ψ′) X and B = Xᵀ diag(w² ψ²) X, ψ(r) = r (ν + 1)/(ν + r²/σ²) the
    Student-t score: right whatever the residuals' distribution (Huber 1967)."""
    if scale == 0:
        return np.zeros((x.shape[1], x.shape[1]))
    z2 = (r / scale) ** 2
    dof = MODEL.jitter_dof
    psi = r * (dof + 1.0) / (dof + z2)
    slope = np.maximum((dof + 1.0) * (dof - z2) / (dof + z2) ** 2, 0.0)
    bread = np.linalg.pinv(x.T @ (x * (w * slope)[:, None]))
    meat = x.T @ (x * (w**2 * psi**2)[:, None])
    return bread @ meat @ bread


def number_beats(times, period: float) -> np.ndarray:
    """(K,) beat numbers of one metronome's sorted tick ``times``, from beat 0.

    Each interval counts round(interval / T) beats, T the current beat: the median of
    the last few single-beat intervals, so that a drifting tempo is followed and a missed
    beat (an interval near 2T) counts two.
    """
    t = np.asarray(times, dtype=float)
    beats = np.zeros(t.size, dtype=np.int64)
    recent = [float(period)] * 3
    for i in range(1, t.size):
        beat = float(np.median(recent[-5:]))
        gap = t[i] - t[i - 1]
        steps = max(1, round(gap / beat))
        beats[i] = beats[i - 1] + steps
        if steps == 1:
            recent.append(gap)
    return beats

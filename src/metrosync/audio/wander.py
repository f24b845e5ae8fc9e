"""How a metronome's beat wanders about its timing model, by a Kalman smoother.

Coupled metronomes falling into step pull each other's phase and tempo for tens of
seconds: their ticks leave a fitted phase, tempo and drift (`timing.Timing`) by up to
tens of milliseconds, far more than the escapement's jitter. The wander g_k (s) at
beat k is modelled as an integrated random walk, the usual state-space model of a
smooth trend (Durbin & Koopman, "Time Series Analysis by State Space Methods", 2012,
§3.2.1): the state (g, ġ) moves from beat to beat as

    g_{k+1} = g_k + ġ_k,    ġ_{k+1} = ġ_k + η_k,    η_k ~ N(0, q²)

(q in seconds per beat: how fast the beat itself may change), and a tick's residual
from the timing model is g_k plus its jitter, N(0, s²/w) for a tick of weight w.
Missed beats are gaps of several beats in one step. The Kalman filter gives the
likelihood of the residuals for each q (from its innovations, the first two, which
fix the diffuse start, left out); q is the maximum-likelihood one of a grid
(`Q_GRID`, relative to the jitter), and no wander at all (q = 0) unless the best q
improves the log-likelihood by more than the Bayesian information criterion's
½·log K for its one parameter. The Rauch–Tung–Striebel smoother then gives g at every
tick from all of them.

Contract: `smooth_wander(beats, residuals, weights, jitter)` returns a `Wander` (or
None when q = 0 wins); `Wander.at(beats)` is g at any beat number, continued past the
ends at the smoothed rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

#: Process noise tried, as multiples of the jitter per beat: from a beat that changes
#: by a thousandth of a jitter a beat (hardly any wander) to one that changes by a whole
#: jitter a beat (the wander as rough as the ticks themselves).
Q_GRID = np.geomspace(1e-3, 1.0, 13)
#: Finest jitter the filter is run with, s: below a detector's timing resolution (ticks
#: of constructed, perfectly regular times), where the covariances would underflow.
MIN_JITTER = 1e-5
#: Fewest ticks on which a wander is fitted: a few dozen beats tell a wander from jitter.
MIN_TICKS = 24


@dataclass(frozen=True)
class Wander:
    """The smoothed wander at the ticks' beat numbers ``beats`` (sorted): ``offset`` g
    (s), ``rate`` ġ (s per beat); ``q`` the process noise chosen (s per beat)."""

    beats: np.ndarray
    offset: np.ndarray
    rate: np.ndarray
    q: float

    def at(self, beats) -> np.ndarray:
        """g at beat numbers ``beats`` (any shape), s: interpolated between the ticks,
        continued at the end's rate beyond them."""
        k = np.asarray(beats, dtype=float)
        g = np.interp(k, self.beats, self.offset)
        before, after = k < self.beats[0], k > self.beats[-1]
        g = np.where(before, self.offset[0] + self.rate[0] * (k - self.beats[0]), g)
        return np.where(after, self.offset[-1] + self.rate[-1] * (k - self.beats[-1]), g)

    def spread_after(self, beats: float) -> float:
        """The standard deviation the random walk adds ``beats`` past the last tick, s."""
        return self.q * math.sqrt(max(beats, 0.0) ** 3 / 3.0)


def smooth_wander(beats, residuals, weights, jitter: float) -> Wander | None:
    """The `Wander` of residuals (s) at integer beat numbers ``beats`` (sorted, no
    repeats), each a tick of weight ``weights`` with jitter ``jitter`` (s); None when
    the data ask for none (see the module docstring)."""
    k = np.asarray(beats, dtype=float)
    r = np.asarray(residuals, dtype=float)
    w = np.asarray(weights, dtype=float)
    keep = w > 0
    k, r, w = k[keep], r[keep], w[keep]
    if k.size < MIN_TICKS or not jitter > 0 or np.any(np.diff(k) <= 0):
        return None
    jitter = max(jitter, MIN_JITTER)
    noise = jitter**2 / w
    qs = np.concatenate(([0.0], Q_GRID * jitter))
    loglik = np.array([_filter(k, r, noise, q, None) for q in qs])
    best = int(np.argmax(loglik))
    if best == 0 or 2.0 * (loglik[best] - loglik[0]) <= math.log(k.size):
        return None
    states = np.empty((k.size, 2))
    _filter(k, r, noise, qs[best], states)
    return Wander(k, states[:, 0].copy(), states[:, 1].copy(), float(qs[best]))


def _filter(k, r, noise, q, out):
    # a diffuse start: a state's prior spread far beyond anything the residuals hold
    start = 1e6 * (float(np.max(np.abs(r))) + math.sqrt(float(np.max(noise)))) ** 2 + 1.0
    return _kalman(k, r, noise, float(q), start, np.empty((0, 2)) if out is None else out)


@nb.njit(cache=True)
def _kalman(k, r, noise, q, start, out):
    """Log-likelihood of residuals ``r`` under the integrated random walk of process
    noise ``q`` from (g, ġ) ~ N(0, start·I); with ``out`` (K, 2) given, the smoothed
    (g, ġ) written into it."""
    n = k.size
    smooth = out.shape[0] == n
    # filtered and predicted means and covariances, kept for the smoother
    fm = np.empty((n, 2))
    fp = np.empty((n, 2, 2))
    pm = np.empty((n, 2))
    pp = np.empty((n, 2, 2))
    m0, m1 = 0.0, 0.0
    p00, p01, p11 = start, 0.0, start
    loglik = 0.0
    for i in range(n):
        if i > 0:
            d = k[i] - k[i - 1]
            # predict: F = [[1, d], [0, 1]], Q = q²[[d³/3, d²/2], [d²/2, d]]
            m0 = m0 + d * m1
            a00 = p00 + 2.0 * d * p01 + d * d * p11 + q * q * d**3 / 3.0
            a01 = p01 + d * p11 + q * q * d * d / 2.0
            a11 = p11 + q * q * d
            p00, p01, p11 = a00, a01, a11
        pm[i, 0], pm[i, 1] = m0, m1
        pp[i, 0, 0], pp[i, 0, 1], pp[i, 1, 0], pp[i, 1, 1] = p00, p01, p01, p11
        s = p00 + noise[i]
        v = r[i] - m0
        if i >= 2:  # the first two fix the diffuse start
            loglik -= 0.5 * (math.log(2.0 * math.pi * s) + v * v / s)
        g0, g1 = p00 / s, p01 / s
        m0, m1 = m0 + g0 * v, m1 + g1 * v
        p00, p01, p11 = p00 - g0 * p00, p01 - g0 * p01, p11 - g1 * p01
        fm[i, 0], fm[i, 1] = m0, m1
        fp[i, 0, 0], fp[i, 0, 1], fp[i, 1, 0], fp[i, 1, 1] = p00, p01, p01, p11
    if smooth:
        s0, s1 = fm[n - 1, 0], fm[n - 1, 1]
        out[n - 1, 0], out[n - 1, 1] = s0, s1
        for i in range(n - 2, -1, -1):
            d = k[i + 1] - k[i]
            # gain C = P_f Fᵀ P_pred⁻¹ (2 × 2)
            f00, f01, f11 = fp[i, 0, 0], fp[i, 0, 1], fp[i, 1, 1]
            c00, c01 = f00 + d * f01, f01
            c10, c11 = f01 + d * f11, f11
            q00, q01, q11 = pp[i + 1, 0, 0], pp[i + 1, 0, 1], pp[i + 1, 1, 1]
            det = q00 * q11 - q01 * q01
            i00, i01, i11 = q11 / det, -q01 / det, q00 / det
            # C = [[c00, c01], [c10, c11]] · P_pred⁻¹, with P_f Fᵀ = [[c00, c01], [c10, c11]]
            g00 = c00 * i00 + c01 * i01
            g01 = c00 * i01 + c01 * i11
            g10 = c10 * i00 + c11 * i01
            g11 = c10 * i01 + c11 * i11
            e0, e1 = s0 - pm[i + 1, 0], s1 - pm[i + 1, 1]
            s0 = fm[i, 0] + g00 * e0 + g01 * e1
            s1 = fm[i, 1] + g10 * e0 + g11 * e1
            out[i, 0], out[i, 1] = s0, s1
    return loglik

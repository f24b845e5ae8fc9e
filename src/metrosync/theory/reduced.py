"""The reduced model: N Kuramoto–Sakaguchi phase oscillators, O(N) per step.

    dφ_i/dt = ω_i + (K/N) Σ_j sin(φ_j − φ_i − α) = ω_i + Im(K e^{−iα} z e^{−iφ_i}),

with z = (1/N) Σ_j e^{iφ_j} = r e^{iψ}. The all-to-all sum is the mean field, so a step
costs O(N). Each run is simulated in the frame turning at its mean natural frequency
(r does not depend on the frame), where the motion is slow: steps of a tenth of a
second or more are accurate.

Scheme: each oscillator is kept as the unit complex number e^{iφ_i} and advanced by an
explicit midpoint step, e^{iφ} ← e^{iφ} · e^{i dt f(φ_½, z_½)} with the half step taken
the same way; the mean field at the half step is extrapolated from the last two steps,
z_½ = (3 z_n − z_{n−1}) / 2, so one pass over the oscillators both advances them and
sums the next z. The scheme is second order (a test measures the slope); the small
rotations use a 7th-order Taylor series, and a Newton step renormalises |e^{iφ}| to 1.

Contract: `simulate_reduced` returns an `xarray.Dataset` shaped like `simulate`'s:
``r (time, run)``, ``r_eq (run)`` (mean of r over the final window) and the inputs in
``attrs``. Frequencies and K are in rad/s, α in rad, times in s.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from numba import njit, prange

from .._version import __version__
from ..errors import ParameterError, describe
from ..integrators._cache import compile_kernel
from ..observables.order import ensemble_statistics
from ..progress import progress_bar

#: Largest phase increment allowed per step, rad (the Taylor rotation's accuracy).
MAX_STEP_ANGLE = 0.5
#: Oscillator-steps per chunk between progress updates.
CHUNK_WORK = 20_000_000
#: From this many oscillators per run, runs are simulated one after the other (each
#: alone fills the caches) instead of side by side on numba's threads.
LARGE_N = 4096


_OPTIONS = {"cache": True, "fastmath": True, "error_model": "numpy"}


@njit(inline="always", **_OPTIONS)
def _rotate(xr_, xi_, d):
    """(xr + i xi) · e^{id} for a small angle d, by the Taylor series to 7th order."""
    d2 = d * d
    c = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 / 720.0))
    s = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 / 5040.0)))
    return xr_ * c - xi_ * s, xr_ * s + xi_ * c


@njit(inline="always", **_OPTIONS)
def _midpoint(xr_, xi_, om, ar, ai, br, bi, dt):
    """One oscillator's midpoint step; ar + i ai, br + i bi are K e^{−iα} z at the
    step's start and (extrapolated) middle."""
    hr, hi = _rotate(xr_, xi_, 0.5 * dt * (om + ai * xr_ - ar * xi_))
    yr, yi = _rotate(xr_, xi_, dt * (om + bi * hr - br * hi))
    # One Newton step towards 1/|y|: |y|² = 1 + ε with ε tiny, so this leaves
    # |y| = 1 + O(ε²) without a square root or a division (several times faster).
    g = 1.5 - 0.5 * (yr * yr + yi * yi)
    return yr * g, yi * g


# Two copies of the sweep over a run's oscillators: numba vectorises a plain `range`
# loop but not a `prange` loop compiled without threads (4-5× slower).
@njit(**_OPTIONS)
def _sweep_serial(cr, ci, om, ar, ai, br, bi, dt):
    """Advance every oscillator of a run in place; returns the sum of the new e^{iφ}."""
    sr = 0.0
    si = 0.0
    for i in range(cr.size):
        cr[i], ci[i] = _midpoint(cr[i], ci[i], om[i], ar, ai, br, bi, dt)
        sr += cr[i]
        si += ci[i]
    return sr, si


@njit(parallel=True, **_OPTIONS)
def _sweep_threads(cr, ci, om, ar, ai, br, bi, dt):
    """`_sweep_serial` split over threads."""
    sr = 0.0
    si = 0.0
    for i in prange(cr.size):
        yr, yi = _midpoint(cr[i], ci[i], om[i], ar, ai, br, bi, dt)
        cr[i] = yr
        ci[i] = yi
        sr += yr
        si += yi
    return sr, si


@njit(**_OPTIONS)
def _fields(z, q_re, q_im):
    """K e^{−iα} z at t_n and at t_n + dt/2, z_½ = (3 z_n − z_{n−1})/2."""
    zr, zi, pr, pi_ = z[0], z[1], z[2], z[3]
    hzr, hzi = 1.5 * zr - 0.5 * pr, 1.5 * zi - 0.5 * pi_
    return (
        q_re * zr - q_im * zi,
        q_re * zi + q_im * zr,
        q_re * hzr - q_im * hzi,
        q_re * hzi + q_im * hzr,
    )


@njit(**_OPTIONS)
def _advance_serial(cr, ci, om, q_re, q_im, z, dt, n_steps, record_every, rec, rec0):
    """Advance one run ``n_steps`` steps; rec[rec0 + k] gets r at the k-th record.

    z : (4,) mean field now and one step ago (re, im, re_prev, im_prev), updated.
    """
    for s in range(n_steps):
        ar, ai, br, bi = _fields(z, q_re, q_im)
        sr, si = _sweep_serial(cr, ci, om, ar, ai, br, bi, dt)
        z[2], z[3], z[0], z[1] = z[0], z[1], sr / cr.size, si / cr.size
        if (s + 1) % record_every == 0:
            rec[rec0 + (s + 1) // record_every] = math.sqrt(z[0] ** 2 + z[1] ** 2)


@njit(**_OPTIONS)
def _advance_threads(cr, ci, om, q_re, q_im, z, dt, n_steps, record_every, rec, rec0):
    """`_advance_serial` with each step's sweep split over threads (large N)."""
    for s in range(n_steps):
        ar, ai, br, bi = _fields(z, q_re, q_im)
        sr, si = _sweep_threads(cr, ci, om, ar, ai, br, bi, dt)
        z[2], z[3], z[0], z[1] = z[0], z[1], sr / cr.size, si / cr.size
        if (s + 1) % record_every == 0:
            rec[rec0 + (s + 1) // record_every] = math.sqrt(z[0] ** 2 + z[1] ** 2)


@njit(parallel=True, **_OPTIONS)
def _advance_runs(cr, ci, om, q_re, q_im, z, dt, n_steps, record_every, rec, rec0):
    for b in prange(cr.shape[0]):
        _advance_serial(
            cr[b], ci[b], om[b], q_re, q_im, z[b], dt, n_steps, record_every, rec[b], rec0
        )


def _per_oscillator(name: str, value, runs: int, n: int | None) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 1:
        arr = np.broadcast_to(arr, (runs, arr.size))
    if arr.ndim != 2 or arr.shape[0] != runs or (n is not None and arr.shape[1] != n):
        want = f"({n},) or ({runs}, {n})" if n is not None else f"(N,) or ({runs}, N)"
        raise ParameterError(
            f"`{name}` must have shape {want}, got shape {np.shape(value)}: {describe(value)}."
        )
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite numbers, got {describe(value)}.")
    return np.array(arr)


def simulate_reduced(
    n: int | None = None,
    *,
    k: float,
    alpha: float = 0.0,
    sigma: float | None = None,
    omega=None,
    phases0=None,
    runs: int = 1,
    duration: float = 600.0,
    dt: float = 0.1,
    seed: int | None = 0,
    record_every: int | None = None,
    equilibrium_window: float | None = None,
    threads: bool = False,
    progress: bool | None = None,
) -> xr.Dataset:
    """Simulate ``runs`` independent Kuramoto–Sakaguchi populations of ``n`` oscillators.

    Parameters
    ----------
    n : oscillators per run (taken from ``omega`` when that is given).
    k, alpha : coupling K (rad/s) and phase lag α (rad).
    sigma : standard deviation (rad/s) of the Gaussian natural frequencies, drawn per
        run; or give ``omega``.
    omega : explicit natural frequencies, rad/s, shape (N,) or (runs, N).
    phases0 : initial phases, rad, (N,) or (runs, N); default uniformly random.
    runs, duration, dt : independent runs, simulated time and step, s.
    seed : seed of the random frequencies and phases.
    record_every : steps between records of r; default the steps of 1 s.
    equilibrium_window : final window (s) averaged for r_eq; default a quarter.
    threads : for large N, split each step over numba's threads. That pays on an idle
        multi-core machine; on a busy one the per-step synchronisation makes it slower
        (see ``benchmarks/reduced.py``).
    progress : show a progress bar; default when stderr is a terminal.
    """
    import sys

    if isinstance(runs, bool) or not isinstance(runs, int | np.integer) or runs < 1:
        raise ParameterError(f"`runs` must be an integer >= 1, got {describe(runs)}.")
    for name, value in (("k", k), ("alpha", alpha)):
        if not math.isfinite(float(value)):
            raise ParameterError(f"`{name}` must be a finite number, got {value!r}.")
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"`duration` must be a finite time > 0 s, got {duration!r}.")
    if not (math.isfinite(dt) and 0 < dt <= duration):
        raise ParameterError(f"`dt` must be a step in (0, duration] s, got {dt!r}.")
    rng_freq, rng_phase = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(2))
    if omega is not None:
        om = _per_oscillator("omega", omega, runs, n)
        n = om.shape[1]
    else:
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ParameterError(f"`n` must be an integer >= 1 oscillator, got {describe(n)}.")
        if sigma is None or not (math.isfinite(sigma) and sigma >= 0):
            raise ParameterError(
                f"`sigma` must be a spread >= 0 rad/s of the natural frequencies (or give "
                f"`omega`), got {sigma!r}."
            )
        om = rng_freq.normal(0.0, float(sigma), size=(runs, n))
    om = om - om.mean(axis=1, keepdims=True)
    if phases0 is None:
        phases = rng_phase.uniform(0.0, 2 * np.pi, size=(runs, n))
    else:
        phases = _per_oscillator("phases0", phases0, runs, n)
    fastest = float(np.max(np.abs(om))) + abs(float(k))
    if fastest * dt > MAX_STEP_ANGLE:
        raise ParameterError(
            f"`dt` = {dt!r} s lets a phase move {fastest * dt:.2f} rad in one step (largest "
            f"|ω − mean| + |K| = {fastest:.3g} rad/s); the limit is {MAX_STEP_ANGLE} rad. Use "
            f"dt <= {MAX_STEP_ANGLE / fastest:.3g} s."
        )
    n_steps = int(round(duration / dt))
    if record_every is None:
        record_every = max(1, int(round(1.0 / dt)))
    if (
        isinstance(record_every, bool)
        or not isinstance(record_every, int | np.integer)
        or not (1 <= record_every <= n_steps)
    ):
        raise ParameterError(
            f"`record_every` must be an integer in [1, {n_steps}] steps, got "
            f"{describe(record_every)}."
        )
    window = duration / 4 if equilibrium_window is None else float(equilibrium_window)
    if not (0 < window <= duration):
        raise ParameterError(
            f"`equilibrium_window` must be in (0, duration], got {equilibrium_window!r}."
        )

    cr, ci = np.cos(phases), np.sin(phases)
    z = np.empty((runs, 4))
    z[:, 0], z[:, 1] = cr.mean(axis=1), ci.mean(axis=1)
    z[:, 2:] = z[:, :2]  # the first half step extrapolates nothing
    n_records = n_steps // record_every + 1
    rec = np.full((runs, n_records), np.nan)
    rec[:, 0] = np.hypot(z[:, 0], z[:, 1])
    q = complex(k) * complex(math.cos(alpha), -math.sin(alpha))
    per_chunk = max(1, CHUNK_WORK // (runs * n))
    per_chunk = max(record_every, per_chunk // record_every * record_every)
    show = sys.stderr.isatty() if progress is None else progress
    with progress_bar(total=round(n_steps * dt, 6), unit="s", enabled=show) as bar:
        step = 0
        while step < n_steps:
            count = min(per_chunk, n_steps - step)
            args = (q.real, q.imag)
            if n >= LARGE_N:
                advance = _advance_threads if threads else _advance_serial
                for b in range(runs):
                    call = (cr[b], ci[b], om[b], *args, z[b], dt, count, record_every, rec[b],
                            step // record_every)  # fmt: skip
                    compile_kernel(advance, *call)
                    advance(*call)
            else:
                call = (cr, ci, om, *args, z, dt, count, record_every, rec, step // record_every)
                compile_kernel(_advance_runs, *call)
                _advance_runs(*call)
            step += count
            bar.update(round(count * dt, 6))

    time = np.arange(n_records) * record_every * dt
    r_eq = np.nanmean(np.where(time >= time[-1] - window + 1e-9, rec, np.nan), axis=1)
    mean, spread = ensemble_statistics(r_eq)
    attrs = {
        "model": "kuramoto-sakaguchi",
        "n": n,
        "runs": runs,
        "k": float(k),
        "alpha": float(alpha),
        "sigma": "explicit" if omega is not None else float(sigma),
        "duration": n_steps * dt,
        "dt": dt,
        "seed": "none" if seed is None else seed,
        "record_every": record_every,
        "equilibrium_window": window,
        "r_eq_mean": mean,
        "r_eq_std": spread,
        "metrosync_version": __version__,
    }
    return xr.Dataset(
        {
            "r": (("time", "run"), rec.T, {"long_name": "Kuramoto order parameter"}),
            "r_eq": (("run",), r_eq, {"long_name": "equilibrium r (mean over final window)"}),
        },
        coords={"time": ("time", time, {"units": "s"}), "run": np.arange(runs)},
        attrs=attrs,
    )

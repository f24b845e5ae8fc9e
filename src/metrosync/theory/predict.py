"""The reduced theory's prediction of the critical frequency ω_c, for a preset.

`coupling_curve` measures K(ω₀) e^{−iα(ω₀)} on a grid of nominal BPM (method
"growth" at N = 32 by default, `coupling`), rescales it to the N asked for (N → ∞ by
default) and sets the analytic estimate beside it; measurements are cached on disk,
one file per point, keyed by everything they depend on. `predict_onset` then solves

    K(ω₀, N) = K_c(α(ω₀), σ_ω(ω₀))                       (`sakaguchi.onset`)

for ω₀, where σ_ω is the spread of the metronomes' *tick* frequencies. The
ensembles draw σ on the nominal BPM; with today's small-amplitude tuning a metronome
ticks at ρ ≈ 0.96 of its nominal rate, so σ_ω = (π/60) σ d(tick)/d(nominal); with the
steady-swing tuning the factor is 1. Its error comes from K ± its uncertainty. Below
ω_c the incoherent state is stable for N → ∞ (r → 0); above it r grows.

Contract: `reduced_theory(...)` returns one `xarray.Dataset` with ``k``, ``alpha``, ``k_cos``,
``k_sin`` (and ``*_err``, ``*_estimate``) on ``bpm``, ``omega_c`` (and ``omega_c_err``)
on ``sigma``; `plot_theory` draws it.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

from .._files import write_text
from .._version import __version__
from ..budget import Budget
from ..errors import ParameterError
from ..model import ModelParameters, get_preset
from ..model.steady_swing import steady_swing
from ..model.tuning import l2_for_bpm, with_tuning
from ..progress import progress_bar
from . import coupling as cp
from .estimate import estimate
from .reduced import simulate_reduced
from .sakaguchi import critical_coupling

#: Bumped when a measurement method changes, so that old cache files are not reused.
CACHE_VERSION = 1


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/metrosync/theory`` (``~/.cache/metrosync/theory``)."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "metrosync" / "theory"


#: CPU seconds of one measurement of K, per BPM: "growth" at N = 32 (it grows with N),
#: "pair" (measured 0.68 s and 5.7 s on the 2-core x86-64 development machine).
MEASURE_SECONDS = {"growth": 0.9, "pair": 7.0}
#: CPU seconds of the reduced model per oscillator, BPM and σ (20 000 oscillators:
#: measured 0.023 s), and of bisecting r = 1/2 per σ (measured 0.11 s).
REDUCED_OSC_SECONDS, HALF_SECONDS = 1.5e-6, 0.15


def theory_budget(
    bpms: Sequence[float],
    *,
    sigmas: int = 0,
    method: str = "growth",
    measure_n: int = 32,
    params: ModelParameters,
    cache: Path | None = None,
    reduced: int = 0,
) -> Budget:
    """The time `reduced_theory` (``sigmas`` > 0) or `coupling_curve` will take.

    bpms : the nominal BPM measured; those already in ``cache`` cost nothing.
    sigmas : spreads for which the reduced model runs.   reduced : its oscillators per
        BPM and σ (runs × size; 0: not run).
    """
    todo = sum(
        not _cache_path(b, method, params, measure_n, cache)[0].is_file() if cache else True
        for b in bpms
    )
    scale = measure_n / 32 if method == "growth" else 1.0
    seconds = todo * MEASURE_SECONDS.get(method, 0.0) * scale  # a bad method: refused next
    work = f"{todo} measurements of K by {method!r}"
    if reduced and sigmas:
        seconds += sigmas * (len(bpms) * reduced * REDUCED_OSC_SECONDS + HALF_SECONDS)
        work += f", the reduced model at {len(bpms)} BPM x {sigmas} sigma"
    return Budget(
        "theory",
        seconds=seconds,
        work=work,
        fixes="measure fewer BPM (a coarser `bpms` grid)"
        + (", or skip the reduced model (`simulate_n`)" if reduced and sigmas else ""),
    )


def _cache_path(bpm, method, params, measure_n, cache: Path | None):
    """The cache entry of a measurement, and the settings it is keyed by.

    The key holds every parameter of ``params``, the design's ``tuning`` among them.
    """
    settings = {
        "version": CACHE_VERSION,
        "bpm": float(bpm),
        "method": method,
        "tuning": params.metronome.tuning,
        "n": measure_n if method == "growth" else 2,
        "dt": cp.MEASURE_DT,
        "params": {k: str(v) for k, v in params.as_dict().items() if k != "preset"},
    }
    key = hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:20]
    return (None if cache is None else Path(cache) / f"{method}-{bpm:g}-{key}.json"), settings


def _measure_cached(bpm, method, params, measure_n, cache: Path | None) -> cp.Coupling:
    """The coupling at ``bpm``, from the cache when an entry has the same key."""
    path, settings = _cache_path(bpm, method, params, measure_n, cache)
    if path is not None and path.is_file():
        try:
            return cp.Coupling(**json.loads(path.read_text())["coupling"])
        except (ValueError, KeyError, TypeError):
            pass  # a damaged entry is measured again and overwritten
    if method == "growth":
        result = cp.measure_by_growth(bpm, n=measure_n, params=params)
    else:
        result = cp.measure_by_pair(bpm, params=params)
    if path is not None:
        write_text(json.dumps({"settings": settings, "coupling": vars(result)}, indent=1), path)
    return result


def coupling_curve(
    bpms: Sequence[float],
    *,
    n: int | float = math.inf,
    params: ModelParameters | str = "default",
    tuning: str | None = None,
    method: str = "growth",
    measure_n: int = 32,
    cache: Path | None = None,
    progress: bool = False,
    budget: Budget | None = None,
) -> xr.Dataset:
    """K(ω₀, N), α(ω₀) measured at each nominal BPM, with the analytic estimate beside it.

    bpms : nominal beat frequencies, BPM (at least 2, increasing).
    n : metronomes the coupling is expressed for (``math.inf``: the N → ∞ limit).
    method : ``"growth"`` or ``"pair"`` (`coupling`).   measure_n : N of the growth runs.
    cache : folder of cached measurements (None: measure every time).
    tuning : how a nominal BPM sets the slider (`metrosync.model.TUNINGS`); None: the
        design's own ``tuning``. Either way the curve is computed, labelled and cached
        with one tuning, the design's after this replacement.
    budget : the time of the whole request the curve is part of (`theory_budget`),
        checked once the inputs are (a warning above `metrosync.budget.WARN_SECONDS`);
        default: the curve's own.
    """
    params = with_tuning(get_preset(params, warn=False), tuning)
    tuning = params.metronome.tuning
    if method not in cp.METHODS:
        raise ParameterError(f"unknown `method` {method!r}; choose one of {list(cp.METHODS)}.")
    bpms = np.asarray(bpms, dtype=float)
    if bpms.ndim != 1 or bpms.size < 2 or np.any(np.diff(bpms) <= 0):
        raise ParameterError(
            f"`bpms` must be at least 2 increasing nominal BPM values, got {bpms.tolist()!r}."
        )
    cp.disk_scale(n, params)  # checks n
    if method == "growth":
        cp.check_growth_n(measure_n, "measure_n")
    l2_for_bpm(params.metronome, bpms, tuning=tuning)  # every BPM tunable, before any work
    if budget is None:
        budget = theory_budget(bpms, method=method, measure_n=measure_n, params=params,
                               cache=cache)  # fmt: skip
    budget.check()
    rows, estimates = [], []
    with progress_bar(total=bpms.size, unit="BPM", enabled=progress, desc="measuring K") as bar:
        for bpm in bpms:
            rows.append(_measure_cached(bpm, method, params, measure_n, cache).for_n(n, params))
            estimates.append(estimate(bpm, n, params))
            bar.update(1)

    def column(items, name):
        return np.array([getattr(c, name) for c in items], dtype=float)

    data = {}
    for name, unit, text in (
        ("k", "rad/s", "coupling K"),
        ("alpha", "rad", "phase lag alpha"),
        ("k_cos", "rad/s", "K cos alpha"),
        ("k_sin", "rad/s", "K sin alpha"),
    ):
        data[name] = ("bpm", column(rows, name), {"units": unit, "long_name": text})
        data[f"{name}_err"] = ("bpm", column(rows, f"{name}_err"), {"units": unit})
        data[f"{name}_estimate"] = (
            "bpm",
            column(estimates, name),
            {"units": unit, "long_name": f"{text}, analytic estimate"},
        )
    data["free_bpm"] = (
        "bpm",
        column(rows, "free_bpm"),
        {"units": "BPM", "long_name": "tick rate at the steady swing"},
    )
    data["spread_factor"] = (
        "bpm",
        np.array([spread_factor(b, params, tuning) for b in bpms]),
        {"long_name": "d(tick rate)/d(nominal BPM)"},
    )
    return xr.Dataset(
        data,
        coords={"bpm": ("bpm", bpms, {"units": "BPM", "long_name": "nominal beat frequency"})},
        attrs={
            "n": "inf" if n == math.inf else int(n),
            "method": method,
            "tuning": tuning,
            "measure_n": measure_n,
            "measure_dt": cp.MEASURE_DT,
            "preset": params.name,
            "metrosync_version": __version__,
        },
    )


def spread_factor(bpm: float, params: ModelParameters, tuning: str | None = None) -> float:
    """d(tick rate)/d(nominal BPM) at ``bpm``: how a nominal spread becomes a tick spread."""
    params = with_tuning(params, tuning)
    tuning = params.metronome.tuning
    if tuning == "steady-swing":
        return 1.0
    design = params.metronome
    ticks = [
        steady_swing(design.with_l2(float(l2_for_bpm(design, b, tuning=tuning)))).tick_bpm
        for b in (bpm - 0.5, bpm + 0.5)
    ]
    return ticks[1] - ticks[0]


def threshold(curve: xr.Dataset, sigma_bpm: float) -> np.ndarray:
    """K_c(α(ω₀), σ_ω(ω₀)) along a `coupling_curve`, rad/s."""
    sigma_omega = math.pi / 60 * sigma_bpm * curve.spread_factor.values
    return np.asarray(critical_coupling(curve.alpha.values, sigma_omega))


def predict_onset(curve: xr.Dataset, sigma_bpm: float, *, shift: float = 0.0) -> float:
    """ω_c (nominal BPM) where K(ω₀) + shift·K_err first rises through K_c; NaN if it
    does not within the curve's BPM range (found by monotone interpolation)."""
    bpm = curve.bpm.values
    k = curve.k.values + shift * curve.k_err.values
    k_c = threshold(curve, sigma_bpm)
    gap = PchipInterpolator(bpm, k - k_c)
    values = gap(bpm)
    sign_change = np.nonzero(np.diff(np.sign(values)) > 0)[0]
    if sign_change.size == 0:
        return math.nan
    i = sign_change[0]
    return float(brentq(gap, bpm[i], bpm[i + 1], xtol=1e-6))


def _reduced_r(curve, sigma_bpm: float, bpm: float, n: int, runs: int, seed=0) -> float:
    """Mean r_eq of the reduced model at ``bpm``, K and α interpolated along the curve."""
    grid = curve.bpm.values

    def at(name):
        return float(PchipInterpolator(grid, curve[name].values)(bpm))

    sigma = math.pi / 60 * sigma_bpm * at("spread_factor")
    k = at("k")
    dt = min(0.5, 0.4 / (6 * sigma + k))
    ds = simulate_reduced(
        n, k=k, alpha=at("alpha"), sigma=sigma, runs=runs, duration=600.0, dt=dt, seed=seed
    )
    return float(ds.r_eq.mean())


def order_curve(curve: xr.Dataset, sigma_bpm: float, *, n: int = 20_000, runs: int = 1):
    """r_eq(ω₀) of the reduced model at the curve's BPM values: ``runs`` runs of ``n``
    oscillators with Gaussian tick frequencies of spread σ_ω (the same draw throughout).

    For the N → ∞ curve, n = 20 000 leaves finite-size noise of ≈ 0.01 in r.
    """
    return np.array([_reduced_r(curve, sigma_bpm, b, n, runs) for b in curve.bpm.values])


def half_order(curve, sigma_bpm: float, r: np.ndarray, *, n: int, runs: int) -> float:
    """The ω₀ where the reduced r_eq rises through 1/2: bracketed on the curve, then
    bisected to 0.2 BPM with K, α interpolated. NaN if r does not cross 1/2."""
    bpm = curve.bpm.values
    up = np.nonzero((r[:-1] < 0.5) & (r[1:] >= 0.5))[0]
    if up.size == 0:
        return math.nan
    lo, hi = bpm[up[0]], bpm[up[0] + 1]
    while hi - lo > 0.2:
        mid = (lo + hi) / 2
        if _reduced_r(curve, sigma_bpm, mid, n, runs) < 0.5:
            lo = mid
        else:
            hi = mid
    return float(lo + hi) / 2


def reduced_theory(
    preset: ModelParameters | str = "default",
    *,
    bpms: Sequence[float] = tuple(range(150, 231, 10)),
    sigmas: Sequence[float] = (0.5, 0.75, 1.0, 1.25, 1.5),
    n: int | float = math.inf,
    tuning: str | None = None,
    method: str = "growth",
    measure_n: int = 32,
    cache: Path | None = None,
    simulate_n: int | None = 20_000,
    progress: bool = False,
) -> xr.Dataset:
    """K(ω₀), α(ω₀) for a preset and the predicted ω_c for each σ (BPM); see module docs.

    simulate_n : also run the reduced model with this many oscillators (for finite ``n``:
        ``n`` of them, 16 runs) at every BPM and σ, giving ``r_reduced(sigma, bpm)`` and the
        ω₀ where it reaches 1/2, ``omega_half``; None skips it.
    """
    params = with_tuning(get_preset(preset, warn=False), tuning)
    if params.overturns:
        raise ParameterError(
            f"preset {params.name!r} overturns (energy-balance amplitude "
            f"{params.balance_amplitude:.2f} rad): there is no steady swing to reduce to a phase "
            f"model. Use a preset whose swing stays below pi/2, e.g. 'default'."
        )
    sigmas = np.asarray(sigmas, dtype=float)
    if sigmas.ndim != 1 or sigmas.size == 0 or not np.all(np.isfinite(sigmas) & (sigmas > 0)):
        raise ParameterError(f"`sigmas` must be spreads > 0 BPM, got {sigmas.tolist()!r}.")
    if simulate_n is None:
        size = 0
    else:  # N → ∞: one large population; finite N: 16 populations of N, averaged.
        size, runs = (simulate_n, 1) if n == math.inf else (int(n), 16)
    budget = theory_budget(
        np.atleast_1d(np.asarray(bpms, dtype=float)), sigmas=sigmas.size, method=method,
        measure_n=measure_n, params=params, cache=cache, reduced=size * runs if size else 0,
    )  # fmt: skip
    ds = coupling_curve(
        bpms,
        n=n,
        params=params,
        method=method,
        measure_n=measure_n,
        cache=cache,
        progress=progress,
        budget=budget,
    )
    centre = [predict_onset(ds, s) for s in sigmas]
    # More coupling moves the crossing down: the +1σ curve gives the lower bound.
    low = [predict_onset(ds, s, shift=1.0) for s in sigmas]
    high = [predict_onset(ds, s, shift=-1.0) for s in sigmas]
    ds = ds.assign_coords(
        sigma=("sigma", sigmas, {"units": "BPM", "long_name": "spread of nominal frequencies"})
    )
    ds["omega_c"] = (
        "sigma",
        np.array(centre),
        {"units": "BPM", "long_name": "predicted critical frequency (NaN: off grid)"},
    )
    ds["omega_c_low"] = ("sigma", np.array(low), {"units": "BPM"})
    ds["omega_c_high"] = ("sigma", np.array(high), {"units": "BPM"})
    ds["k_c"] = (
        ("sigma", "bpm"),
        np.stack([threshold(ds, s) for s in sigmas]),
        {"units": "rad/s", "long_name": "Sakaguchi threshold K_c(alpha, sigma_omega)"},
    )
    if simulate_n is not None:
        r = np.empty((sigmas.size, ds.bpm.size))
        with progress_bar(total=r.size, unit="point", enabled=progress,
                          desc="reduced model") as bar:  # fmt: skip
            for (i, j), _ in np.ndenumerate(r):  # `order_curve`, one point at a time
                r[i, j] = _reduced_r(ds, sigmas[i], float(ds.bpm[j]), size, runs)
                bar.update(1)
        ds["r_reduced"] = (
            ("sigma", "bpm"),
            r,
            {"long_name": "r_eq of the reduced model (Gaussian tick frequencies)"},
        )
        half = [half_order(ds, s, row, n=size, runs=runs) for s, row in zip(sigmas, r, strict=True)]
        ds["omega_half"] = (
            "sigma",
            np.array(half),
            {"units": "BPM", "long_name": "where the reduced r_eq reaches 1/2"},
        )
    ds.attrs.update({k: str(v) if isinstance(v, list) else v for k, v in params.as_dict().items()})
    ds.attrs["preset"] = params.name
    return ds

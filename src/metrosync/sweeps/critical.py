"""The critical frequency ω_c(N) of the onset of synchronization (paper §7, Fig. 10).

Contract: from per-run equilibrium order parameters r_eq on a grid of nominal
frequencies ω₀ (BPM), two estimators of ω_c for each N:

``peak``  where σ_r(ω₀), the spread of r_eq over runs, is largest;
``rise``  where r̄(ω₀), the mean over runs, rises fastest (largest slope of a local
          quadratic fit over 5 grid points on an even grid; plain differences
          between neighbours otherwise).

Both are refined below the grid step by the vertex of the parabola through the
maximum and its two neighbours. Error bars come from a bootstrap over runs: the
runs at each ω₀ are resampled with replacement and both estimators recomputed; the
error is the standard deviation of the replicas.

`extrapolate` fits ω_c(N) = ω_c∞ + a·N^(−ν) (weighted by the bootstrap errors, which
are floored at 1 % of the grid step, the estimators' resolution). With only three
sizes ν is fixed to 1 (ω_c linear in 1/N); with fewer there is no extrapolation.
`size_set_spread` adds the fit's systematic error: how far ω_c∞ moves when the
smallest or the largest N is left out. `judge` says why a fit is not to be trusted:
ω_c∞ outside the swept grid (the data say nothing there), an uncertainty over half the
grid, or an exponent at the fit's bound; `critical_frequency` stores that as
``fit_note_<method>`` ('' = trusted).
All frequencies are in BPM.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.optimize import OptimizeWarning, curve_fit
from scipy.signal import savgol_filter

from .. import interrupts
from ..budget import Budget
from ..errors import ParameterError
from .resample import resample_runs

METHODS = ("peak", "rise")
#: Grid points in the local quadratic fit that gives the slope of r̄(ω₀).
SLOPE_WINDOW = 5
#: Resampled values per bootstrap batch.
BATCH_VALUES = 2_000_000
#: Bounds of the free exponent ν in the N → ∞ fit.
NU_BOUNDS = (0.05, 5.0)


def _refined_argmax(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Position of the maximum of ``y`` (..., K) over ``x`` (K,), refined by a parabola.

    NaN entries are ignored; a row with no finite value gives NaN.
    """
    y = np.asarray(y, dtype=float)
    filled = np.where(np.isfinite(y), y, -np.inf)
    k = np.argmax(filled, axis=-1)
    best = np.take_along_axis(filled, k[..., None], axis=-1)[..., 0]
    out = x[k].astype(float)
    inner = (k > 0) & (k < len(x) - 1)
    km, kp = np.clip(k - 1, 0, len(x) - 1), np.clip(k + 1, 0, len(x) - 1)
    x0, x1, x2 = x[km], x[k], x[kp]
    y0 = np.take_along_axis(filled, km[..., None], axis=-1)[..., 0]
    y2 = np.take_along_axis(filled, kp[..., None], axis=-1)[..., 0]
    with np.errstate(all="ignore"):
        denom = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (best - y0) + x1 * (y0 - y2) + x0 * (y2 - best)) / denom
        b = (x2**2 * (y0 - best) + x1**2 * (y2 - y0) + x0**2 * (best - y2)) / denom
        vertex = np.clip(-b / (2 * a), x0, x2)
    ok = inner & np.isfinite(y0) & np.isfinite(y2) & (a < 0) & np.isfinite(vertex)
    out = np.where(ok, vertex, out)
    return np.where(np.isfinite(best), out, np.nan)


def estimate(bpm: np.ndarray, r_runs: np.ndarray) -> dict[str, np.ndarray]:
    """Both ω_c estimators for run samples ``r_runs`` (..., K, B) at ``bpm`` (K,).

    Returns ``{"peak": (...), "rise": (...)}`` in BPM. NaN runs are ignored.
    """
    bpm = np.asarray(bpm, dtype=float)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows give NaN on purpose
        mean = np.nanmean(r_runs, axis=-1)
        spread = np.nanstd(r_runs, axis=-1, ddof=1)
    return {"peak": _refined_argmax(bpm, spread), "rise": _refined_argmax(*_slope(bpm, mean))}


def _slope(bpm: np.ndarray, mean: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dr̄/dω₀ and where it is taken: a Savitzky–Golay derivative (quadratic over
    ``SLOPE_WINDOW`` points) on an even grid, else plain differences at midpoints.

    Differentiating noisy means amplifies the noise; the local quadratic fit tames it
    and, being symmetric, leaves the position of a symmetric rise unbiased. Where a
    fit's window holds a NaN mean (no finite run there), its slope is NaN.
    """
    steps = np.diff(bpm)
    if bpm.size >= SLOPE_WINDOW and np.allclose(steps, steps[0], rtol=1e-6):
        missing = ~np.isfinite(mean)
        slope = savgol_filter(
            np.where(missing, 0.0, mean), SLOPE_WINDOW, 2, deriv=1, delta=steps[0], axis=-1,
            mode="interp",
        )  # fmt: skip
        # Position k uses the window centred on it; the first and last half-windows share
        # the window at their end of the grid (mode="interp").
        half = SLOPE_WINDOW // 2
        centre = np.clip(np.arange(bpm.size), half, bpm.size - 1 - half)
        windows = centre[:, None] + np.arange(-half, half + 1)[None, :]
        touched = missing[..., windows].any(axis=-1)
        return bpm, np.where(touched, np.nan, slope)
    return 0.5 * (bpm[1:] + bpm[:-1]), np.diff(mean, axis=-1) / steps


def bootstrap(
    bpm: np.ndarray, r_runs: np.ndarray, *, n_boot: int = 1000, seed: int = 0
) -> dict[str, np.ndarray]:
    """Bootstrap replicas of both estimators: ``{"peak": (n_boot,), "rise": (n_boot,)}``.

    r_runs : (K, B) per-run r_eq at each of the K frequencies; runs are resampled
    independently at each frequency (they are independent simulations), each among
    its own finite runs (`metrosync.sweeps.resample`).
    """
    r_runs = np.asarray(r_runs, dtype=float)
    rng = np.random.default_rng(seed)
    # In batches, so that memory stays bounded for many runs and replicas.
    batch = max(1, BATCH_VALUES // r_runs.size)
    parts: dict[str, list[np.ndarray]] = {m: [] for m in METHODS}
    for start in range(0, n_boot, batch):
        interrupts.check()
        replicas = resample_runs(r_runs, rng, (min(batch, n_boot - start), *r_runs.shape))
        for m, values in estimate(bpm, replicas).items():
            parts[m].append(values)
    return {m: np.concatenate(parts[m]) for m in METHODS}


def bootstrap_budget(n_boot: int, shape: tuple[int, ...]) -> Budget:
    """Memory and time of the bootstrap of `critical_frequency` over ``shape`` =
    (sizes N, frequencies, runs): each size's replicas of both estimators (kept, then
    joined), one batch of resamples, and about 60 ns per resampled value (measured
    30-120 ns)."""
    sizes, per_size = shape[0], float(np.prod(shape[1:]))
    return Budget(
        "the bootstrap",
        {"replicas": 4 * 8.0 * n_boot, "one batch of resamples": 48.0 * BATCH_VALUES},
        seconds=60e-9 * n_boot * per_size * sizes,
        work=f"{n_boot} replicas x {sizes} sizes x {per_size:.0f} values",
        fixes="use fewer replicas (`n_boot`): 1000 give the error bars to about 2 %",
    )


@dataclass(frozen=True)
class Extrapolation:
    """ω_c(N) = omega_inf + a·N^(−nu); ``form`` says which fit was possible."""

    omega_inf: float
    omega_inf_err: float
    a: float
    nu: float
    form: str


def extrapolate(
    n: np.ndarray, omega_c: np.ndarray, err: np.ndarray, *, step: float
) -> Extrapolation:
    """Finite-size extrapolation of ω_c(N) to N → ∞ (see the module docstring).

    n, omega_c, err : (S,) sizes, estimates and their errors; ``step`` is the grid step
    (BPM) that floors the errors.
    """
    n, omega_c, err = (np.asarray(v, dtype=float) for v in (n, omega_c, err))
    good = np.isfinite(omega_c)
    n, omega_c = n[good], omega_c[good]
    sigma = np.maximum(np.nan_to_num(err[good], nan=step), 0.01 * step)
    if n.size >= 4:
        order = np.argsort(n)
        span = omega_c[order[0]] - omega_c[order[-1]]
        p0 = (omega_c[order[-1]], span * n[order[0]], 1.0)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", OptimizeWarning)
                popt, pcov = curve_fit(
                    lambda x, w, a, nu: w + a * x ** (-nu), n, omega_c, p0=p0, sigma=sigma,
                    absolute_sigma=True,
                    bounds=([-np.inf, -np.inf, NU_BOUNDS[0]], [np.inf, np.inf, NU_BOUNDS[1]]),
                    maxfev=20000,
                )  # fmt: skip
            if np.all(np.isfinite(pcov)):
                return Extrapolation(
                    float(popt[0]), float(math.sqrt(pcov[0, 0])), float(popt[1]), float(popt[2]),
                    "omega_inf + a*N**-nu",
                )  # fmt: skip
        except (RuntimeError, OptimizeWarning, ValueError):
            pass  # too few or too flat points for a free exponent: fall back to nu = 1
    if n.size >= 3:
        design = np.column_stack([np.ones_like(n), 1.0 / n]) / sigma[:, None]
        coef, *_ = np.linalg.lstsq(design, omega_c / sigma, rcond=None)
        cov = np.linalg.inv(design.T @ design)
        return Extrapolation(
            float(coef[0]), float(math.sqrt(cov[0, 0])), float(coef[1]), 1.0, "omega_inf + a/N"
        )
    return Extrapolation(math.nan, math.nan, math.nan, math.nan, "none (fewer than 3 sizes)")


def size_set_spread(
    n: np.ndarray, omega_c: np.ndarray, err: np.ndarray, *, step: float
) -> tuple[Extrapolation, float]:
    """The extrapolation of all sizes and its systematic error: the largest shift of
    omega_inf when the smallest or the largest N is left out (as the collapse's size
    sets in `sweeps.scaling`). A left-out set of fewer than 3 sizes gives no fit and
    no shift; with no variant at all the spread is NaN.
    """
    n, omega_c, err = (np.asarray(v, dtype=float) for v in (n, omega_c, err))
    main = extrapolate(n, omega_c, err, step=step)
    order = np.argsort(n)
    shifts = []
    for keep in (order[1:], order[:-1]):
        if keep.size < 3:
            continue
        fit = extrapolate(n[keep], omega_c[keep], err[keep], step=step)
        if np.isfinite(fit.omega_inf):
            shifts.append(abs(fit.omega_inf - main.omega_inf))
    return main, max(shifts, default=math.nan)


def judge(fit: Extrapolation, bpm: np.ndarray, sizes: int) -> str:
    """Why the extrapolation ``fit`` is not to be trusted, or '' when it is.

    bpm : the swept grid (BPM).   sizes : how many N had a finite ω_c.
    """
    low, high = float(np.min(bpm)), float(np.max(bpm))
    if not np.isfinite(fit.omega_inf):
        return f"needs at least 3 sizes N with an estimate, got {sizes}; sweep more N"
    if not low <= fit.omega_inf <= high:
        return (
            f"the fit gives {fit.omega_inf:.1f} +- {fit.omega_inf_err:.1f} BPM, outside the "
            f"swept grid {low:g} .. {high:g} BPM where the data say nothing; widen the --bpm "
            f"range or add larger N"
        )
    if not fit.omega_inf_err <= (high - low) / 2:
        return (
            f"the fit gives {fit.omega_inf:.1f} +- {fit.omega_inf_err:.1f} BPM, uncertain by "
            f"more than half the grid; add runs or larger N"
        )
    if fit.form.endswith("**-nu") and not NU_BOUNDS[0] * 1.01 < fit.nu < NU_BOUNDS[1] * 0.99:
        return (
            f"the exponent nu = {fit.nu:.3g} sits at the fit's bound {NU_BOUNDS}, so the form "
            f"does not describe these sizes; add larger N"
        )
    return ""


def sweep_runs(sweep: xr.Dataset) -> xr.DataArray:
    """r_eq of a merged sweep as (n, bpm, run), bpm ascending; see `critical_frequency`.

    Refuses a sweep without ``bpm`` and ``run``, with under 3 BPMs, with another swept
    dimension of more than one value, or with an N whose every run is NaN.
    """
    if "r_eq" not in sweep or "bpm" not in sweep.dims or "run" not in sweep.dims:
        raise ParameterError(
            "`sweep` must be a merged sweep with `r_eq` over `bpm` and `run`; sweep `bpm` "
            "(e.g. --bpm 150:220:2.5)."
        )
    if sweep.sizes["bpm"] < 3:
        raise ParameterError(
            f"`bpm` needs at least 3 values to locate ω_c, got {sweep.sizes['bpm']}."
        )
    extra = [d for d in sweep.dims if d not in ("bpm", "run", "n", "time")]
    wide = [d for d in extra if sweep.sizes[d] > 1]
    if wide:
        raise ParameterError(
            f"the sweep also varies {wide}; select one value first, e.g. ds.sel({wide[0]}=...) "
            f"or `metrosync critical --select {wide[0]}=VALUE`."
        )
    r = sweep.r_eq.isel({d: 0 for d in extra})
    if "n" not in r.dims:
        n_value = sweep.attrs.get("fixed_n", 0)
        r = r.expand_dims(n=[n_value])
    r = r.sortby("bpm").transpose("n", "bpm", "run")
    empty = [
        n.item() for n, row in zip(r.n.values, r.values, strict=True) if not np.isfinite(row).any()
    ]
    if empty:
        raise ParameterError(
            f"`sweep` has no finite r_eq for N = {empty}: every point failed, or the runs are "
            f"too short for the crossing phase (each metronome must cross zero twice before "
            f"the final window). Sweep a longer `duration`, or select other N."
        )
    return r


def critical_frequency(sweep: xr.Dataset, *, n_boot: int = 1000, seed: int = 0) -> xr.Dataset:
    """ω_c(N) by both estimators, with bootstrap errors and the N → ∞ extrapolation.

    Parameters
    ----------
    sweep : a merged sweep with a ``bpm`` dimension (at least 3 values), a ``run``
        dimension, optionally an ``n`` dimension; any other dimension must have length 1
        (select a slice first, e.g. ``ds.sel(drive=6e-5)``).
    n_boot : bootstrap replicas.   seed : seed of the resampling.

    Returns
    -------
    xarray.Dataset with r_mean, sigma_r (n, bpm) and omega_c_{peak,rise} and their
    ``_err`` (n); attrs hold the extrapolation for each method, its error over runs
    (``omega_c_inf_<method>_err``) and its spread over size sets (``_syst``, NaN
    with fewer than 4 sizes).
    """
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 2:
        raise ParameterError(f"`n_boot` must be an integer >= 2, got {n_boot!r}.")
    r = sweep_runs(sweep)
    bpm = r.bpm.values.astype(float)
    step = float(np.min(np.diff(bpm)))
    values = r.values
    bootstrap_budget(n_boot, values.shape).check()
    central = estimate(bpm, values)
    errors = {m: np.empty(values.shape[0]) for m in METHODS}
    for i in range(values.shape[0]):
        replicas = bootstrap(bpm, values[i], n_boot=n_boot, seed=seed + i)
        for m in METHODS:
            errors[m][i] = np.nanstd(replicas[m], ddof=1)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        r_mean = np.nanmean(values, axis=-1)
        sigma_r = np.nanstd(values, axis=-1, ddof=1)
    bpm_units = {"units": "BPM"}
    data = {
        "r_mean": (("n", "bpm"), r_mean, {"long_name": "equilibrium r, mean over runs"}),
        "sigma_r": (("n", "bpm"), sigma_r, {"long_name": "std of equilibrium r over runs"}),
    }
    attrs: dict = {"n_boot": n_boot, "bootstrap_seed": seed}
    for m in METHODS:
        data[f"omega_c_{m}"] = ("n", central[m], {**bpm_units, "long_name": f"ω_c from the {m}"})
        data[f"omega_c_{m}_err"] = ("n", errors[m], {**bpm_units, "long_name": "bootstrap std"})
        fit, spread = size_set_spread(r.n.values, central[m], errors[m], step=step)
        attrs.update(
            {
                f"omega_c_inf_{m}": fit.omega_inf,
                f"omega_c_inf_{m}_err": fit.omega_inf_err,
                f"omega_c_inf_{m}_syst": spread,
                f"fit_a_{m}": fit.a,
                f"fit_nu_{m}": fit.nu,
                f"fit_form_{m}": fit.form,
                f"fit_note_{m}": judge(fit, bpm, int(np.isfinite(central[m]).sum())),
            }
        )
    coords = {
        "n": ("n", r.n.values, {"long_name": "metronomes on the disk"}),
        "bpm": ("bpm", bpm, {**bpm_units, "long_name": "nominal beat frequency ω₀"}),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def plot_critical(result: xr.Dataset, path=None):
    """r̄(ω₀) and σ_r(ω₀) for every N with ω_c marked, and ω_c against N with the fit.

    result : a `critical_frequency` dataset.   path : write the figure there when given.
    Error bands are clipped to the swept grid; a fit with a ``fit_note`` is not drawn.
    Returns the figure.
    """
    import matplotlib

    from ..plots import finish_figure, new_figure

    fig = new_figure(path, figsize=(14, 4.2), layout="constrained")
    axes = fig.subplots(1, 3)
    bpm = result.bpm.values
    colors = matplotlib.colormaps["viridis"](np.linspace(0, 0.9, result.sizes["n"]))
    for color, n in zip(colors, result.n.values, strict=True):
        one = result.sel(n=n)
        axes[0].plot(bpm, one.r_mean, "o-", ms=3, color=color, label=f"N = {n}")
        axes[1].plot(bpm, one.sigma_r, "o-", ms=3, color=color)
        for ax, m, style in ((axes[0], "rise", "--"), (axes[1], "peak", ":")):
            wc, err = float(one[f"omega_c_{m}"]), float(one[f"omega_c_{m}_err"])
            ax.axvline(wc, color=color, ls=style, lw=1)
            # The data end with the grid; so does what they say about ω_c.
            lo, hi = max(wc - err, bpm.min()), min(wc + err, bpm.max())
            if hi > lo:
                ax.axvspan(lo, hi, color=color, alpha=0.12, lw=0)
    for ax in axes[:2]:
        ax.set_xlim(bpm.min() - 0.02 * np.ptp(bpm), bpm.max() + 0.02 * np.ptp(bpm))
    axes[0].set(xlabel=r"$\omega_0$ (BPM)", ylabel="r (mean over runs)",
                title=r"$\omega_c$ from the steepest rise")  # fmt: skip
    axes[1].set(xlabel=r"$\omega_0$ (BPM)", ylabel=r"$\sigma_r$ (spread of r over runs)",
                title=r"$\omega_c$ from the $\sigma_r$ peak")  # fmt: skip
    axes[0].legend(loc="upper left", fontsize=8)
    ax = axes[2]
    n = result.n.values.astype(float)
    for k, (m, marker) in enumerate((("peak", "o"), ("rise", "s"))):
        bars = ax.errorbar(n, result[f"omega_c_{m}"], yerr=result[f"omega_c_{m}_err"],
                           fmt=marker, capsize=3, label=f"{m}")  # fmt: skip
        color = bars[0].get_color()
        w, a, nu = (result.attrs[f"{key}_{m}"] for key in ("omega_c_inf", "fit_a", "fit_nu"))
        note = result.attrs.get(f"fit_note_{m}", "")
        where = (0.03, 0.97 - 0.07 * k)
        if note or not np.isfinite(w):
            ax.annotate(f"{m}: no N → ∞ value (see the printed reason)", where,
                        xycoords="axes fraction", fontsize=8, va="top")  # fmt: skip
            continue
        grid = np.geomspace(n.min(), n.max() * 4, 100)
        ax.plot(grid, w + a * grid ** (-nu), lw=1, color=color)
        err = result.attrs[f"omega_c_inf_{m}_err"]
        syst = result.attrs.get(f"omega_c_inf_{m}_syst", math.nan)
        spread = "" if np.isnan(syst) else f" ± {syst:.1f} (N set)"
        ax.axhline(w, ls="--", lw=0.8, color=color)
        ax.annotate(rf"{m}: $\omega_{{c,\infty}}$ = {w:.1f} ± {err:.1f}{spread} BPM", where,
                    xycoords="axes fraction", fontsize=8, va="top")  # fmt: skip
    ax.set(xscale="log", xlabel="N (metronomes)", ylabel=r"$\omega_c$ (BPM)",
           title="finite-size extrapolation")  # fmt: skip
    ax.legend(loc="lower right", fontsize=8)
    return finish_figure(fig, path)

"""Finite-size scaling: the collapse of r_eq(x, N) onto one curve, and x_c(∞) from it.

Contract: given the mean order parameter r(x, N) and its error on a grid of a
control parameter x (the tick rate ω₀ in BPM for metronomes, the coupling K for
plain Kuramoto oscillators) for several sizes N, fit the finite-size-scaling form

    r(x, N) = N^(−β/ν̄) · F((x − x_c) · N^(1/ν̄))

with F a polynomial of degree ``degree`` in tanh(u/s), u the scaling variable and s
a fitted scale: a master curve that may saturate on either side of the transition,
so that a BPM grid wide enough for the smallest N still collapses at the largest.
The fit is one weighted least-squares problem over all sizes at once, in the raw
r, so each point keeps its own error; x_c, the polynomial's coefficients and,
unless fixed, the exponents a = β/ν̄ and b = 1/ν̄ are its parameters. The statistical
error of one fit comes from its covariance, scaled up by √(χ²/dof) when that exceeds
1; `finite_size_scaling` takes the larger of that and a bootstrap over runs.

`finite_size_scaling` repeats the fit over narrower x-windows around x_c and over
size sets with the smallest or the largest N left out; the spread of those fits
(their largest deviation from the main fit) is the systematic error, added in
quadrature to the statistical one. For the Kuramoto model with randomly drawn
(quenched) natural frequencies β = 1/2 and ν̄ = 5/2, so a = 1/5 and b = 2/5 (Hong,
Chaté, Park and Tang, Phys. Rev. Lett. 98, 184101 (2007)); `KURAMOTO_EXPONENTS`.

Arrays: ``x`` (K,), ``sizes`` (M,), ``r`` and ``r_err`` (M, K), per-run values
(M, K, B); NaN marks a missing point. Only `sweep_scaling` knows about sweeps (it
reads ω₀ in BPM as x); the rest knows nothing of metronomes or units.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from scipy.optimize import least_squares

from .. import interrupts
from ..errors import ParameterError
from .resample import resample_runs

#: (β/ν̄, 1/ν̄) of the Kuramoto transition with random natural frequencies.
KURAMOTO_EXPONENTS = (0.2, 0.4)
#: Bounds of the exponents a = β/ν̄ and b = 1/ν̄ when they are fitted.
A_BOUNDS = (0.0, 1.0)
B_BOUNDS = (0.05, 2.0)
#: Bounds of the fitted factor on the master curve's scale of u.
W_BOUNDS = (0.05, 20.0)
#: Smallest error a point may carry, so that a point with zero spread (all runs
#: equal) does not dominate the fit.
ERROR_FLOOR = 1e-4
#: Starting values of x_c tried across the window; the best fit wins.
STARTS = 7


@dataclass(frozen=True)
class Collapse:
    """One finite-size-scaling fit.

    Attributes
    ----------
    x_c, x_c_err : float
        Critical value of the control parameter and its statistical error.
    a, a_err, b, b_err : float
        Exponents β/ν̄ and 1/ν̄ (errors are 0 when they were fixed).
    fixed : bool
        True when the exponents were fixed rather than fitted.
    coefficients : ndarray (degree + 1,)
        Master curve F(u) = Σ c_k tanh(u/u_scale)^k.
    u_scale : float
        Fitted scale of the scaling variable u in the master curve.
    chi2_dof : float
        χ² per degree of freedom of the fit.
    sizes : tuple of int
        The sizes N that entered the fit.
    window : (float, float)
        The x-range that entered the fit.
    points : int
        The number of (x, N) points that entered the fit.
    """

    x_c: float
    x_c_err: float
    a: float
    a_err: float
    b: float
    b_err: float
    fixed: bool
    coefficients: np.ndarray = field(repr=False)
    u_scale: float
    chi2_dof: float
    sizes: tuple[int, ...]
    window: tuple[float, float]
    points: int

    def master(self, u: np.ndarray) -> np.ndarray:
        """The fitted master curve F at scaling variable ``u`` = (x − x_c)·N^b."""
        t = np.tanh(np.asarray(u, dtype=float) / self.u_scale)
        return np.polynomial.polynomial.polyval(t, self.coefficients)


@dataclass(frozen=True)
class ScalingEstimate:
    """The main collapse, its variants, and x_c and the exponents with total errors.

    ``*_syst`` is the largest deviation of a variant from the main fit; ``*_err``
    is the statistical error of the main fit and ``*_syst`` added in quadrature.
    """

    best: Collapse
    variants: tuple[Collapse, ...]
    x_c: float
    x_c_err: float
    x_c_syst: float
    a: float
    a_err: float
    a_syst: float
    b: float
    b_err: float
    b_syst: float


def _check(x, sizes, r, r_err):
    x = np.asarray(x, dtype=float)
    sizes = np.asarray(sizes)
    r = np.asarray(r, dtype=float)
    r_err = np.asarray(r_err, dtype=float)
    if x.ndim != 1 or x.size < 3 or not np.all(np.isfinite(x)):
        raise ParameterError(
            f"`x` must be a 1-D array of at least 3 finite values, got shape {x.shape}."
        )
    if (
        sizes.ndim != 1
        or sizes.size < 2
        or np.any(sizes < 1)
        or len(set(sizes.tolist())) != sizes.size
    ):
        raise ParameterError(
            f"`sizes` must list at least 2 different sizes N >= 1, got {sizes.tolist()!r}."
        )
    shape = (sizes.size, x.size)
    for name, arr in (("r", r), ("r_err", r_err)):
        if arr.shape != shape:
            raise ParameterError(
                f"`{name}` must have shape (len(sizes), len(x)) = {shape}, got {arr.shape}."
            )
    if np.any(r_err[np.isfinite(r_err)] < 0):
        raise ParameterError("`r_err` must be >= 0 (standard errors); negative values found.")
    return x, sizes.astype(int), r, r_err


def collapse(
    x,
    sizes,
    r,
    r_err,
    *,
    exponents: tuple[float, float] | None = None,
    window: tuple[float, float] | None = None,
    degree: int = 4,
    x_c_guess: float | None = None,
) -> Collapse:
    """Fit the finite-size-scaling form r = N^(−a)·F((x − x_c)·N^b) to ``r`` (M, K).

    Parameters
    ----------
    x : array (K,)
        Control parameter.
    sizes : array (M,)
        System sizes N.
    r, r_err : arrays (M, K)
        Mean order parameter and its standard error (NaN: no data).
    exponents : (a, b), optional
        Fix a = β/ν̄ and b = 1/ν̄ (e.g. `KURAMOTO_EXPONENTS`); fitted when None.
    window : (lo, hi), optional
        Only points with lo <= x <= hi enter the fit; all when None.
    degree : int
        Degree of the polynomial master curve F. A χ²/dof well above 1 says the
        degree is too low for the window (or the window too wide for the form).
    x_c_guess : float, optional
        Start of x_c; several starts across the window are tried when None.

    Returns
    -------
    Collapse
    """
    x, sizes, r, r_err = _check(x, sizes, r, r_err)
    if not isinstance(degree, (int, np.integer)) or not 1 <= degree <= 8:
        raise ParameterError(f"`degree` must be an integer from 1 to 8, got {degree!r}.")
    lo, hi = (float(x.min()), float(x.max())) if window is None else map(float, window)
    if not lo < hi:
        raise ParameterError(f"`window` must be (lo, hi) with lo < hi, got {window!r}.")
    if exponents is not None:
        a0, b0 = map(float, exponents)
        if not (A_BOUNDS[0] <= a0 <= A_BOUNDS[1] and B_BOUNDS[0] <= b0 <= B_BOUNDS[1]):
            raise ParameterError(
                f"`exponents` must be (a, b) with a in {A_BOUNDS} and b in {B_BOUNDS}, "
                f"got {exponents!r}."
            )
    else:
        a0, b0 = KURAMOTO_EXPONENTS
    xx, nn = np.meshgrid(x, sizes.astype(float))
    use = np.isfinite(r) & np.isfinite(r_err) & (xx >= lo) & (xx <= hi)
    xs, ns, rs = xx[use], nn[use], r[use]
    es = np.maximum(r_err[use], ERROR_FLOOR)
    n_par = degree + 3 + (0 if exponents is not None else 2)
    if rs.size <= n_par:
        raise ParameterError(
            f"the collapse needs more than {n_par} points for `degree`={degree}, "
            f"got {rs.size} in `window` {(lo, hi)}: sweep more values of x (ω₀) or sizes, "
            f"widen the window, or lower the degree."
        )
    used_sizes = tuple(int(n) for n in sizes if np.any(ns == n))
    # tanh(u/u_scale) spans most of (−1, 1) across the window at the median N; the
    # fitted factor w on u_scale lets the master curve saturate, or stay linear
    u_scale = 0.5 * (hi - lo) * float(np.median(ns)) ** b0

    def unpack(p):
        if exponents is None:
            return p[0], p[1], p[2], p[3], p[4:]
        return p[0], a0, b0, p[1], p[2:]

    def residual(p):
        xc, a, b, log_w, c = unpack(p)
        t = np.tanh((xs - xc) * ns**b / (u_scale * math.exp(log_w)))
        model = ns ** (-a) * np.polynomial.polynomial.polyval(t, c)
        return (rs - model) / es

    def linear_start(xc):
        # the coefficients are linear given x_c and the exponents
        u = np.tanh((xs - xc) * ns**b0 / u_scale)
        design = ns[:, None] ** (-a0) * u[:, None] ** np.arange(degree + 1)
        c, *_ = np.linalg.lstsq(design / es[:, None], rs / es, rcond=None)
        return c

    starts = [x_c_guess] if x_c_guess is not None else np.linspace(lo, hi, STARTS + 2)[1:-1]
    best = None
    for xc0 in starts:
        c0 = linear_start(float(xc0))
        head = [float(xc0)] + ([] if exponents is not None else [a0, b0]) + [0.0]
        lower = [lo] + ([] if exponents is not None else [A_BOUNDS[0], B_BOUNDS[0]])
        upper = [hi] + ([] if exponents is not None else [A_BOUNDS[1], B_BOUNDS[1]])
        lower, upper = lower + [math.log(W_BOUNDS[0])], upper + [math.log(W_BOUNDS[1])]
        p0 = np.concatenate([head, c0])
        bounds = (lower + [-np.inf] * c0.size, upper + [np.inf] * c0.size)
        p0[: len(lower)] = np.clip(p0[: len(lower)], lower, upper)
        fit = least_squares(residual, p0, bounds=bounds, x_scale="jac")
        if best is None or fit.cost < best.cost:
            best = fit
    dof = rs.size - best.x.size
    chi2_dof = 2.0 * best.cost / dof
    with np.errstate(all="ignore"):
        try:
            cov = np.linalg.pinv(best.jac.T @ best.jac) * max(1.0, chi2_dof)
            err = np.sqrt(np.abs(np.diag(cov)))
        except np.linalg.LinAlgError:
            err = np.full(best.x.size, np.nan)
    xc, a, b, log_w, c = unpack(best.x)
    a_err, b_err = (0.0, 0.0) if exponents is not None else (float(err[1]), float(err[2]))
    return Collapse(
        x_c=float(xc),
        x_c_err=float(err[0]),
        a=float(a),
        a_err=a_err,
        b=float(b),
        b_err=b_err,
        fixed=exponents is not None,
        coefficients=np.asarray(c, dtype=float),
        u_scale=u_scale * math.exp(log_w),
        chi2_dof=float(chi2_dof),
        sizes=used_sizes,
        window=(lo, hi),
        points=int(rs.size),
    )


def mean_and_error(r_runs) -> tuple[np.ndarray, np.ndarray]:
    """Mean over runs and its standard error for per-run values ``r_runs`` (M, K, B).

    NaN runs are ignored; a point with fewer than 2 finite runs gets NaN.
    """
    r_runs = np.asarray(r_runs, dtype=float)
    count = np.sum(np.isfinite(r_runs), axis=-1)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(r_runs, axis=-1)
        err = np.nanstd(r_runs, axis=-1, ddof=1) / np.sqrt(count)
    bad = count < 2
    return np.where(bad, np.nan, mean), np.where(bad, np.nan, err)


def finite_size_scaling(
    x,
    sizes,
    r_runs,
    *,
    exponents: tuple[float, float] | None = None,
    window: tuple[float, float] | None = None,
    narrowing: tuple[float, ...] = (0.75, 0.5),
    degree: int = 4,
    n_boot: int = 50,
    seed: int = 0,
) -> ScalingEstimate:
    """x_c and the exponents with an error that includes the collapse's systematic spread.

    Parameters
    ----------
    x : array (K,)
        Control parameter.
    sizes : array (M,)
        System sizes N.
    r_runs : array (M, K, B)
        r_eq of each run (frequency draw); NaN marks a missing run. Run b is taken
        to be the same draw at every x (as in the sweeps), so the bootstrap
        resamples whole runs and keeps the correlation between neighbouring x.
    exponents, window, degree
        As in `collapse`.
    narrowing : tuple of float
        Fractions of the main fit's half-window for the narrower variants.
    n_boot : int
        Bootstrap replicas over runs for the statistical error of the main fit;
        0 uses the fit's covariance instead.
    seed : int
        Seed of the bootstrap.

    Notes
    -----
    The main fit uses all sizes in ``window``. The variants narrow the window around
    its x_c to each fraction in ``narrowing`` of its half-width, and leave out the
    smallest and (with 4 sizes or more) the largest N; variants with too few points
    are skipped. The statistical error is the larger of the bootstrap's standard
    deviation and the covariance error; the systematic error is the largest
    deviation of a variant from the main fit.

    Returns
    -------
    ScalingEstimate
    """
    r_runs = np.asarray(r_runs, dtype=float)
    if r_runs.ndim != 3:
        raise ParameterError(
            f"`r_runs` must have shape (len(sizes), len(x), runs), got {r_runs.shape}."
        )
    if not isinstance(n_boot, (int, np.integer)) or n_boot < 0 or n_boot == 1:
        raise ParameterError(f"`n_boot` must be 0 or an integer >= 2, got {n_boot!r}.")
    r, r_err = mean_and_error(r_runs)
    x, sizes, r, r_err = _check(x, sizes, r, r_err)
    main = collapse(x, sizes, r, r_err, exponents=exponents, window=window, degree=degree)
    lo, hi = main.window
    half = max(main.x_c - lo, hi - main.x_c)
    variants = []
    for f in narrowing:
        if not 0 < f < 1:
            raise ParameterError(f"`narrowing` fractions must lie in (0, 1), got {f!r}.")
        variants.append(dict(window=(main.x_c - f * half, main.x_c + f * half)))
    order = np.argsort(sizes)
    keep_sets = [order[1:]]
    if sizes.size >= 4:
        keep_sets.append(order[:-1])
    for keep in keep_sets:
        variants.append(dict(window=(lo, hi), keep=np.sort(keep)))
    fits = []
    for v in variants:
        keep = v.get("keep", np.arange(sizes.size))
        if keep.size < 2:
            continue
        try:
            fits.append(
                collapse(
                    x,
                    sizes[keep],
                    r[keep],
                    r_err[keep],
                    exponents=exponents,
                    window=v["window"],
                    degree=degree,
                    x_c_guess=main.x_c,
                )
            )
        except ParameterError:
            continue
    boot = []
    rng = np.random.default_rng(seed)
    runs = r_runs.shape[-1]
    for _ in range(n_boot):
        interrupts.check()  # a long loop of fits: let Ctrl-C land between two
        rb, eb = mean_and_error(resample_runs(r_runs, rng, (sizes.size, 1, runs)))
        try:
            boot.append(
                collapse(
                    x,
                    sizes,
                    rb,
                    eb,
                    exponents=exponents,
                    window=(lo, hi),
                    degree=degree,
                    x_c_guess=main.x_c,
                )
            )
        except ParameterError:
            continue

    def total(name):
        value = getattr(main, name)
        stat = getattr(main, name + "_err")
        if len(boot) >= 2:
            stat = max(stat, float(np.std([getattr(f, name) for f in boot], ddof=1)))
        syst = max((abs(getattr(f, name) - value) for f in fits), default=0.0)
        return value, math.hypot(stat, syst), syst

    xc, xc_err, xc_syst = total("x_c")
    a, a_err, a_syst = total("a")
    b, b_err, b_syst = total("b")
    return ScalingEstimate(
        best=main,
        variants=tuple(fits),
        x_c=xc,
        x_c_err=xc_err,
        x_c_syst=xc_syst,
        a=a,
        a_err=a_err,
        a_syst=a_syst,
        b=b,
        b_err=b_err,
        b_syst=b_syst,
    )


def sweep_scaling(
    sweep: xr.Dataset,
    *,
    exponents: str = "kuramoto",
    n_boot: int = 50,
    seed: int = 0,
    degree: int = 4,
) -> tuple[ScalingEstimate, xr.DataArray]:
    """The collapse of a merged sweep's r_eq over ``n``, ``bpm`` and ``run``.

    Parameters
    ----------
    sweep : a merged sweep as `metrosync.sweeps.critical.critical_frequency` takes it,
        with at least 2 sizes N.
    exponents : ``"kuramoto"`` fixes β/ν̄ = 1/5 and 1/ν̄ = 2/5; ``"free"`` fits them.
    n_boot, seed, degree : as in `finite_size_scaling`.

    Returns
    -------
    (ScalingEstimate, r_eq as a DataArray (n, bpm, run)); x_c is ω_c(∞) in BPM.
    """
    from .critical import sweep_runs

    choices = {"kuramoto": KURAMOTO_EXPONENTS, "free": None}
    if exponents not in choices:
        raise ParameterError(f"`exponents` must be one of {sorted(choices)}, got {exponents!r}.")
    r = sweep_runs(sweep)
    if r.sizes["n"] < 2:
        raise ParameterError(
            f"the collapse needs at least 2 sizes N, the sweep has N = {r.n.values.tolist()}; "
            f"sweep --n with several values (e.g. --n 64,256,1024)."
        )
    est = finite_size_scaling(
        r.bpm.values,
        r.n.values,
        r.values,
        exponents=choices[exponents],
        degree=degree,
        n_boot=n_boot,
        seed=seed,
    )
    return est, r


def plot_collapse(
    fit: Collapse, x, sizes, r, r_err, *, path=None, x_label="x", c_label=None, units=""
):
    """Two panels: r(x) for each N, and r·N^a against (x − x_c)·N^b with the master curve.

    ``x_label`` names x, ``c_label`` its critical value (default ``x_label`` + "_c"),
    ``units`` their unit.

    Returns the figure (also written to ``path`` when given).
    """
    import matplotlib

    from ..plots import finish_figure, new_figure

    x, sizes, r, r_err = _check(x, sizes, r, r_err)
    fig = new_figure(path, figsize=(10, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    colors = matplotlib.colormaps["viridis"](np.linspace(0, 0.9, sizes.size))
    u_all = []
    for color, n, rn, en in zip(colors, sizes, r, r_err, strict=True):
        left.errorbar(x, rn, yerr=en, marker="o", ms=3, capsize=2, color=color,
                      label=f"N = {n}")  # fmt: skip
        u = (x - fit.x_c) * float(n) ** fit.b
        scale = float(n) ** fit.a
        right.errorbar(u, rn * scale, yerr=en * scale, marker="o", ms=3, capsize=2,
                       ls="none", color=color, label=f"N = {n}")  # fmt: skip
        if int(n) in fit.sizes:
            inside = (x >= fit.window[0]) & (x <= fit.window[1]) & np.isfinite(rn)
            u_all.extend(u[inside])
    left.axvline(fit.x_c, color="k", ls=":", lw=1)
    c_label = c_label or f"{x_label}_c"
    unit = f" {units}" if units else ""
    left.set(xlabel=f"{x_label} ({units})" if units else x_label, ylabel="r_eq (mean over runs)")
    left.legend(fontsize=8)
    if u_all:
        uu = np.linspace(min(u_all), max(u_all), 200)
        right.plot(uu, fit.master(uu), "k-", lw=1, label="master curve")
    kind = "fixed" if fit.fixed else "fitted"
    right.set(xlabel=f"({x_label} − {c_label})·N^{fit.b:.3g}", ylabel=f"r_eq·N^{fit.a:.3g}")
    right.set_title(
        f"{c_label} = {fit.x_c:.5g} ± {fit.x_c_err:.2g}{unit} (stat), exponents {kind}, "
        f"χ²/dof = {fit.chi2_dof:.2g}",
        fontsize=9,
    )
    right.legend(fontsize=8)
    return finish_figure(fig, path)

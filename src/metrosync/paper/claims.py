"""Verdicts on the paper's claims (`CLAIM_TEXT`), from study data.

Contract: each ``claim_*`` function takes the assembled dataset(s) of its study and
returns a `Verdict`: the claim, one of `VERDICTS`, the measured numbers as text, and
the key numbers in ``values`` (for tests and the report). They are pure functions; a
verdict rests on a statistical criterion stated in its text, never on eyesight.

A trend counts as shown when the weighted least-squares slope of the run-mean
equilibrium r is more than `Z_SIGNIFICANT` standard errors from zero, with each
point weighted by its standard error σ_r/√runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

VERDICTS = ("reproduced", "partly reproduced", "not reproduced", "inconclusive", "not assessed")
Z_SIGNIFICANT = 2.0
#: Equilibrium r that counts as complete synchronization.
R_COMPLETE = 0.99
#: |z| above which two metronomes count as locked in (anti-)phase.
Z_LOCKED = 0.9
#: The paper's critical frequency, BPM, and the distance that still counts as "near".
OMEGA_C_PAPER = 185.0
OMEGA_C_TOLERANCE = 5.0

CLAIM_TEXT = {
    1: "Identical metronomes (σ = 0), N = 2…64 at 192 BPM: complete synchronization, r → 1.",
    2: "N = 7 with realistic spread: equilibrium r grows with ω₀ over 160…208 BPM.",
    3: "At 192 BPM, r decreases as N grows from 2 to 7.",
    4: "For large N, r(ω₀) rises sharply near ω_c ≈ 185 BPM and sharpens with N; σ_r peaks "
    "there, and the peak narrows with N.",
    5: "Two metronomes (z-study): without damping and drive no locking (z depends on θ₂(0)); "
    "with small damping and drive both in-phase and anti-phase are reachable; with the "
    "large drive only in-phase is stable.",
    6: "The parameter-estimation procedure (section 5) recovers c_θ, M and c_φ.",
}


@dataclass(frozen=True)
class Verdict:
    claim: int
    verdict: str
    numbers: str
    study: str | None = None
    values: dict = field(default_factory=dict)

    @property
    def text(self) -> str:
        return CLAIM_TEXT[self.claim]


def weighted_slope(x, mean, sigma_r, runs: int) -> tuple[float, float]:
    """Slope of ``mean`` against ``x`` and its standard error (weights runs/σ_r²).

    x, mean, sigma_r : (K,). A floor on σ_r keeps a saturated point (σ_r = 0) from
    taking all the weight.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(mean, dtype=float)
    var = np.maximum(np.asarray(sigma_r, dtype=float) ** 2, 1e-4) / runs
    w = 1.0 / var
    xm = np.sum(w * x) / np.sum(w)
    sxx = np.sum(w * (x - xm) ** 2)
    slope = np.sum(w * (x - xm) * y) / sxx
    return float(slope), float(np.sqrt(1.0 / sxx))


def _trend_verdict(z: float, sign: int) -> str:
    if sign * z > Z_SIGNIFICANT:
        return "reproduced"
    if sign * z < -Z_SIGNIFICANT:
        return "not reproduced"
    return "inconclusive"


def _runs(ds: xr.Dataset) -> int:
    return int(ds.sizes["run"])


def _listing(keys, means, stds, unit: str = "") -> str:
    return ", ".join(
        f"{k:g}{unit}: {m:.3f} ± {s:.3f}" for k, m, s in zip(keys, means, stds, strict=True)
    )


def claim_identical(ds: xr.Dataset) -> Verdict:
    """Claim 1 from the Fig. 11 study: the runs of every N reach r_eq ≥ `R_COMPLETE`.

    *reproduced* when every run does, *partly reproduced* when most runs of every N do,
    *not reproduced* otherwise. Runs left below are described (r ≈ 0 for N = 2 is the
    anti-phase state).
    """
    r_eq = ds.r_eq.transpose("case", "run").values
    complete = np.mean(r_eq >= R_COMPLETE, axis=1)
    flagged = int((ds.status != 0).sum())
    times = [
        _time_to_reach(ds.time.values, ds.r_mean.sel(case=c).values, R_COMPLETE)
        for c in ds.case.values
    ]
    if np.all(complete == 1.0) and flagged == 0:
        verdict = "reproduced"
    elif np.all(complete > 0.5):
        verdict = "partly reproduced"
    else:
        verdict = "not reproduced"
    stuck = [
        f"N = {n}: {int(np.sum(row < R_COMPLETE))} of {row.size} runs end at r_eq = "
        + ", ".join(f"{x:.2f}" for x in np.sort(row[row < R_COMPLETE]))
        for n, row in zip(ds.n.values, r_eq, strict=True)
        if np.any(row < R_COMPLETE)
    ]
    numbers = (
        f"runs with r_eq ≥ {R_COMPLETE}: "
        + ", ".join(f"N = {n}: {c:.0%}" for n, c in zip(ds.n.values, complete, strict=True))
        + f"; time for the run-mean r to stay ≥ {R_COMPLETE}: "
        + ", ".join(
            f"N = {n}: " + (f"{t:.0f} s" if np.isfinite(t) else "not within the run")
            for n, t in zip(ds.n.values, times, strict=True)
        )
        + f"; flagged runs {flagged}."
        + (" Runs that do not synchronize completely: " + "; ".join(stuck) + "." if stuck else "")
    )
    values = {
        "r_eq_min": float(np.nanmin(r_eq)) if np.isfinite(r_eq).any() else float("nan"),
        "r_eq_median": np.median(r_eq, axis=1).tolist(),
        "complete_fraction": complete.tolist(),
    }
    return Verdict(1, verdict, numbers, ds.attrs.get("study"), values)


def claim_frequency_trend(ds: xr.Dataset) -> Verdict:
    """Claim 2 from Fig. 8 (top): r_eq rises with ω₀ (weighted slope > 2 SE)."""
    return _trend_claim(2, ds, "bpm", +1, unit=" BPM", per=(10.0, "10 BPM"),
                        r_eq_mean=ds.r_eq_mean.values.tolist())  # fmt: skip


def claim_size_trend(ds: xr.Dataset) -> Verdict:
    """Claim 3 from Fig. 8 (bottom): r_eq falls with N (weighted slope < −2 SE)."""
    return _trend_claim(3, ds, "n", -1, suffix=" (N)", per=(1.0, "metronome"))


def _trend_claim(claim: int, ds: xr.Dataset, x: str, sign: int, *, unit: str = "",
                 suffix: str = "", per: tuple[float, str], **values) -> Verdict:  # fmt: skip
    """A trend of the run-mean r_eq along coordinate ``x`` in direction ``sign``.

    ``per`` = (factor, text) scales the slope as printed ("per 10 BPM"); ``values``
    are added to the verdict's values.
    """
    slope, se = weighted_slope(ds[x], ds.r_eq_mean, ds.sigma_r, _runs(ds))
    numbers = (
        f"r_eq (mean ± σ_r over {_runs(ds)} runs): "
        f"{_listing(ds[x].values, ds.r_eq_mean.values, ds.sigma_r.values, unit)}{suffix}; "
        f"slope {slope * per[0]:.4f} per {per[1]} ({slope / se:+.1f} SE)."
    )
    return Verdict(
        claim,
        _trend_verdict(slope / se, sign),
        numbers,
        ds.attrs.get("study"),
        {"slope": slope, "z": slope / se, **values},
    )


def sweep_features(ds: xr.Dataset) -> dict[int, dict[str, float]]:
    """Per N: ω₀ where r crosses 1/2, the steepest dr/dω₀, σ_r's peak and its width.

    The width is the span of grid points around the peak with σ_r ≥ half its maximum
    (the full grid span when the half-maximum is never crossed).
    """
    bpm = ds.bpm.values
    out = {}
    for n in ds.n.values:
        r = ds.r_eq_mean.sel(n=n).values
        s = ds.sigma_r.sel(n=n).values
        k = int(np.nanargmax(s))
        above = s >= s[k] / 2
        lo, hi = k, k
        while lo > 0 and above[lo - 1]:
            lo -= 1
        while hi < bpm.size - 1 and above[hi + 1]:
            hi += 1
        out[int(n)] = {
            "omega_half": _crossing(bpm, r, 0.5),
            "max_slope": float(np.nanmax(np.diff(r) / np.diff(bpm))),
            "peak_bpm": float(bpm[k]),
            "peak_sigma_r": float(s[k]),
            "peak_interior": bool(0 < k < bpm.size - 1),
            "peak_width": float(bpm[hi] - bpm[lo]),
        }
    return out


def claim_transition(ds: xr.Dataset) -> Verdict:
    """Claim 4 from Fig. 10: interior σ_r peak, sharpening and narrowing with N, ω_c."""
    feats = sweep_features(ds)
    ns = sorted(feats)
    small, large = feats[ns[0]], feats[ns[-1]]
    checks = {
        "σ_r peaks inside the swept range for the largest N": large["peak_interior"],
        "the rise sharpens with N (steepest slope, largest vs smallest N)": large["max_slope"]
        > small["max_slope"],
        "the σ_r peak narrows with N (half-maximum width, largest vs smallest N)": large[
            "peak_width"
        ]
        < small["peak_width"],
        f"the transition sits within {OMEGA_C_TOLERANCE:g} BPM of ω_c = {OMEGA_C_PAPER:g} BPM": abs(
            large["peak_bpm"] - OMEGA_C_PAPER
        )
        <= OMEGA_C_TOLERANCE,
    }
    verdict = verdict_of(checks)
    rows = "; ".join(
        f"N = {n}: r = 1/2 at {f['omega_half']:.1f} BPM, steepest {f['max_slope']:.4f}/BPM, "
        f"σ_r peak {f['peak_sigma_r']:.3f} at {f['peak_bpm']:g} BPM, width {f['peak_width']:g} BPM"
        for n, f in feats.items()
    )
    numbers = (
        rows + ". Checks: " + "; ".join(f"{k}: {'yes' if v else 'no'}" for k, v in checks.items())
    )
    return Verdict(
        4, verdict, numbers + ".", ds.attrs.get("study"), {"features": feats, "checks": checks}
    )


def verdict_of(checks) -> str:
    """*reproduced* when every check holds, *not reproduced* when none does."""
    passed = sum(checks.values())
    if passed == len(checks):
        return "reproduced"
    return "not reproduced" if passed == 0 else "partly reproduced"


def claim_z(ds: xr.Dataset) -> Verdict:
    """Claim 5 from the z-study; regimes 0, 1, 2 are free, small drive, published drive."""

    def regime(i):
        ok = (ds.status.isel(regime=i) == 0).values
        return ds.z.isel(regime=i).values, ds.z_late.isel(regime=i).values, ok

    z_free, _, ok_free = regime(0)
    spread = z_free[ok_free]
    intermediate = float(np.mean(np.abs(spread) < Z_LOCKED)) if spread.size else np.nan
    free_ok = bool(spread.size and intermediate >= 0.5)
    _, zl_small, ok_small = regime(1)
    both = bool(np.any(zl_small[ok_small] > Z_LOCKED) and np.any(zl_small[ok_small] < -Z_LOCKED))
    _, zl_big, ok_big = regime(2)
    overturned = float(np.mean(~ok_big))
    theta2 = ds.theta2.values
    not_antiphase = ~np.isclose(theta2, -float(ds.attrs["theta1_0"]))
    kept = ok_big & not_antiphase
    only_in = bool(kept.any() and np.all(zl_big[kept] > Z_LOCKED))
    parts = [
        f"no friction/drive: {intermediate:.0%} of θ₂(0) give |z| < {Z_LOCKED} "
        f"(z from {np.nanmin(spread):.2f} to {np.nanmax(spread):.2f})"
        if spread.size
        else "no friction/drive: every run flagged",
        f"M = 6×10⁻⁵: final z > {Z_LOCKED} for {np.mean(zl_small[ok_small] > Z_LOCKED):.0%}, "
        f"< −{Z_LOCKED} for {np.mean(zl_small[ok_small] < -Z_LOCKED):.0%} of θ₂(0)",
        f"M = 6×10⁻⁴: {overturned:.0%} of runs overturn (|θ| > π/2; the pendulums then rotate, "
        f"late max |θ| up to {float(ds.amplitude_late.isel(regime=2).max()):.1f} rad)",
    ]
    for i in range(3, ds.sizes["regime"]):
        _, zl, ok = regime(i)
        parts.append(
            f"{ds.regime.values[i]}: final z > {Z_LOCKED} for {np.mean(zl[ok] > Z_LOCKED):.0%}, "
            f"< −{Z_LOCKED} for {np.mean(zl[ok] < -Z_LOCKED):.0%} of θ₂(0), "
            f"{np.mean(~ok):.0%} overturned"
        )
    sub = [free_ok, both, only_in]
    verdict = (
        "reproduced" if all(sub) else "not reproduced" if not any(sub) else "partly reproduced"
    )
    values = {
        "free_intermediate": intermediate,
        "small_both": both,
        "large_only_in_phase": only_in,
        "large_overturned": overturned,
    }
    return Verdict(5, verdict, "; ".join(parts) + ".", ds.attrs.get("study"), values)


def claim_estimation(ds: xr.Dataset) -> Verdict:
    """Claim 6 from the estimation study: each of c_θ, M and c_φ recovered within tolerance.

    c_θ counts as recovered when both its estimates (trajectory, light gate) are; c_φ
    is judged at the published value with the estimated c_θ and M, as the paper did.
    The refusal or error of each step is quoted, and the disk amplitude's dependence
    on c_φ over the scan is summarized.
    """
    tol = float(ds.attrs["tolerance"])
    ok = {str(p): bool(v) for p, v in zip(ds.parameter.values, ds.recovered.values, strict=True)}
    sub = {
        "c_θ": ok["c_theta (trajectory)"] and ok["c_theta (light gate)"],
        "M": ok["M"],
        "c_φ": ok["c_phi (published)"],
    }
    verdict = (
        "reproduced"
        if all(sub.values())
        else "not reproduced"
        if not any(sub.values())
        else "partly reproduced"
    )

    def found(name: str) -> str:
        row = ds.sel(parameter=name)
        est, err = float(row.estimate), float(row.relative_error)
        if not np.isfinite(est):
            return str(row.outcome.item()).rstrip(".")
        ratio = f"{err:+.1%}" if abs(err) < 1 else f"{est / float(row.true):.3g} × the truth"
        return f"{est:.4g} ({ratio})"

    scan, amp = ds.c_phi.values, ds.disk_amplitude.values
    published = float(ds.true.sel(parameter="c_phi (published)"))
    at_low, at_published = (
        amp[int(np.argmin(np.abs(np.log(scan / c))))] for c in (scan[0], published)
    )
    flat = scan <= 0.1
    numbers = (
        f"Truth: the `{ds.attrs['preset']}` preset, {ds.attrs['bpm']:g} BPM. "
        f"c_θ (true {float(ds.true[0]):.3g} kg m²/s) from a free decay of "
        f"{ds.attrs['decay_duration']:g} s: trajectory extrema "
        f"{found('c_theta (trajectory)')}, light-gate log {found('c_theta (light gate)')}. "
        f"M (true {float(ds.true.sel(parameter='M')):.3g} N m s) from the steady amplitude "
        f"{ds.attrs['steady_amplitude_measured']:.4f} rad with the light-gate c_θ: "
        f"{found('M')}. "
        f"c_φ at the published {published:.3g} kg m²/s (disk amplitude "
        f"{ds.attrs['disk_amplitude_measured']:.6f} rad, N = {ds.attrs['n']}): with the "
        f"estimated c_θ and M the procedure returns {found('c_phi (published)')}; given the "
        f"true c_θ and M: {found('c_phi (published, true c_theta and M)')}. "
        f"Control c_φ = {float(ds.true.sel(parameter='c_phi (control)')):.3g} kg m²/s: "
        f"{found('c_phi (control)')}. "
        f"Disk amplitude against c_φ ({scan[0]:.0e}…{scan[-1]:.0e}, {scan.size} values, "
        f"{ds.attrs['disk_duration']:g} s runs): {at_low:.6f} rad at {scan[0]:.0e}, "
        f"{at_published:.6f} rad at {published:.0e} (relative change "
        f"{abs(at_published / at_low - 1):.1e}); |d ln A / d ln c_φ| ≤ "
        f"{np.nanmax(np.abs(ds.sensitivity.values[flat])):.3f} for c_φ ≤ 0.1, "
        f"{float(ds.sensitivity[-1]):+.2f} at {scan[-1]:g}. "
        f"Recovered means within {tol:.0%}: "
        + ", ".join(f"{k} {'yes' if v else 'no'}" for k, v in sub.items())
        + "."
    )
    values = {
        "recovered": sub,
        "estimate": dict(zip(ok, ds.estimate.values.tolist(), strict=True)),
        "relative_error": dict(zip(ok, ds.relative_error.values.tolist(), strict=True)),
        "disk_amplitude_low": float(at_low),
        "disk_amplitude_published": float(at_published),
    }
    return Verdict(6, verdict, numbers, ds.attrs.get("study"), values)


def _crossing(x, y, level: float) -> float:
    """First x where y rises through ``level`` (linear interpolation); NaN if never."""
    for i in range(len(y) - 1):
        if y[i] < level <= y[i + 1]:
            return float(x[i] + (level - y[i]) * (x[i + 1] - x[i]) / (y[i + 1] - y[i]))
    return float("nan")


def _time_to_reach(time, r, level: float) -> float:
    """First time after which every finite r stays ≥ ``level``; NaN if it never does."""
    finite = np.isfinite(r)
    below = np.nonzero(finite & (r < level))[0]
    if not finite.any() or (below.size and below[-1] >= np.nonzero(finite)[0][-1]):
        return float("nan")
    return float(time[below[-1] + 1]) if below.size else float(time[np.nonzero(finite)[0][0]])


#: Which claim each study checks, by study name.
CHECKS = {
    "fig11": claim_identical,
    "fig8_top": claim_frequency_trend,
    "fig8_bottom": claim_size_trend,
    "fig10": claim_transition,
    "z": claim_z,
    "estimation": claim_estimation,
}
#: The study each claim needs (for "not assessed" when it was not run).
STUDY_OF_CLAIM = {
    1: "fig11",
    2: "fig8_top",
    3: "fig8_bottom",
    4: "fig10",
    5: "z",
    6: "estimation",
}


def all_verdicts(datasets: dict[str, xr.Dataset]) -> list[Verdict]:
    """Verdicts on claims 1–6 from the studies that were run (by study name)."""
    out = []
    for claim, study in STUDY_OF_CLAIM.items():
        if study in datasets:
            out.append(CHECKS[study](datasets[study]))
        else:
            out.append(Verdict(claim, "not assessed", f"the `{study}` study was not run.", study))
    return out

"""Which integrator and step each study of `metrosync reproduce` can run with: measured.

For each study it takes a probe, a few of the study's own ``--full`` points (the same
`simulate` calls: runs, durations, seeds, model changes), and simulates them with the
paper's scheme and step (``verlet``, dt = 0.01 s: the reference) and with each
candidate (``located`` at dt = 0.02 and 0.04 s by default). Per point it prints the
mean equilibrium r over runs, the difference Δ from the reference, the study's
statistical error of that mean (SE = σ_r/√runs of the reference, the error the
report's verdicts and slopes are weighted by) and the CPU seconds of each call.

A candidate is accepted for a study when its r_eq means carry no bias beyond the
study's error, |mean Δ over the probe's points| ≤ the mean SE, and no point differs
by more than 2 SE (the report's significance threshold; errors of opposite sign near
an onset would otherwise cancel in the mean). The cheapest accepted candidate is the study's choice
(`stepping` in `metrosync/paper/studies.py` and `sigma_map.py`). The same draws enter
every scheme, so Δ measures the scheme, not the sampling; its own error (± after each
Δ) is that of the paired differences over runs. ``--runs`` caps the runs a point
(cheaper probes, noisier Δ); the SE stays the study's own.

    python benchmarks/reproduce_accuracy.py                       # every probe
    python benchmarks/reproduce_accuracy.py --only fig10 sigma_map
    python benchmarks/reproduce_accuracy.py --candidates located:0.02 verlet:0.02

CPU time (user + system of this process, all threads) hardly depends on other jobs;
it includes no compilation (each scheme is compiled by a warm-up call first).
"""

from __future__ import annotations

import argparse
import os
import platform
import time
import warnings

import numpy as np

from metrosync import simulate
from metrosync.paper.claims_map import _plan
from metrosync.paper.readings import SCREEN, Reading
from metrosync.paper.runner import PAPER_STEPPING, Stepping
from metrosync.paper.sigma_map import SIGMA_MAP
from metrosync.paper.studies import FIG8_BOTTOM, FIG8_TOP, FIG10, FIG11

#: The candidates tried against the reference, cheapest last.
CANDIDATES = (Stepping("located", 0.02), Stepping("located", 0.04))


def _fig10(spec) -> bool:
    return spec.coords["n"] in (64, 256) and spec.coords["bpm"] in (167.5, 172.5, 177.5)


def _sigma_map(spec) -> bool:
    c = spec.coords
    centre = dict(SIGMA_MAP.centres)[c["tuning"]][SIGMA_MAP.sigmas.index(c["sigma"])]
    return (
        (c["tuning"], c["sigma"]) in {("small-amplitude", 0.75), ("steady-swing", 1.25)}
        and c["n"] == 256
        and abs(c["bpm"] - centre) <= 5.0
    )


def _claims_map_specs():
    """Claim 1–4 screen points of the best-ranked reading other than today's (σ per period,
    steady-swing tuning): the map's other readings run the same studies."""
    reading = Reading(sigma="period", tuning="steady-swing")
    out = []
    for _, claim, _, specs in _plan([reading], SCREEN):
        if claim == 4:
            specs = [s for s in specs if s.coords["n"] == 64 and 160 <= s.coords["bpm"] <= 200]
        if claim < 5:  # the z-study (claim 5) keeps the paper's step (studies.py)
            out.extend(specs if claim in (2, 3, 4) else specs[::2])
    return out


#: Study -> (its probe: some of the study's own --full points, the claims map's from
#: its screen; at most this many runs a point, None: all).
PROBES = {
    "fig8_top": (lambda: FIG8_TOP.points("full"), None),
    "fig8_bottom": (lambda: FIG8_BOTTOM.points("full"), None),
    "fig11": (lambda: FIG11.points("full"), None),
    # N = 64 and 256 around the onset, where a biased step shows most (30 of 100 runs)
    "fig10": (lambda: [s for s in FIG10.points("full") if _fig10(s)], 30),
    "sigma_map": (lambda: [s for s in SIGMA_MAP.points("full") if _sigma_map(s)], None),
    "claims_map": (_claims_map_specs, None),
}


def run(spec, stepping: Stepping, runs: int | None) -> tuple[np.ndarray, float]:
    """Per-run r_eq of ``spec`` simulated with ``stepping`` (its first ``runs`` draws), and
    the CPU seconds it took."""
    kwargs = {**spec.kwargs, **stepping.kwargs(), "progress": False}
    if runs is not None:
        kwargs["runs"] = min(runs, kwargs["runs"])
    started = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(**kwargs)
    return ds.r_eq.values, time.process_time() - started


def label(spec) -> str:
    k = spec.kwargs
    return f"N={k['n']} {k['bpm']:g} BPM σ={k['sigma_bpm']:.3g}"


def warm(steppings) -> None:
    """Compile each scheme in both CPU layouts (runs innermost for N < 10 with 16 runs or
    more, metronomes innermost otherwise), so that no CPU figure includes compiling."""
    for s in steppings:
        for n, runs in ((7, 32), (16, 2)):
            simulate(
                n, 192.0, sigma_bpm=0.75, runs=runs, duration=1.0, progress=False, **s.kwargs()
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=list(PROBES), default=list(PROBES))
    parser.add_argument(
        "--candidates", nargs="+", default=[f"{c.integrator}:{c.dt:g}" for c in CANDIDATES],
        help="integrator:dt pairs tried against verlet:0.01",
    )  # fmt: skip
    parser.add_argument("--points", type=int, default=None, help="at most this many per probe")
    parser.add_argument(
        "--runs", type=int, default=None,
        help="at most this many runs a point, every probe (SE stays the study's: σ_r/√(its runs))",
    )  # fmt: skip
    args = parser.parse_args()
    candidates = [Stepping(c.split(":")[0], float(c.split(":")[1])) for c in args.candidates]
    every = [PAPER_STEPPING, *candidates]
    print(
        f"# {platform.machine()}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f}, {time.strftime('%Y-%m-%d %H:%M')}",
        flush=True,
    )
    warm(every)
    names = " | ".join(f"Δ {c.integrator} {c.dt:g}" for c in candidates)
    summary = []
    for study in args.only:
        probe, cap = PROBES[study]
        specs = probe()[: args.points]
        runs = args.runs if args.runs is not None else cap
        print(f"\n## {study}: {len(specs)} points\n")
        print(f"| point | runs × s | r_eq verlet 0.01 | SE | {names} |")
        print("|---|---|---|---|" + "---|" * len(candidates))
        deltas = np.zeros((len(specs), len(candidates)))
        paired = np.zeros((len(specs), len(candidates)))
        ses = np.zeros(len(specs))
        cpu = np.zeros(len(every))
        for i, spec in enumerate(specs):
            outcomes = [run(spec, s, runs) for s in every]
            ref = outcomes[0][0]
            ses[i] = np.nanstd(ref, ddof=1) / np.sqrt(spec.kwargs["runs"])
            for j, (r, _) in enumerate(outcomes[1:]):
                d = r - ref
                deltas[i, j] = np.nanmean(d)
                paired[i, j] = np.nanstd(d, ddof=1) / np.sqrt(np.isfinite(d).sum())
            cpu += [c for _, c in outcomes]
            cells = " | ".join(
                f"{d:+.3f} ± {e:.3f}" for d, e in zip(deltas[i], paired[i], strict=True)
            )
            k = spec.kwargs
            print(
                f"| {label(spec)} | {ref.size} × {k['duration']:g} | {np.nanmean(ref):.3f} | "
                f"{ses[i]:.3f} | {cells} |",
                flush=True,
            )
        se = max(float(np.mean(ses)), 1e-3)
        verdicts = []
        for j, c in enumerate(candidates):
            bias = float(np.mean(deltas[:, j]))
            bias_err = float(np.sqrt(np.sum(paired[:, j] ** 2)) / len(specs))
            worst = float(np.max(np.abs(deltas[:, j]) / np.maximum(ses, 1e-3)))
            ok = abs(bias) <= se and worst <= 2.0
            verdicts.append((c, ok))
            print(
                f"\n{c.describe()}: mean Δ {bias:+.4f} ± {bias_err:.4f} (study's SE "
                f"{se:.4f}; largest |Δ|/SE {worst:.1f}): "
                f"{'within' if ok else 'outside'} the study's error; CPU "
                f"{cpu[j + 1]:.1f} s against {cpu[0]:.1f} s ({cpu[0] / cpu[j + 1]:.2f}×)",
                flush=True,
            )
        accepted = [(c, cpu[j + 1]) for j, (c, ok) in enumerate(verdicts) if ok]
        best = min(accepted, key=lambda a: a[1])[0] if accepted else PAPER_STEPPING
        summary.append((study, best))
    print("\n## choice per study (cheapest within the error)\n")
    for study, best in summary:
        print(f"- {study}: {best.describe()}")


if __name__ == "__main__":
    main()

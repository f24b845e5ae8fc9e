"""``metrosync simulate``: run an ensemble, print a summary, write NetCDF and a plot."""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from .._words import plural
from ..errors import ParameterError
from ..integrators._cache import compile_seconds
from ..model.tuning import MEANINGS
from ..observables.death import SILENT_PERIODS
from ..plots import plot_order
from ..status import STATUS_STOPPED
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import (
    HelpFormatter,
    add_aliases,
    add_ensemble_options,
    ensemble_defaults,
    path_option,
    simulate_from_args,
)

#: A swinging metronome's period over its small-swing period, at most (the default swing
#: ticks about 4 % slower).
SWING_SLOWER = 1.05

#: Options of the virtual light gate: type, default, help, and the `LightGate` field.
GATE_OPTIONS = {
    "--gate-offset": (float, 0.1, "beam centre angle, rad", "offset"),
    "--gate-width": (float, 0.05, "beam width, rad", "width"),
    "--gate-jitter": (float, 0.0, "timing noise (std), s", "jitter"),
    "--gate-counter-bits": (int, 16, "logger counter width, bits", "counter_bits"),
}


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "simulate",
        help="simulate an ensemble of metronomes",
        description="Simulate B independent runs of N metronomes on a free disk, print "
        "the equilibrium order parameter, and write the dataset, a plot of r(t) and "
        "virtual light-gate logs when asked. The defaults are the paper's experiment "
        "(sigma 0.75 BPM, 20 runs); the Python function metrosync.simulate defaults to one "
        "run of identical metronomes instead, a building block configured by its caller.",
        formatter_class=HelpFormatter,
    )
    add_ensemble_options(parser)
    out = parser.add_argument_group("output")
    out.add_argument("--out", type=path_option, default=None, help="write the dataset to FILE.nc")
    out.add_argument("--plot", type=path_option, default=None,
                     help="write r(t) to FILE.png (or .pdf, .svg, ...)")  # fmt: skip
    gate = parser.add_argument_group("virtual light gate")
    gate.add_argument(
        "--lightgate-dir",
        type=path_option,
        default=None,
        metavar="DIR",
        help="write one light-gate log per run to DIR (simulates recording every step)",
    )
    for flag, (kind, default, text, _) in GATE_OPTIONS.items():
        gate.add_argument(flag, type=kind, default=default, help=text)
    add_aliases(parser, **{name: flag for flag, (*_, name) in GATE_OPTIONS.items()})
    parser.set_defaults(func=run)


def run(args) -> int:
    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    if args.lightgate_dir is None:
        given = [flag for flag, (_, default, *_) in GATE_OPTIONS.items()
                 if getattr(args, flag[2:].replace("-", "_")) != default]  # fmt: skip
        if given:
            raise ParameterError(
                f"`{given[0]}` sets up the virtual light gate; add `--lightgate-dir DIR` "
                f"to write its logs, or drop {', '.join(given)}."
            )
    compiling, started = compile_seconds(), time.perf_counter()
    if args.lightgate_dir is None:
        ds = simulate_from_args(args)
    else:
        ds = _simulate_with_gate(args)
    elapsed = time.perf_counter() - started
    compiling = compile_seconds() - compiling
    print(summary(ds, elapsed, ensemble_defaults(args)[2], compiling=compiling))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_order)
    return 0


def _simulate_with_gate(args):
    """Simulate recording every step, write the logs, then coarsen back to the records asked."""
    from ..lightgate.virtual import LightGate, write_logs
    from ..observables.order import ensemble_statistics, equilibrium_order

    gate = LightGate(offset=args.gate_offset, width=args.gate_width, jitter=args.gate_jitter,
                     counter_bits=args.gate_counter_bits, seed=args.seed)  # fmt: skip
    n, option = (sum(g.n for g in args.groups), "--group") if args.groups else (args.n, "--n")
    if n > 8:
        raise ParameterError(
            f"`--lightgate-dir`: the logger follows at most 8 gates, got {n} metronomes ({option})."
        )
    if args.lightgate_dir.exists() and not args.lightgate_dir.is_dir():
        raise ParameterError(
            f"`--lightgate-dir` {str(args.lightgate_dir)!r} is a file; give a directory."
        )
    check_output(args.lightgate_dir, "--lightgate-dir", folder=True)
    asked = args.save_every
    fine = simulate_from_args(argparse.Namespace(**{**vars(args), "save_every": 1}))
    paths = write_logs(fine, args.lightgate_dir, gate)
    print(f"wrote {len(paths)} light-gate logs to {args.lightgate_dir}")
    every = asked if asked is not None else max(1, int(round(0.1 / args.dt)))
    ds = fine.isel(time=slice(None, None, every))
    if asked is None:
        ds = ds.drop_vars(["theta", "theta_dot", "phi", "phi_dot"])
    # r_eq is a time average: take it again on the coarser records, as a plain run would.
    window = ds.attrs["equilibrium_window"]
    t = ds.time.values
    ds["r_eq"] = ("run", equilibrium_order(ds.r_crossing.values, t, window), ds.r_eq.attrs)
    ds["r_eq_analytic"] = ("run", equilibrium_order(ds.r.values, t, window), ds.r_eq_analytic.attrs)
    mean, spread = ensemble_statistics(ds.r_eq.values)
    ds.attrs.update(r_eq_mean=mean, r_eq_std=spread, record_every=every)
    if "r_group" in ds:
        pairs = (("r_eq_group", "r_crossing_group"), ("r_eq_analytic_group", "r_group"))
        for name, source in pairs:
            value = equilibrium_order(ds[source].values, t, window)
            ds[name] = (("run", "group"), value, ds[name].attrs)
        stats = np.array([ensemble_statistics(v) for v in ds.r_eq_group.values.T])
        ds.attrs.update(r_eq_group_mean=stats[:, 0], r_eq_group_std=stats[:, 1])
    return ds


def _no_phase(ds) -> str:
    """Why no run has r_eq: too short for every metronome's crossing phase in the
    final window, with the duration that would do."""
    a = ds.attrs
    period = SWING_SLOWER * 120.0 / float(ds.frequency_bpm.min())  # two beats a period
    # The first upward crossing comes within the first period, the last within the final
    # one: a window longer than a period, ending at least two periods in, holds a phase.
    return (
        f"r_eq averages the crossing phases over the final window, and a metronome has a "
        f"phase only between two of its upward zero crossings: {a['duration']:g} s with a "
        f"window of {a['equilibrium_window']:g} s is too short for every metronome to cross "
        f"upwards before and after a time in the window (one period is up to {period:.2g} "
        f"s). Give `--duration` of at least {math.ceil(4 * period)} s (the default window is "
        f"the last quarter), and a `--window` longer than one period."
    )


def summary(
    ds, elapsed: float, adapted: dict[str, str] | None = None, *, compiling: float = 0.0
) -> str:
    """The printed summary: frequencies, tick rate, r_eq ± σ_r, flagged runs, throughput.

    adapted : why σ or the run count took an adapted default (`ensemble_defaults`).
    compiling : seconds of ``elapsed`` spent compiling kernels, left out of the throughput.
    """
    from ..observables.order import ensemble_statistics

    a = ds.attrs
    status = ds.status.values
    bad = int((status != 0).sum())
    masks = ds.status.attrs["flag_masks"]
    meanings = ds.status.attrs["flag_meanings"].split()
    flagged = ", ".join(
        f"{int(((status & mask) != 0).sum())} {meaning}"
        for mask, meaning in zip(masks, meanings, strict=True)
    )
    steps = a["runs"] * a["n"] * round(a["duration"] / a["dt"])
    # Say why σ = 0 or one run, where the user did not ask for it.
    adapted = adapted or {}
    sigma = f"sigma={a['sigma_bpm']} BPM" + (f" ({adapted['sigma']})" if "sigma" in adapted else "")
    runs = plural(a["runs"], "run") + (f" ({adapted['runs']})" if "runs" in adapted else "")
    ensemble = (
        f"N={a['n']} in groups {a['groups']} (N@BPM:SIGMA)"
        if "groups" in a
        else f"N={a['n']} at {a['bpm']} BPM, {sigma}"
    )
    lines = [
        f"metrosync simulate: {ensemble}, "
        f"{runs} x {a['duration']:g} s, dt={a['dt']} s, "
        f"preset={a['preset']}, integrator={a['integrator']}",
        f"  natural frequencies (small swing): {float(ds.frequency_bpm.min()):.3f} .. "
        f"{float(ds.frequency_bpm.max()):.3f} BPM",
    ]
    ticks = ds.tick_rate_bpm.values
    if np.isfinite(ticks).any():
        lines.append(
            f"  tick rate (measured over the last {a['tick_rate_span']:g} s): "
            f"{np.nanmin(ticks):.2f} .. {np.nanmax(ticks):.2f} per minute "
            f"({a['tuning']} tuning: {MEANINGS[a['tuning']]})"
        )
    window = f"  equilibrium r (last {a['equilibrium_window']:g} s, crossing phases)"
    ok = status == 0
    measured = ok & np.isfinite(ds.r_eq.values)
    if ok.any() and not measured.any():
        lines.append(f"{window}: not measured. {_no_phase(ds)}")
    elif bad == 0 and measured.all():
        lines.append(f"{window}: {a['r_eq_mean']:.4f} +- {a['r_eq_std']:.4f} (sigma_r over runs)")
    elif ok.any():
        mean, spread = ensemble_statistics(ds.r_eq.values[ok])
        kind = "unflagged run" if bad else "run"
        over = plural(int(ok.sum()), kind)
        if not measured.all():
            over = f"{int(measured.sum())} of the {over} that have a crossing phase in the window"
        lines.append(f"{window}: {mean:.4f} +- {spread:.4f} (sigma_r over the {over})")
    else:
        lines.append(f"{window}: not meaningful, every run is flagged")
    if "r_eq_group" in ds and ok.any():
        for g, label in enumerate(str(a["groups"]).split()):
            mean, spread = ensemble_statistics(ds.r_eq_group.values[ok, g])
            lines.append(f"    group {g} ({label}): {mean:.4f} +- {spread:.4f}")
    if ok.any():
        final = float(ds.r.isel(time=-1).values[ok].mean())
        lines.append(f"  final r (analytic phase), mean over unflagged runs: {final:.4f}")
    lines.append(f"  runs flagged: {bad} of {a['runs']}" + (f" ({flagged})" if bad else ""))
    if bad:
        lines.append(
            f"    the r of {'every flagged run' if bad > 1 else 'the flagged run'} is not "
            f"meaningful (see `status` in the dataset; bits in metrosync.status)"
        )
    stopped = int(((status & STATUS_STOPPED) != 0).sum())
    if stopped:
        lines.append(
            f"    stopped: in {plural(stopped, 'run')} some metronome's escapement gave no "
            f"impulse in its last {SILENT_PERIODS:g} periods: its swing no longer reaches the "
            f'escapement, so nothing drives it and it decays ("metronome death", '
            f"Goldsztein et al., Chaos 32, 043119 (2022)); decaying pendulums can look in "
            f"step, so these runs are left out of r above"
        )
    if "disk_at_rest" in ds:
        rest = 100 * ds.disk_at_rest.values
        lines.append(
            f"  {a.get('platform', 'disk')} held at rest by dry friction: {np.mean(rest):.0f} % "
            f"of the final "
            f"{a['equilibrium_window']:g} s (mean over runs; {np.min(rest):.0f} .. "
            f"{np.max(rest):.0f} %)"
        )
    if str(a.get("record_every_reason", "")).startswith("raised"):
        lines.append(
            f"  r(t) recorded every {a['record_interval']:g} s "
            f"({plural(a['record_every'], 'step')}), {a['record_every_reason']}"
        )
    compiled = f" ({compiling:.1f} s of it compiling kernels, once)" if compiling >= 0.5 else ""
    rate = steps / max(elapsed - compiling, 1e-9)
    lines.append(f"  {elapsed:.2f} s wall{compiled}, {rate:.3g} oscillator-steps/s")
    return "\n".join(lines)

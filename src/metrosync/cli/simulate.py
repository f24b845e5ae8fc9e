"""``metrosync simulate``: run an ensemble, print a summary, write NetCDF and a plot."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..errors import ParameterError
from ..plots import plot_order
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import HelpFormatter, add_aliases, add_ensemble_options, simulate_from_args

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
        "virtual light-gate logs when asked.",
        formatter_class=HelpFormatter,
    )
    add_ensemble_options(parser)
    out = parser.add_argument_group("output")
    out.add_argument("--out", type=Path, default=None, help="write the dataset to FILE.nc")
    out.add_argument("--plot", type=Path, default=None,
                     help="write r(t) to FILE.png (or .pdf, .svg, ...)")  # fmt: skip
    gate = parser.add_argument_group("virtual light gate")
    gate.add_argument(
        "--lightgate-dir",
        type=Path,
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
    started = time.perf_counter()
    if args.lightgate_dir is None:
        ds = simulate_from_args(args)
    else:
        ds = _simulate_with_gate(args)
    elapsed = time.perf_counter() - started
    print(summary(ds, elapsed))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_order)
    return 0


def _simulate_with_gate(args):
    """Simulate recording every step, write the logs, then coarsen back to the records asked."""
    from ..lightgate.virtual import LightGate, write_logs
    from ..observables.order import ensemble_statistics, equilibrium_order

    gate = LightGate(offset=args.gate_offset, width=args.gate_width, jitter=args.gate_jitter,
                     counter_bits=args.gate_counter_bits, seed=args.seed)  # fmt: skip
    if args.n > 8:
        raise ParameterError(
            f"`--lightgate-dir`: the logger follows at most 8 gates, got --n {args.n}."
        )
    if args.lightgate_dir.exists() and not args.lightgate_dir.is_dir():
        raise ParameterError(
            f"`--lightgate-dir` {str(args.lightgate_dir)!r} is a file; give a directory."
        )
    check_output(args.lightgate_dir / "run000.log", "--lightgate-dir")
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
    return ds


def summary(ds, elapsed: float) -> str:
    """The printed summary: frequencies, r_eq ± σ_r, flagged runs, throughput."""
    a = ds.attrs
    bad = int((ds.status != 0).sum())
    masks = ds.status.attrs["flag_masks"]
    meanings = ds.status.attrs["flag_meanings"].split()
    flagged = ", ".join(
        f"{int(((ds.status & mask) != 0).sum())} {meaning}"
        for mask, meaning in zip(masks, meanings, strict=True)
    )
    steps = a["runs"] * a["n"] * round(a["duration"] / a["dt"])
    lines = [
        f"metrosync simulate: N={a['n']} at {a['bpm']} BPM, sigma={a['sigma_bpm']} BPM, "
        f"{a['runs']} runs x {a['duration']:g} s, dt={a['dt']} s, preset={a['preset']}, "
        f"integrator={a['integrator']}",
        f"  natural frequencies: {float(ds.frequency_bpm.min()):.3f} .. "
        f"{float(ds.frequency_bpm.max()):.3f} BPM",
        f"  equilibrium r (last {a['equilibrium_window']:g} s, crossing phases): "
        f"{a['r_eq_mean']:.4f} +- {a['r_eq_std']:.4f} (sigma_r over runs)",
        f"  final r (analytic phase), mean over runs: {float(ds.r.isel(time=-1).mean()):.4f}",
        f"  runs flagged: {bad} of {a['runs']}" + (f" ({flagged})" if bad else ""),
        f"  {elapsed:.2f} s wall, {steps / max(elapsed, 1e-9):.3g} oscillator-steps/s",
    ]
    if str(a.get("record_every_reason", "")).startswith("raised"):
        lines.append(
            f"  r(t) recorded every {a['record_interval']:g} s ({a['record_every']} steps), "
            f"{a['record_every_reason']}"
        )
    return "\n".join(lines)

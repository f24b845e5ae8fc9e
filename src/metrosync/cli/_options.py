"""Argument types and option groups shared by several subcommands."""

from __future__ import annotations

import argparse
import math


def float_list(text: str) -> list[float]:
    """Parse a comma-separated list of numbers, e.g. ``0.1,-0.05``."""
    try:
        values = [float(item) for item in text.split(",") if item.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None
    if not values or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r}")
    return values


def add_ensemble_options(parser: argparse.ArgumentParser) -> None:
    """Options that define an ensemble run, shared by `simulate` and friends."""
    g = parser.add_argument_group("ensemble")
    g.add_argument("--n", type=int, default=7, help="metronomes on the disk (default 7)")
    g.add_argument(
        "--bpm", type=float, default=192.0, help="nominal beat frequency, BPM (default 192)"
    )
    g.add_argument(
        "--sigma",
        type=float,
        default=0.75,
        help="spread of natural frequencies, BPM (default 0.75)",
    )
    g.add_argument("--runs", type=int, default=20, help="independent runs (default 20)")
    g.add_argument("--duration", type=float, default=600.0, help="simulated time, s (default 600)")
    g.add_argument("--dt", type=float, default=0.01, help="time step, s (default 0.01)")
    g.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    g.add_argument("--preset", default="default", help="parameter preset (see `metrosync presets`)")
    g.add_argument(
        "--set",
        dest="changes",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change one model parameter, e.g. --set drive=1e-4 (repeatable)",
    )
    g.add_argument("--integrator", choices=("verlet", "exact"), default="verlet")
    g.add_argument("--backend", choices=("numba", "numpy", "gpu"), default="numba",
                   help="numba (CPU), numpy (plain reference) or gpu (NVIDIA, CUDA)")  # fmt: skip
    g.add_argument(
        "--amplitude", type=float, default=None, help="start amplitude, rad (random phases)"
    )
    g.add_argument(
        "--theta0", type=float_list, default=None, help="initial angles, comma-separated, rad"
    )
    g.add_argument(
        "--theta-dot0", type=float_list, default=None, help="initial angular velocities, rad/s"
    )
    g.add_argument("--save-every", type=int, default=None, metavar="K",
                   help="record every K steps and keep trajectories")  # fmt: skip


def parse_changes(items: list[str]) -> dict[str, float]:
    from ..errors import ParameterError

    changes = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            changes[name.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep:
            raise ParameterError(f"`--set` expects NAME=VALUE with a number, got {item!r}.")
    return changes


def simulate_from_args(args, **extra):
    """Run `metrosync.simulate` with the ensemble options of ``args``."""
    from ..simulate import simulate

    return simulate(
        args.n,
        args.bpm,
        sigma_bpm=args.sigma,
        runs=args.runs,
        duration=args.duration,
        dt=args.dt,
        seed=args.seed,
        preset=args.preset,
        changes=parse_changes(args.changes) or None,
        integrator=args.integrator,
        backend=args.backend,
        amplitude=args.amplitude,
        theta0=args.theta0,
        theta_dot0=args.theta_dot0,
        record_every=args.save_every,
        trajectories=args.save_every is not None,
        **extra,
    )

"""Argument types, the help layout and the option groups shared by several subcommands.

Library functions name their arguments in Python (``sigma_bpm``, ``record_every``);
where an option sets such an argument under another name (``--sigma``,
``--save-every``), the subcommand declares it with `add_aliases`, and `metrosync.cli.main`
adds the option to any error message that names the argument.
"""

from __future__ import annotations

import argparse
import math
import warnings

from ..errors import ParameterError
from ..integrators import BACKENDS, REGISTRY, get_integrator, integrator_names


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows each option's default, unless there is none to show (None, off, empty)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        default = action.default
        if default is None or default is False or (isinstance(default, list) and not default):
            return action.help
        return super()._get_help_string(action)


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


def int_list(text: str) -> list[int]:
    """Parse a comma-separated list of whole numbers, e.g. ``0,2``."""
    try:
        values = [int(item) for item in text.split(",") if item.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated whole numbers such as 0,2, got {text!r}"
        ) from None
    if not values:
        raise argparse.ArgumentTypeError(f"expected at least one number, got {text!r}")
    return values


def add_aliases(parser: argparse.ArgumentParser, **names: str) -> None:
    """Declare library argument names set by options of another name (for errors)."""
    parser.set_defaults(_aliases={**(parser.get_default("_aliases") or {}), **names})


def add_ensemble_options(parser: argparse.ArgumentParser, *, runs: int = 20) -> None:
    """Options that define an ensemble run, shared by `simulate` and friends."""
    g = parser.add_argument_group("ensemble")
    g.add_argument("--n", type=int, default=7, help="metronomes on the disk")
    g.add_argument("--bpm", type=float, default=192.0, help="nominal beat frequency, BPM")
    g.add_argument(
        "--sigma", type=float, default=0.75, help="spread (std) of the natural frequencies, BPM"
    )
    g.add_argument("--runs", type=int, default=runs, help="independent runs")
    g.add_argument("--duration", type=float, default=600.0, help="simulated time, s")
    g.add_argument("--dt", type=float, default=0.01, help="time step, s")
    g.add_argument("--seed", type=int, default=0, help="random seed")
    g.add_argument("--preset", default="default", help="parameter preset (see `metrosync presets`)")
    g.add_argument(
        "--set",
        dest="changes",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change one model parameter, e.g. --set drive=1e-4 (repeatable)",
    )
    g.add_argument(
        "--integrator",
        choices=integrator_names(),
        default=integrator_names()[0],
        help="; ".join(f"{i.name}: {i.summary}" for i in REGISTRY.values()),
    )
    g.add_argument(
        "--backend",
        choices=tuple(BACKENDS),
        default=None,
        help="for a fixed-step integrator: "
        + "; ".join(f"{name}: {what}" for name, what in BACKENDS.items())
        + " (default: numba)",
    )
    g.add_argument(
        "--amplitude",
        type=float,
        default=None,
        help="start amplitude, rad, at random phases (default: the steady swing)",
    )
    g.add_argument(
        "--theta0",
        type=float_list,
        default=None,
        metavar="A,B,...",
        help="initial angles of the metronomes, rad",
    )
    g.add_argument(
        "--theta-dot0",
        type=float_list,
        default=None,
        metavar="A,B,...",
        help="initial angular velocities, rad/s",
    )
    g.add_argument(
        "--window",
        type=float,
        default=None,
        metavar="S",
        help="final window averaged for r_eq, s (default: the last quarter)",
    )
    g.add_argument(
        "--save-every",
        type=int,
        default=None,
        metavar="K",
        help="record every K steps and keep the trajectories",
    )
    add_aliases(
        parser,
        sigma_bpm="--sigma",
        record_every="--save-every",
        equilibrium_window="--window",
        changes="--set",
    )


def parse_changes(items: list[str]) -> dict[str, float]:
    """``--set NAME=VALUE`` items as a dict of numbers."""
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

    if args.backend is not None and not get_integrator(args.integrator).fixed_step:
        warnings.warn(
            f"`--backend {args.backend}` applies to `--integrator verlet` only; "
            f"`--integrator {args.integrator}` ignores it.",
            UserWarning,
            stacklevel=2,
        )
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
        backend=args.backend or "numba",
        amplitude=args.amplitude,
        theta0=args.theta0,
        theta_dot0=args.theta_dot0,
        record_every=args.save_every,
        trajectories=args.save_every is not None,
        equilibrium_window=args.window,
        **extra,
    )

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
from pathlib import Path

from ..capabilities import describe_lacks
from ..errors import ParameterError
from ..groups import Group, parse_group
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


def path_option(text: str) -> Path:
    """Parse a file or folder option: any path but an empty one, which `Path` would
    read as the current folder (``--out ""`` would write there without saying so)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"expected a path, got {text!r}")
    return Path(text)


def seed(text: str) -> int:
    """Parse a random seed: a whole number from 0 up, as NumPy's generators take."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number such as 0 or 7, got {text!r}"
        ) from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"a seed is a whole number from 0 up, got {value}")
    return value


def positive_seconds(text: str) -> float:
    """Parse a time in seconds that must be finite and > 0, e.g. ``--window 2.5``.

    Refused while the arguments are parsed, so that a window or a spacing that no input
    could use stops a command before it reads anything (`track` would otherwise decode
    a whole video first). Whether it fits a particular input is the command's check.
    """
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(
            f"expected a time in seconds, finite and > 0, such as 0.5; got {text!r}"
        )
    return value


def group_spec(text: str) -> Group:
    """Parse ``--group N@BPM[:SIGMA]`` (see `metrosync.groups.parse_group`)."""
    try:
        return parse_group(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


class GivenOption(argparse.Action):
    """Store the value and note that the option was given on the command line, in
    ``args._given``, for options that another one replaces (``--n`` beside ``--group``)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        namespace._given = {*getattr(namespace, "_given", ()), option_string}


def add_aliases(parser: argparse.ArgumentParser, **names: str) -> None:
    """Declare library argument names set by options of another name (for errors)."""
    parser.set_defaults(_aliases={**(parser.get_default("_aliases") or {}), **names})


#: The command line's spread of natural frequencies, BPM: the paper's σ (Tables 1–2).
#: `metrosync.simulate` defaults to 0 instead (see its docstring).
CLI_SIGMA_BPM = 0.75


def add_ensemble_options(parser: argparse.ArgumentParser, *, runs: int = 20) -> None:
    """Options that define an ensemble run, shared by `simulate` and friends.

    ``--sigma`` and ``--runs`` default to None and are resolved by `ensemble_defaults`:
    one metronome, or explicit initial conditions, imply σ = 0 (and one run) unless given.
    """
    g = parser.add_argument_group("ensemble")
    g.add_argument("--n", type=int, default=7, action=GivenOption,
                   help="metronomes on the disk")  # fmt: skip
    g.add_argument("--bpm", type=float, default=192.0, action=GivenOption,
                   help="nominal beat frequency, BPM; it tunes the small-swing frequency, so "
                   "at the default swing a metronome ticks slower (192 BPM: about 184.6 "
                   "ticks a minute)")  # fmt: skip
    g.add_argument(
        "--sigma", type=float, default=None,
        help=f"spread (std) of the natural frequencies, BPM (default: {CLI_SIGMA_BPM}, the "
        f"paper's; 0 with --n 1 or --theta0)",
    )  # fmt: skip
    g.add_argument(
        "--group",
        dest="groups",
        type=group_spec,
        action="append",
        default=None,
        metavar="N@BPM[:SIGMA]",
        help="a group of N metronomes at BPM with spread SIGMA (else --sigma); repeat "
        "for several groups, e.g. --group 7@184 --group 7@200:0.5. Replaces --n and --bpm",
    )
    more = "; 1 with --n 1 or --theta0" if runs > 1 else ""
    g.add_argument("--runs", type=int, default=None,
                   help=f"independent runs (default: {runs}{more})")  # fmt: skip
    parser.set_defaults(_runs_default=runs)
    g.add_argument("--duration", type=float, default=600.0, help="simulated time, s")
    g.add_argument("--dt", type=float, default=0.01, help="time step, s")
    g.add_argument("--seed", type=seed, default=0, help="random seed")
    g.add_argument("--preset", default="default", help="parameter preset (see `metrosync presets`)")
    add_platform_option(g)
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
        help="; ".join(
            f"{i.name}: {i.summary}" + (f" ({lacks})" if (lacks := describe_lacks(i.name)) else "")
            for i in REGISTRY.values()
        ),
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
        l2_bounds="--set l2_bounds=LOW,HIGH",
        l1="--set l1=METRES",
        groups="--group",
    )


def ensemble_defaults(args) -> tuple[float, int, dict[str, str]]:
    """σ (BPM) and runs for ``args``, and ``{"sigma": why, "runs": why}`` for each
    default that was adapted.

    A single metronome has no spread to draw and no phase to differ by, and explicit
    initial conditions (``--theta0``) describe one experiment: both take σ = 0 and one
    run unless given, rather than silently drawing frequencies and repeating the start.
    """
    why = ""
    if args.theta0 is not None:
        why = "explicit --theta0"
    elif args.n == 1:
        why = "one metronome"
    sigma = args.sigma if args.sigma is not None else (0.0 if why else CLI_SIGMA_BPM)
    runs = args.runs if args.runs is not None else (1 if why else args._runs_default)
    adapted = {name: why for name in ("sigma", "runs") if why and getattr(args, name) is None}
    return sigma, runs, adapted


#: Model parameters that take two numbers (``--set l2_bounds=0,0.12``).
PAIR_PARAMETERS = ("l2_bounds",)


def add_platform_option(group) -> None:
    """``--platform``, beside every ``--preset``: the same as ``--set platform=NAME``."""
    from ..model.platform import PLATFORMS

    group.add_argument(
        "--platform",
        choices=PLATFORMS,
        default=None,
        help="what carries the metronomes: the paper's rotating disk, or a board on rollers "
        "(Pantaleone 2002); the same as --set platform=NAME (default: the preset's)",
    )


def model_changes(args) -> dict[str, float | tuple[float, ...] | str]:
    """The model changes of ``--set`` items and ``--platform``, which must agree."""
    changes = parse_changes(args.changes)
    platform = getattr(args, "platform", None)
    given = changes.get("platform")
    if platform is not None and given is not None and given != platform:
        raise ParameterError(
            f"`--platform {platform}` and `--set platform={given}` disagree; give the platform "
            f"once."
        )
    if platform is not None:
        changes["platform"] = platform
    return changes


def parse_changes(items: list[str]) -> dict[str, float | tuple[float, ...] | str]:
    """``--set NAME=VALUE`` items as a dict of numbers; ``A,B`` gives a pair
    (``--set l2_bounds=0,0.12``) and ``tuning`` and ``platform`` take a name."""
    from ..model import MetronomeDesign, Platform
    from ..model.quantity import named

    choices = named(MetronomeDesign, Platform)
    changes: dict[str, float | tuple[float, ...] | str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if name.strip() in choices and sep:
            allowed = choices[name.strip()]
            if value.strip() not in allowed:
                raise ParameterError(
                    f"`--set {name.strip()}` takes one of {list(allowed)}, got {value.strip()!r}."
                )
            changes[name.strip()] = value.strip()
            continue
        try:
            parts = [float(part) for part in value.split(",")]
        except ValueError:
            sep = ""
        if not sep:
            raise ParameterError(
                f"`--set` expects NAME=VALUE with a number (or LOW,HIGH for `l2_bounds`), "
                f"got {item!r}."
            )
        name = name.strip()
        pair = name in PAIR_PARAMETERS
        if len(parts) != (2 if pair else 1):
            want = "two numbers LOW,HIGH" if pair else "one number"
            raise ParameterError(f"`--set {name}` takes {want}, got {value!r}.")
        changes[name] = tuple(parts) if pair else parts[0]
    return changes


def simulate_from_args(args, **extra):
    """Run `metrosync.simulate` with the ensemble options of ``args``."""
    from ..simulate import simulate

    groups = getattr(args, "groups", None)
    if groups:
        given = sorted(getattr(args, "_given", ()))
        if given:
            raise ParameterError(
                f"`--group` sets the number and BPM of each group's metronomes; drop "
                f"{' and '.join(given)} (the total N is the sum of the groups')."
            )
    if args.backend is not None and not get_integrator(args.integrator).fixed_step:
        warnings.warn(
            f"`--backend {args.backend}` applies to `--integrator verlet` only; "
            f"`--integrator {args.integrator}` ignores it.",
            UserWarning,
            stacklevel=2,
        )
    sigma, runs, _ = ensemble_defaults(args)
    return simulate(
        None if groups else args.n,
        None if groups else args.bpm,
        sigma_bpm=sigma,
        groups=groups or None,
        runs=runs,
        duration=args.duration,
        dt=args.dt,
        seed=args.seed,
        preset=args.preset,
        changes=model_changes(args) or None,
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

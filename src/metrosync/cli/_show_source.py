"""The input shared by `animate`, `listen` and `page`: a file, or a fresh simulation.

A subcommand either reads a NetCDF file written by ``metrosync simulate --save-every
K --out FILE.nc`` or simulates with the same options as ``simulate``, always keeping
trajectories (one run by default, since one run is shown). Giving both a file and
simulation options is an error, not a silent choice.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from ..errors import ParameterError
from ._io import read_dataset
from ._options import (
    add_aliases,
    add_ensemble_options,
    ensemble_defaults,
    path_option,
    simulate_from_args,
)


def add_source_options(parser: argparse.ArgumentParser, *, record_seconds: float | None) -> None:
    """Add the input file, the ensemble options and ``--run``, ``--start``, ``--end``.

    record_seconds : recording interval used when simulating without ``--save-every``;
        None records every step.
    """
    parser.add_argument(
        "input",
        nargs="?",
        type=path_option,
        default=None,
        help="NetCDF file from `metrosync simulate --save-every K --out FILE.nc`; "
        "without it, simulate with the options below",
    )
    before = set(vars(parser.parse_args([])))
    add_ensemble_options(parser, runs=1)
    ensemble = sorted(
        name for name in set(vars(parser.parse_args([]))) - before if not name.startswith("_")
    )
    parser.set_defaults(_ensemble_defaults={k: parser.get_default(k) for k in ensemble},
                        _record_seconds=record_seconds)  # fmt: skip
    shown = parser.add_argument_group("what to show")
    shown.add_argument("--run", type=int, default=0, help="which run of the ensemble")
    shown.add_argument("--start", type=float, default=None, help="start of the time window, s")
    shown.add_argument("--end", type=float, default=None, help="end of the time window, s")
    add_aliases(parser, run="--run", start="--start", end="--end")


def load_or_simulate(args, check: Callable[[float, float], None] | None = None):
    """The dataset to show: read ``args.input``, or simulate from the ensemble options.

    check : the command's own check of the window [start, end] (s) it will show, called
        before simulating (a file's window is checked by the library once it is read).
    """
    if args.input is not None:
        changed = [
            name
            for name, default in args._ensemble_defaults.items()
            if getattr(args, name) != default
        ]
        if changed:
            flag = args._aliases  # --set fills `changes`
            options = ", ".join(flag.get(name, "--" + name.replace("_", "-")) for name in changed)
            raise ParameterError(
                f"give either an input file or simulation options, not both "
                f"(got {str(args.input)!r} and {options})."
            )
        return read_dataset(args.input)
    check_before_simulating(args, check)
    if args.save_every is None:
        seconds = args._record_seconds
        # A bad --dt is reported by `simulate`; it must not break this arithmetic first.
        usable = seconds is not None and args.dt > 0 and args.dt < float("inf")
        args.save_every = max(1, round(seconds / args.dt)) if usable else 1
    return simulate_from_args(args)


def check_before_simulating(args, check: Callable[[float, float], None] | None = None) -> None:
    """Refuse what the options already make impossible, before anything is simulated.

    What a simulation will hold follows from the options: ``--runs`` runs (or its
    default) over [0, ``--duration``] s. ``--run``, ``--start`` and ``--end`` are checked
    against them with the checks the library makes on a recording, then ``check`` runs
    on the window. A bad ``--runs`` or ``--duration`` is left to `simulate`, which says
    what is wrong with it.
    """
    from ..show.recording import check_run, check_window

    _, runs, _ = ensemble_defaults(args)
    if isinstance(runs, int) and runs >= 1:
        check_run(args.run, runs)
    duration = args.duration
    if not (isinstance(duration, int | float) and 0 < duration < float("inf")):
        return
    start, end = check_window(args.start, args.end, 0.0, float(duration))
    if check is not None:
        check(start, end)

"""``metrosync sweep``: run a parameter grid, resumably, in process or on Dask."""

from __future__ import annotations

import argparse

from .._words import plural
from ..errors import ParameterError
from ._io import NETCDF, check_output
from ._options import HelpFormatter, add_aliases, add_platform_option, group_spec, path_option

#: Options that take a value or a grid (``a:b:step`` or ``x,y,z``), and their parameter.
GRID_OPTIONS = {
    "n": "metronomes on the disk",
    "bpm": "nominal beat frequency, BPM",
    "sigma": "spread of natural frequencies, BPM",
    "runs": "independent runs per point",
    "duration": "simulated time, s",
    "dt": "time step, s",
    "seed": "sweep seed (a list gives independent replicas)",
    "amplitude": "start amplitude at random phases, rad (default: the steady swing "
    "2M/(pi c_theta); needed where --drive is 0)",
    "drive": "escapement impulse M, N m s",
    "c-theta": "pendulum friction, kg m2/s",
    "c-phi": "disk friction, kg m2/s",
    "inertia": "disk inertia J, kg m2 (inf pins the disk)",
    "group-offset-bpm": "BPM added to every --group after the first",
}


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help="run a parameter grid (resumable; in process or on a Dask cluster)",
        description=(
            "Run one ensemble simulation per grid point and merge them into one NetCDF file "
            "with a dimension per swept parameter. Give a value (fixed) or a grid "
            "(START:STOP:STEP or a comma list) to any parameter option, and/or a TOML grid "
            "file. Finished points are kept in the store, so running the same command again "
            "after an interruption computes only what is missing. Exit code 1 when some "
            "point has no result (failed, or lost with a worker)."
        ),
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "grid", nargs="?", type=path_option, help="TOML grid file ([grid], [fixed])"
    )
    g = parser.add_argument_group("parameters (VALUE or START:STOP:STEP or A,B,C)")
    for name, text in GRID_OPTIONS.items():
        g.add_argument(f"--{name}", metavar="SPEC", default=None, help=text)
    g.add_argument("--set", dest="changes", action="append", default=[], metavar="NAME=SPEC",
                   help="any model parameter, e.g. --set l1=0.035 (repeatable)")  # fmt: skip
    g.add_argument("--preset", default=None, help="parameter preset (default: 'default')")
    add_platform_option(g)
    g.add_argument("--group", dest="groups", type=group_spec, action="append", default=None,
                   metavar="N@BPM[:SIGMA]",
                   help="a group of N metronomes at BPM (repeat for several; replaces --n "
                   "and --bpm); sweep --group-offset-bpm to move the groups apart")  # fmt: skip
    a = parser.add_argument_group("runs until the error is small enough")
    a.add_argument(
        "--target-error",
        type=target_error,
        default=None,
        metavar="SE",
        help="run each point in batches of --runs until the standard error of its "
        "mean r_eq is at most SE (e.g. 0.01); 'none' turns a grid file's off",
    )
    a.add_argument(
        "--max-runs",
        type=int,
        default=None,
        metavar="RUNS",
        help="most runs a point grows to with --target-error (default: 8 x --runs)",
    )
    o = parser.add_argument_group("run")
    o.add_argument("--out", type=path_option, required=True, help="merged result, FILE.nc")
    o.add_argument("--store", type=path_option, default=None,
                   help="finished points directory (default: OUT with suffix .points)")  # fmt: skip
    o.add_argument("--keep-r", action="store_true", help="also keep r(t) of every run")
    o.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run on a Dask LocalCluster or an existing Dask scheduler")  # fmt: skip
    o.add_argument("--workers", type=int, default=None, help="workers of --scheduler local")
    o.add_argument("--retry-failed", action="store_true", help="recompute points stored as failed")
    o.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_aliases(parser, sigma_bpm="--sigma", n_workers="--workers", scheduler="--scheduler",
                groups="--group", n="--n", bpm="--bpm",
                group_offset_bpm="--group-offset-bpm", target_error="--target-error",
                max_runs="--max-runs")  # fmt: skip
    parser.set_defaults(func=run)


#: ``--target-error none``: a grid file's target turned off (runs fixed by --runs).
NO_TARGET = object()


def target_error(text: str):
    """``--target-error``: a standard error, or ``none``."""
    if text.strip().lower() == "none":
        return NO_TARGET
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"takes a standard error such as 0.01, or none; got {text!r}"
        ) from None


def grid_from_args(args):
    """The `Grid` from the grid file and the options (an option replaces the file's value)."""
    from ..sweeps.grid import Grid, canonical_name

    axes, fixed = {}, {}
    items = [
        (name.replace("-", "_"), getattr(args, name.replace("-", "_"))) for name in GRID_OPTIONS
    ]
    for item in args.changes:
        name, sep, spec = item.partition("=")
        if not sep or not spec.strip():
            raise ParameterError(f"`--set` expects NAME=SPEC, got {item!r}.")
        items.append((name.strip(), spec.strip()))
    items.append(("platform", args.platform))
    given: dict[str, str] = {}
    for name, spec in items:
        if spec is None:
            continue
        name = canonical_name(name)
        if name in given:
            raise ParameterError(
                f"`{name}` is given twice ({given[name]!r} and {spec!r}, by an option and "
                f"`--set`); keep one."
            )
        given[name] = spec
        (axes if (":" in spec or "," in spec) else fixed)[name] = spec
    options = {"keep_r": True} if args.keep_r else {}
    if args.preset is not None:
        options["preset"] = args.preset
    if args.groups:
        options["groups"] = args.groups
    if args.target_error is NO_TARGET:  # a grid file's target and cap, both off
        options.update(target_error=None, max_runs=args.max_runs)
    elif args.target_error is not None:
        options["target_error"] = args.target_error
    if args.max_runs is not None:
        options["max_runs"] = args.max_runs
    if args.grid is not None:
        return Grid.from_toml(args.grid, axes=axes, fixed=fixed, **options)
    if not axes:
        raise ParameterError(
            "nothing to sweep: give a grid file or a grid to some option, e.g. --bpm 150:220:2.5."
        )
    return Grid(axes=axes, fixed=fixed, **options)


def run(args) -> int:
    from ..sweeps import sweep
    from ..sweeps.executors import check_scheduler

    check_output(args.out, "--out", suffixes=NETCDF)
    check_scheduler(args.scheduler, args.workers)
    grid = grid_from_args(args)
    store = args.store if args.store is not None else args.out.with_suffix(".points")
    check_output(store, "--store", folder=True)
    shape = dict(zip(grid.axes, grid.shape, strict=True))
    print(f"metrosync sweep: {plural(grid.size, 'point')}, grid {shape}, store {store}", flush=True)
    result = sweep(
        grid,
        store,
        out=args.out,
        scheduler=args.scheduler,
        n_workers=args.workers,
        progress=False if args.no_progress else None,
        retry_failed=args.retry_failed,
    )
    print(result.summary())
    return 1 if result.failures() else 0

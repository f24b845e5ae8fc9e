"""``metrosync reproduce``: every simulation figure and claim of the paper, and REPORT.md."""

from __future__ import annotations

import sys
from pathlib import Path

from ..errors import ParameterError
from ._options import add_aliases, path_option


def register(subparsers) -> None:
    from ..paper.names import MEASURED_COST, STUDY_NAMES

    parser = subparsers.add_parser(
        "reproduce",
        help="reproduce the paper's figures and check its claims",
        description="Run the paper's simulation studies, write NetCDF data, PNG/PDF figures "
        "and REPORT.md with a verdict on each claim. Finished simulations are kept under "
        "OUT/points/, keyed by their fully resolved parameters, the metrosync version and "
        "the simulation code, so an interrupted run resumes and a changed model is "
        "recomputed. Exit code 1 when a simulation failed or was lost with a worker.",
    )
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument(
        "--quick",
        dest="mode",
        action="store_const",
        const="quick",
        help=f"reduced statistics (the default); {MEASURED_COST['quick']}",
    )
    mode.add_argument(
        "--full",
        dest="mode",
        action="store_const",
        const="full",
        help=f"the paper's statistics (100 runs a point); {MEASURED_COST['full']}. "
        "REPORT.md estimates it for the machine it runs on",
    )
    parser.set_defaults(mode="quick")
    parser.add_argument(
        "--out", type=path_option, default=Path("results"), help="output folder (default: results)"
    )
    parser.add_argument(
        "--experiment",
        type=path_option,
        default=None,
        metavar="DIR",
        help="light-gate logs, one folder per ω₀ named by its BPM (adds Fig. 9)",
    )
    parser.add_argument(
        "--large-n",
        type=path_option,
        nargs="+",
        default=(),
        metavar="SWEEP",
        help="merged sweeps of the large-N study (studies/large_n/*.toml), the paper's sigma "
        "first: adds its section, and claim 4's check of where the transition sits comes "
        "from it",
    )
    parser.add_argument(
        "--only",
        nargs="+",
        default=None,
        metavar="STUDY",
        choices=list(STUDY_NAMES),
        help="run only these studies",
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="local|tcp://HOST:PORT",
        help="run the simulations on a Dask LocalCluster or an existing Dask scheduler "
        "(as `metrosync sweep`; default: in process)",
    )
    parser.add_argument("--workers", type=int, default=None, help="workers of --scheduler local")
    parser.add_argument(
        "--no-progress",
        dest="progress",
        action="store_false",
        help="no progress bars (they show when stderr is a terminal)",
    )
    add_aliases(parser, n_workers="--workers", large_n="--large-n")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..paper import reproduce
    from ..paper.runner import StudyIncomplete
    from ._io import check_output

    # Refuse an unwritable output folder before any study runs (REPORT.md stands for
    # every file written there).
    if args.out.exists() and not args.out.is_dir():
        raise ParameterError(f"`--out` {str(args.out)!r} is a file; give a folder.")
    check_output(args.out, "--out", folder=True)

    try:
        rep = reproduce(
            args.out,
            mode=args.mode,
            studies=args.only,
            experiment=args.experiment,
            progress=args.progress and sys.stderr.isatty(),
            log=lambda line: print(line, flush=True),
            scheduler=args.scheduler,
            n_workers=args.workers,
            large_n=args.large_n,
        )
    except StudyIncomplete as error:  # the work ran; what finished is kept
        print(f"metrosync reproduce: error: {error}", file=sys.stderr)
        return 1
    width = max(len(v.verdict) for v in rep.verdicts)
    print(f"\nverdicts ({rep.mode} mode, {rep.wall_s:.0f} s):")
    for v in rep.verdicts:
        print(f"  claim {v.claim}: {v.verdict:<{width}}  {v.text}")
    print(f"report: {rep.report}")
    return 0

"""``metrosync pantaleone``: Pantaleone's 2002 observations reproduced on the board."""

from __future__ import annotations

from pathlib import Path

from ._io import check_output
from ._options import path_option


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "pantaleone",
        help="reproduce Pantaleone's metronomes on a board (Am. J. Phys. 2002)",
        description="Run each observation of J. Pantaleone, 'Synchronization of metronomes' "
        "(Am. J. Phys. 70, 992, 2002) on the board preset pantaleone2002: the time to lock, "
        "the lag of a detuned pair against his averaged theory and metrosync's reduced "
        "theory, a heavier board, a strongly damped board, the bob removed, seven "
        "metronomes. Writes OUT/PANTALEONE.md (a verdict on each), OUT/pantaleone.png and "
        "OUT/pantaleone.nc.",
    )
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--quick", dest="mode", action="store_const", const="quick",
                      help="a few starts each, to check the machinery (the default; "
                      "about 40 s on 2 cores, most of it compiling the kernels once)")  # fmt: skip
    mode.add_argument("--full", dest="mode", action="store_const", const="full",
                      help="the report's statistics (about 2 min on 2 cores)")  # fmt: skip
    parser.set_defaults(mode="quick")
    parser.add_argument("--out", type=path_option, default=Path("results-pantaleone"),
                        help="output folder (default: results-pantaleone)")  # fmt: skip
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..pantaleone.report import FULL, QUICK, run_report

    check_output(args.out, "--out", folder=True)
    path = run_report(args.out, FULL if args.mode == "full" else QUICK,
                      say=lambda line: print(f"  {line}", flush=True))  # fmt: skip
    print(f"wrote {path}, {path.with_name('pantaleone.png')} and "
          f"{path.with_name('pantaleone.nc')}")  # fmt: skip
    return 0

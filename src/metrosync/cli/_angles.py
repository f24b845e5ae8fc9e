"""``metrosync analyze angles.csv``: the options and the run for angle tables.

`metrosync.cli.analyze` adds these options to its parser. An input that is not a
recording is an angle table (`metrosync.angles`: a rotary encoder's CSV, Tracker's
exported data) when an option of this group is given, or when its text is not a
light-gate capture but a table of numbers under a header; `tables_requested` tells,
and `run_tables` analyses them. A file that is neither is refused naming both
readings. The light-gate options that read or clean gate edges draw a warning with a
table; ``--channels``, ``--grid-dt`` and ``--window`` mean what they mean for logs.
"""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

from ..angles.table import AngleTableError
from ..errors import ParameterError
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import add_aliases

#: Options of the angle tables, which logs and recordings ignore.
ANGLE_OPTIONS = {
    "time_column": "--time-column", "angle_column": "--angle-column",
    "x_column": "--x-column", "y_column": "--y-column", "pivot": "--pivot",
    "time_unit": "--time-unit", "angle_unit": "--angle-unit",
}  # fmt: skip
#: Light-gate options that only reading and cleaning gate edges use.
EDGE_OPTIONS = {
    "tick": "--tick", "counter_bits": "--counter-bits", "polarity": "--polarity",
    "strict": "--strict", "glitch": "--glitch", "min_asymmetry": "--min-asymmetry",
}  # fmt: skip
#: Bytes of a file looked at to tell a light-gate capture from a table.
SNIFF_BYTES = 1 << 16


def pivot_arg(text: str) -> tuple[float, float]:
    """``--pivot``: the pivot's position, ``X,Y``, in the table's unit of length."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 2 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(
            f"expected X,Y in the table's unit of length, such as 0,0.25, got {text!r}"
        )
    return values


def add_angle_options(parser: argparse.ArgumentParser) -> None:
    """Add the options for angle tables; call after the light-gate options."""
    parser.set_defaults(_edge_defaults={d: parser.get_default(d) for d in EDGE_OPTIONS})
    g = parser.add_argument_group(
        "angle tables (a rotary encoder's CSV, Tracker's exported data: .csv, .tsv, .txt)",
        "A pendulum's angle in time, or its bob's x and y; each angle column, x/y pair or "
        "Tracker track is a metronome. Its passes through the vertical (its median angle) "
        "are analysed as a light gate's. Columns are found by their names unless given.",
    )
    g.add_argument("--time-column", default=None, metavar="NAME",
                   help="the time column's header, or its number from 1 (default: the one "
                   "named t, time, millis, ...)")  # fmt: skip
    g.add_argument("--angle-column", default=None, metavar="NAME[,NAME...]",
                   help="angle columns, one metronome each, in every Tracker track "
                   "(default: those named theta, θ, angle, phi)")  # fmt: skip
    g.add_argument("--x-column", default=None, metavar="NAME",
                   help="the bob's horizontal position, with --y-column, where there is no "
                   "angle (default: x)")  # fmt: skip
    g.add_argument(
        "--y-column", default=None, metavar="NAME", help="the bob's vertical position (default: y)"
    )
    g.add_argument("--pivot", type=pivot_arg, action="append", default=None, metavar="X,Y",
                   help="a pendulum's pivot in the table's unit, once per pendulum in order: "
                   "its angle is then atan2 about it (without: its position along its swing, "
                   "which passes the bottom when the angle does)")  # fmt: skip
    g.add_argument("--time-unit", choices=("auto", "s", "ms", "us"), default="auto",
                   help="the time column's unit (auto: from its header, else s)")  # fmt: skip
    g.add_argument("--angle-unit", choices=("auto", "deg", "rad"), default="auto",
                   help="the angle's unit, for the rest angle and swing reported (auto: from "
                   "its header)")  # fmt: skip
    parser.set_defaults(_angle_defaults={d: parser.get_default(d) for d in ANGLE_OPTIONS})
    add_aliases(parser, **ANGLE_OPTIONS)


def _changed(args, defaults: dict, names: dict) -> list[str]:
    return [names[d] for d, v in defaults.items() if getattr(args, d, v) != v]


def tables_requested(args) -> bool:
    """True when the inputs (none of them a recording) are angle tables; refuses a mix
    of tables and light-gate logs, and a file that is neither; warns about the options
    of tables given with other inputs."""
    from ..audio.reader import is_audio_path

    paths = [Path(p) for p in args.logs]
    asked = _changed(args, args._angle_defaults, ANGLE_OPTIONS)
    if any(is_audio_path(p) for p in paths) or getattr(args, "follow", False):
        kinds = []
    else:
        kinds = [input_kind(p) for p in paths]
        if asked:  # the user says they are tables: the table reader says what is wrong
            kinds = ["table" if k == "neither" else k for k in kinds]
    if not kinds or all(k == "log" for k in kinds):
        if asked:
            what = "light-gate logs" if kinds else "recordings and --follow"
            warnings.warn(f"{what} ignore {', '.join(asked)} (options for angle tables).",
                          UserWarning, stacklevel=2)  # fmt: skip
        return False
    if "log" in kinds:
        logs = [str(p) for p, k in zip(paths, kinds, strict=True) if k == "log"]
        tables = [str(p) for p, k in zip(paths, kinds, strict=True) if k != "log"]
        raise ParameterError(
            f"give either light-gate logs or angle tables, not both: {', '.join(logs)} "
            f"{'is a light-gate log' if len(logs) == 1 else 'are light-gate logs'}, "
            f"{', '.join(tables)} {'is' if len(tables) == 1 else 'are'} not."
        )
    if "neither" in kinds:
        path = paths[kinds.index("neither")]
        raise AngleTableError(
            f"{str(path)!r} is neither a light-gate log (no record such as '0-1-0-0 1450' "
            f"in its first lines) nor a table of times and angles (no header such as "
            f"'t,theta' over rows of numbers); `analyze` reads light-gate logs, sound "
            f"recordings and videos (.wav, .flac, .mp3, .m4a, .mp4, ...) and angle tables."
        )
    return True


def input_kind(path: Path) -> str:
    """``"log"``, ``"table"`` or ``"neither"``, from the start of the file's text.

    A capture is a log when most of its non-blank lines are gate records (a terminal's
    banner and the logger's messages are a few lines); a file that cannot be read, or
    is empty, goes to the log reader, whose messages say why.
    """
    from ..angles.table import AngleTableError, parse_table
    from ..lightgate.messages import parse_message
    from ..lightgate.reader import classify

    try:
        with path.open("rb") as f:
            head = f.read(SNIFF_BYTES)
    except OSError:
        return "log"
    text = head.decode("utf-8", errors="replace")
    lines = [line for line in text.splitlines() if line.strip()]
    if len(head) == SNIFF_BYTES and lines:
        lines.pop()  # cut off in the middle
    if not lines:
        return "log"
    records = sum(classify(line).gates is not None for line in lines)
    messages = sum(parse_message(line) is not None for line in lines)
    if records and records >= (len(lines) - messages) / 2:
        return "log"
    try:
        parse_table("\n".join(lines), source=str(path))
    except AngleTableError:
        return "log" if records or messages else "neither"
    return "table"


def run_tables(args) -> int:
    """Analyse the angle tables, print the light gate's summary, write --out and --plot."""
    from ..angles import AngleColumns, analyze_angles
    from ..lightgate.plots import plot_analysis
    from ..lightgate.summary import summary_text

    ignored = _changed(args, args._edge_defaults, EDGE_OPTIONS)
    if ignored:
        warnings.warn(f"an angle table ignores {', '.join(ignored)} (options for reading and "
                      f"cleaning light-gate logs).", UserWarning, stacklevel=2)  # fmt: skip
    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    columns = AngleColumns(
        time=args.time_column,
        angle=tuple(a.strip() for a in args.angle_column.split(",")) if args.angle_column else (),
        x=args.x_column,
        y=args.y_column,
        pivot=tuple(args.pivot or ()),
        time_unit=args.time_unit,
        angle_unit=args.angle_unit,
    )
    ds = analyze_angles(args.logs, columns=columns, channels=args.channels,
                        grid_dt=args.grid_dt, equilibrium_window=args.window)  # fmt: skip
    print(summary_text(ds))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_analysis)
    return 0

"""``metrosync analyze``: light-gate logs → r(t), frequencies, σ and the cleaning report.

The same command reads a sound recording or a video's sound (`_audio`) and angle
tables of other instruments (`_angles`); `run` tells the inputs apart and hands them on.
"""

from __future__ import annotations

import argparse

from ..lightgate.cleaning import DEFAULT_GLITCH, DEFAULT_MIN_ASYMMETRY
from ..lightgate.reader import DEFAULT_TICK
from ._angles import add_angle_options, run_tables, tables_requested
from ._audio import add_audio_options, audio_requested, run_audio
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import HelpFormatter, add_aliases, int_list, path_option, positive_seconds


def counter_bits_arg(text: str):
    """``--counter-bits``: ``auto``, ``none`` (never wraps) or a width in bits."""
    if text == "auto":
        return "auto"
    if text == "none":
        return None
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected 'auto', 'none' or a number of bits, got {text!r}"
        ) from None


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "analyze",
        help="analyse light-gate logs (real or virtual), a sound recording or angle tables",
        description="Read light-gate logs, clean them, and measure r(t), the metronomes' "
        "frequencies and their spread. Several logs are repeated runs and are averaged. "
        "A sound recording (.wav, .flac, .ogg, .mp3, a phone's .m4a) or a video (.mp4, .mov) "
        "is analysed for its ticks instead. Tables of a pendulum's angle in time (a rotary "
        "encoder's CSV, Tracker's exported data) are analysed as light-gate logs are, their "
        "passes through the vertical taken as the gate's.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument("logs", nargs="+", type=path_option, metavar="LOG",
                        help="light-gate log files, one sound recording or video, or angle "
                        "tables")  # fmt: skip
    g = parser.add_argument_group("reading")
    g.add_argument("--tick", type=float, default=DEFAULT_TICK, help="seconds per logger tick")
    g.add_argument("--counter-bits", type=counter_bits_arg, default="auto",
                   help="counter width in bits, 'auto' or 'none' (never wraps)")  # fmt: skip
    g.add_argument("--polarity", choices=("auto", "0", "1"), default="auto",
                   help="level that means 'beam interrupted'")  # fmt: skip
    g.add_argument("--strict", action="store_true", help="refuse any line that is not a record")
    c = parser.add_argument_group("cleaning and measuring")
    c.add_argument("--channels", type=int_list, default=None, metavar="I,J,...",
                   help="gates to analyse, comma-separated, 0-based (default: all; a gate "
                   "that never changed is left out, with a warning)")  # fmt: skip
    c.add_argument("--glitch", type=float, default=DEFAULT_GLITCH, help="shortest real spell, s")
    c.add_argument("--min-asymmetry", type=float, default=DEFAULT_MIN_ASYMMETRY,
                   help="smallest (l-s)/(l+s) that tells the pass directions apart")  # fmt: skip
    c.add_argument("--grid-dt", type=positive_seconds, default=0.1,
                   help="spacing of the r(t) grid, s")  # fmt: skip
    c.add_argument(
        "--window",
        type=positive_seconds,
        default=None,
        metavar="S",
        help="final window averaged for r_eq, s (default: the last quarter)",
    )
    out = parser.add_argument_group("output")
    out.add_argument("--out", type=path_option, default=None, help="write the dataset to FILE.nc")
    out.add_argument("--plot", type=path_option, default=None,
                     help="write r(t) to FILE.png (or .pdf, .svg, ...)")  # fmt: skip
    out.add_argument("--follow", action="store_true",
                     help="follow a LOG that is still being written (by `metrosync record` or "
                     "a terminal program), with a live panel; at Ctrl-C analyse it, write "
                     "--out/--plot and exit 130")  # fmt: skip
    add_aliases(parser, equilibrium_window="--window", grid_dt="--grid-dt", channels="--channels")
    add_audio_options(parser)
    add_angle_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    tables = tables_requested(args)
    if audio_requested(args, others="angle tables" if tables else "light-gate logs"):
        return run_audio(args)
    if tables:
        return run_tables(args)
    from ..lightgate import analyze
    from ..lightgate.plots import plot_analysis
    from ..lightgate.summary import summary_text

    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    options = dict(
        tick=args.tick,
        counter_bits=args.counter_bits,
        polarity=args.polarity if args.polarity == "auto" else int(args.polarity),
        strict=args.strict,
        channels=args.channels,
        glitch=args.glitch,
        min_asymmetry=args.min_asymmetry,
        grid_dt=args.grid_dt,
        equilibrium_window=args.window,
    )
    if getattr(args, "follow", False):
        from ._follow import follow

        return follow(args, options)
    ds = analyze(args.logs, **options)
    print(summary_text(ds))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_analysis)
    return 0

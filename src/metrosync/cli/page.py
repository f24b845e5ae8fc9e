"""``metrosync page``: one self-contained HTML file that plays a run back offline."""

from __future__ import annotations

from pathlib import Path

from ._io import check_output
from ._options import HelpFormatter, add_aliases, path_option
from ._show_source import add_source_options, load_or_simulate


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "page",
        help="write an interactive, offline HTML page of a run",
        description="Write one HTML file (inline script, data as JSON) with the animated "
        "disk, r(t), a phase wheel, play/pause, seek and speed. It needs no server and "
        "no network.",
        formatter_class=HelpFormatter,
    )
    add_source_options(parser, record_seconds=0.05)
    out = parser.add_argument_group("page")
    out.add_argument("--out", type=path_option, default=Path("metrosync.html"), help="FILE.html")
    out.add_argument("--max-rate", type=float, default=50.0,
                     help="keep at most this many records per second")  # fmt: skip
    add_aliases(parser, max_rate="--max-rate")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.page import check_max_rate, write_page

    check_output(args.out, "--out", suffixes=(".html", ".htm"))
    check_max_rate(args.max_rate)
    ds = load_or_simulate(args)
    path = write_page(ds, args.out, run=args.run, start=args.start, end=args.end,
                      max_rate=args.max_rate)  # fmt: skip
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB); open it in a browser")
    return 0

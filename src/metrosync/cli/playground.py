"""``metrosync playground``: one offline HTML file that runs the model live, with controls."""

from __future__ import annotations

from pathlib import Path

from ._io import check_output
from ._options import (
    HelpFormatter,
    add_aliases,
    add_platform_option,
    model_changes,
    path_option,
    seed,
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "playground",
        help="write an offline HTML page that simulates live, with sliders and sound",
        description="Write one HTML file that runs the paper's model in the browser while "
        "you watch: change N, BPM, the spread, the drive, the platform (the disk or a board "
        "on rollers), the disk's inertia and friction or the board's mass and damping, or "
        "hold the platform, and see and hear the metronomes respond. The options set where "
        "the page starts; every one can be changed on the page. It needs no server and no "
        "network.",
        formatter_class=HelpFormatter,
    )
    g = parser.add_argument_group("starting point")
    g.add_argument("--n", type=int, default=7, help="metronomes on the disk (1 to 100)")
    g.add_argument("--bpm", type=float, default=192.0, help="nominal beat frequency, BPM")
    g.add_argument("--sigma", type=float, default=0.0,
                   help="spread (std) of the natural frequencies, BPM (0 to 10)")  # fmt: skip
    g.add_argument("--preset", default="default", help="parameter preset (see `metrosync presets`)")
    add_platform_option(g)
    g.add_argument("--set", dest="changes", action="append", default=[], metavar="NAME=VALUE",
                   help="change a model parameter, e.g. --set drive=1e-4 (repeatable)")  # fmt: skip
    g.add_argument("--dt", type=float, default=0.01, help="time step, s")
    g.add_argument("--seed", type=seed, default=0, help="seed of the first random start")
    out = parser.add_argument_group("page")
    out.add_argument("--out", type=path_option, default=Path("playground.html"), help="FILE.html")
    add_aliases(parser, sigma_bpm="--sigma", changes="--set")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.playground import write_playground

    check_output(args.out, "--out", suffixes=(".html", ".htm"))
    path = write_playground(
        args.out, preset=args.preset, changes=model_changes(args) or None, n=args.n,
        bpm=args.bpm, sigma_bpm=args.sigma, dt=args.dt, seed=args.seed,
    )  # fmt: skip
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB); open it in a browser, "
          "no server or network needed")  # fmt: skip
    return 0

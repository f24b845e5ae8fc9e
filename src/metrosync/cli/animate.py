"""``metrosync animate``: the disk seen from above beside r(t), as a GIF or an MP4."""

from __future__ import annotations

from pathlib import Path

from ._io import check_output
from ._options import HelpFormatter, add_aliases
from ._show_source import add_source_options, load_or_simulate


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "animate",
        help="animate a run: the disk from above and r(t)",
        description="Render a recorded (or freshly simulated) run as a GIF, or an MP4 when "
        "ffmpeg is on PATH. Frames come from the recorded trajectories.",
        formatter_class=HelpFormatter,
    )
    add_source_options(parser, record_seconds=0.05)
    out = parser.add_argument_group("animation")
    out.add_argument("--out", type=Path, default=Path("metrosync.gif"), help="FILE.gif or FILE.mp4")
    out.add_argument("--fps", type=float, default=15.0,
                     help="frames per second (at most 50 for a GIF)")  # fmt: skip
    out.add_argument(
        "--speedup",
        type=float,
        default=None,
        help="simulated seconds per second shown (default: the speed-up of 1, 2, 2.5, 4, 5, "
        "10, ... that fits the window in 30 s)",
    )
    out.add_argument("--dpi", type=float, default=80.0,
                     help="resolution: frames of 8 x 4 in x dpi pixels, 25 to 512")  # fmt: skip
    add_aliases(parser, speedup="--speedup", fps="--fps", dpi="--dpi")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.animation import animate, plan

    check_output(args.out, "--out", suffixes=(".gif", ".mp4"))

    def check(start: float, end: float) -> None:
        # Refuse what the options make impossible, and warn about a long rendering, on
        # the window the simulation will cover.
        plan(start, end, fps=args.fps, speedup=args.speedup, dpi=args.dpi, size=(8.0, 4.0),
             path=args.out)[2].check()  # fmt: skip

    ds = load_or_simulate(args, check)
    speedup = args.speedup
    if speedup is None:
        from ..show.animation import auto_speedup
        from ..show.recording import RecordedRun

        window = RecordedRun.from_dataset(ds, args.run).window(args.start, args.end)
        speedup = auto_speedup(window[1] - window[0])
    frames = animate(
        ds, args.out, run=args.run, fps=args.fps, speedup=speedup,
        start=args.start, end=args.end, dpi=args.dpi,
    )  # fmt: skip
    print(f"wrote {args.out} ({frames} frames at {args.fps:g} fps, speed-up {speedup:g}, "
          f"{frames / args.fps:.0f} s)")  # fmt: skip
    return 0

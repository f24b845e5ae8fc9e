"""``metrosync animate``: the disk seen from above beside r(t), as a GIF or an MP4."""

from __future__ import annotations

from pathlib import Path

from ._io import check_output
from ._options import HelpFormatter
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
    out.add_argument("--fps", type=float, default=20.0, help="frames per second")
    out.add_argument(
        "--speedup", type=float, default=1.0, help="simulated seconds per second shown"
    )
    out.add_argument("--dpi", type=float, default=80.0, help="resolution (pixels = 8x4 in x dpi)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.animation import animate

    check_output(args.out, "--out", suffixes=(".gif", ".mp4"))
    ds = load_or_simulate(args)
    frames = animate(
        ds, args.out, run=args.run, fps=args.fps, speedup=args.speedup,
        start=args.start, end=args.end, dpi=args.dpi,
    )  # fmt: skip
    print(f"wrote {args.out} ({frames} frames at {args.fps:g} fps, speed-up {args.speedup:g})")
    return 0

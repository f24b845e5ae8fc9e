"""``metrosync animate``: the disk seen from above beside r(t), as a GIF or an MP4."""

from __future__ import annotations

from pathlib import Path

from .._files import atomic_path
from .._words import plural
from ..errors import ParameterError
from ._io import check_output
from ._options import HelpFormatter, add_aliases, path_option, seed
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
    out.add_argument(
        "--out", type=path_option, default=Path("metrosync.gif"), help="FILE.gif or FILE.mp4"
    )
    out.add_argument("--fps", type=float, default=None,
                     help="frames per second: 15 unless given, at most 50 for a GIF; "
                     "60 with --phone")  # fmt: skip
    out.add_argument(
        "--speedup",
        type=float,
        default=None,
        help="simulated seconds per second shown (default: the speed-up of 1, 2, 2.5, 4, 5, "
        "10, ... that fits the window in 30 s)",
    )
    out.add_argument("--dpi", type=float, default=80.0,
                     help="resolution: frames of 8 x 4 in x dpi pixels, 25 to 512")  # fmt: skip
    phone = parser.add_argument_group(
        "as a phone films it",
        "--phone films the run instead: metronomes in perspective before a cluttered "
        "background, with a phone's blur, rolling shutter, flicker, noise, jittered "
        "timestamps and H.264, at real speed, with the ticks as sound; the ground truth "
        "(frame times, pivots, angles, crossings) goes to FILE.truth.json beside it.",
    )
    phone.add_argument(
        "--phone", action="store_true",
        help="film the run as a phone would (--out FILE.mp4, .mov or .mkv)",
    )  # fmt: skip
    phone.add_argument(
        "--phone-seed", type=seed, default=0, help="draws the scene and the phone's settings"
    )
    phone.add_argument(
        "--size", default="1280x720",
        help="frame size WIDTHxHEIGHT, px (width even, height a multiple of 4)",
    )  # fmt: skip
    add_aliases(parser, speedup="--speedup", fps="--fps", dpi="--dpi")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.animation import animate, plan

    if args.phone:
        return run_phone(args)
    if args.fps is None:
        args.fps = 15.0
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
    print(f"wrote {args.out} ({plural(frames, 'frame')} at {args.fps:g} fps, speed-up {speedup:g}, "
          f"{frames / args.fps:.0f} s)")  # fmt: skip
    return 0


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        width = height = 0
    if not (64 <= width <= 3840 and width % 2 == 0 and 64 <= height <= 2160 and height % 4 == 0):
        raise ParameterError(
            f"`--size` must be WIDTHxHEIGHT in pixels, e.g. 1280x720 (width even, 64 to "
            f"3840; height a multiple of 4, 64 to 2160), got {text!r}."
        )
    return width, height


def run_phone(args) -> int:
    import numpy as np

    from ..show.recording import RecordedRun
    from ..video.camera import Camera, Scene, film

    if args.out == Path("metrosync.gif"):
        args.out = Path("metrosync.mp4")
    check_output(args.out, "--out", suffixes=(".mp4", ".mov", ".mkv"))
    for option, given in (("--speedup", args.speedup is not None), ("--dpi", args.dpi != 80.0)):
        if given:
            raise ParameterError(f"`{option}` does not apply to --phone: a phone films at real "
                                 f"speed, at the size --size gives.")  # fmt: skip
    width, height = _size(args.size)
    if args.phone_seed < 0:
        raise ParameterError(f"`--phone-seed` must be >= 0, got {args.phone_seed}.")
    fps = 60.0 if args.fps is None else args.fps
    camera = Camera.random(args.phone_seed, fps=fps, width=width, height=height)
    if args.input is None and args.n > 8:
        raise ParameterError(f"`--n` must be at most 8 metronomes for --phone, got {args.n}.")
    ds = load_or_simulate(args)
    run = RecordedRun.from_dataset(ds, args.run)
    start, end = run.window(args.start, args.end)
    # The camera interpolates linearly: resample a coarse record at 2 ms (Hermite, from
    # θ and θ̇) so that the angles between records are the run's, not chords.
    step = min(float(np.median(np.diff(run.time))), 0.002)
    times = start + step * np.arange(int((end - start) / step) + 1)
    theta = run.theta_at(times)
    if theta.shape[1] > 8:
        raise ParameterError(f"--phone films at most 8 metronomes; the run has {theta.shape[1]}.")
    scene = Scene.random(theta.shape[1], seed=args.phone_seed)
    truth = film(args.out, times, theta, scene=scene, camera=camera, audio=True,
                 seed=args.phone_seed)  # fmt: skip
    truth_path = args.out.with_name(args.out.stem + ".truth.json")
    with atomic_path(truth_path) as tmp:
        tmp.write_text(truth.to_json())
    dropped = f", {truth.dropped} dropped" if truth.dropped else ""
    print(f"wrote {args.out} ({plural(truth.frame_times.size, 'frame')}{dropped}, "
          f"{truth.frame_times[-1]:.1f} s, {width}x{height} at {fps:g} fps, camera "
          f"{camera.yaw_deg:+.0f}° aside) and {truth_path}; "
          f"rods seen {np.round(truth.visible * 100).astype(int).tolist()} %")  # fmt: skip
    return 0

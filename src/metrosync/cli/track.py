"""``metrosync track VIDEO``: a video of metronomes → angles, passes, r(t) and σ."""

from __future__ import annotations

import sys

from .._words import plural
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import HelpFormatter, add_aliases, path_option, positive_seconds


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "track",
        help="measure metronomes filmed with a phone or camera",
        description="Find the metronomes swinging in a video (MP4, MOV, MKV, AVI), measure "
        "each rod's angle in every frame, and time its passes through the vertical: "
        "frequencies, jitter, tick/tock asymmetry, amplitudes and r(t), as `analyze` "
        "measures light-gate logs. Frame times come from the file. When the video has "
        "sound, its ticks are timed against the picture.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument("video", type=path_option, metavar="VIDEO", help="the video file")
    g = parser.add_argument_group("finding the metronomes")
    g.add_argument(
        "--count",
        type=int,
        default=None,
        metavar="N",
        help="insist on N metronomes (default: as many as swing)",
    )
    g.add_argument(
        "--regions",
        type=path_option,
        default=None,
        metavar="FILE",
        help="metronomes given by hand: a text file, one per line, 'x y' (the "
        "pivot) or 'x0 y0 x1 y1' (a box round the swing), in the video's pixels; a pivot "
        "may lie outside the picture (a pendulum hung above it) if its rod swings in view",
    )
    g.add_argument(
        "--learn",
        type=float,
        default=6.0,
        metavar="S",
        help="seconds at the start in which the metronomes are found",
    )
    g.add_argument(
        "--resolution",
        type=int,
        default=640,
        metavar="PIXELS",
        help="longest side of the pictures analysed (smaller is faster)",
    )
    m = parser.add_argument_group("measuring")
    m.add_argument(
        "--view-angle",
        type=float,
        default=0.0,
        metavar="DEG",
        help="the camera's angle off square to the swing, turned about the "
        "vertical; angles are corrected for it",
    )
    m.add_argument(
        "--vertical",
        choices=("swing", "picture"),
        default="swing",
        help="the vertical: the middle of the swing, or straight up in the picture",
    )
    m.add_argument(
        "--readout",
        type=float,
        default=None,
        metavar="S",
        help="rolling-shutter readout time, top row to bottom row (0: a global shutter; "
        "default: estimated from how the moving rods look bent)",
    )
    m.add_argument(
        "--max-gap",
        type=int,
        default=3,
        metavar="FRAMES",
        help="longest gap without a clear rod that is interpolated",
    )
    m.add_argument(
        "--grid-dt",
        type=positive_seconds,
        default=0.1,
        help="spacing of the r(t) grid, s (at most half the video's length)",
    )
    m.add_argument(
        "--window",
        type=positive_seconds,
        default=None,
        metavar="S",
        help="final window averaged for r_eq, s (default: the last quarter)",
    )
    m.add_argument("--no-sound", action="store_true", help="ignore the video's audio track")
    out = parser.add_argument_group("output")
    out.add_argument(
        "--out", type=path_option, default=None, metavar="FILE", help="write the dataset to FILE.nc"
    )
    out.add_argument(
        "--plot",
        type=path_option,
        default=None,
        metavar="FILE",
        help="write r(t) and the last seconds' angles to FILE.png",
    )
    out.add_argument(
        "--preview",
        type=path_option,
        default=None,
        metavar="FILE",
        help="write the first frame with what was found to FILE.png",
    )
    add_aliases(
        parser,
        count="--count",
        regions="--regions",
        learn="--learn",
        max_side="--resolution",
        view_angle="--view-angle",
        vertical="--vertical",
        readout="--readout",
        max_gap="--max-gap",
        grid_dt="--grid-dt",
        equilibrium_window="--window",
    )
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..video.plots import plot_preview, plot_tracking
    from ..video.regions import read_regions
    from ..video.tracking import track

    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    check_output(args.preview, "--preview", suffixes=FIGURE)
    regions = read_regions(args.regions) if args.regions is not None else None
    ds = track(
        args.video,
        count=args.count,
        regions=regions,
        max_side=args.resolution,
        view_angle=args.view_angle,
        vertical=args.vertical,
        readout=args.readout,
        learn=args.learn,
        grid_dt=args.grid_dt,
        equilibrium_window=args.window,
        max_gap=args.max_gap,
        sound=not args.no_sound,
        progress=sys.stderr.isatty(),
        report=lambda line: print(line, file=sys.stderr, flush=True),
    )
    print(summary(ds))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_tracking)
    if args.preview is not None:
        plot_preview(ds, args.preview)
        print(f"wrote {args.preview}")
    return 0


def summary(ds) -> str:
    """The printed summary: per metronome its pivot, tick rate, jitter, asymmetry,
    amplitude and frames lost; r_eq, σ, z; what was lost; the sound's verdict."""
    a = ds.attrs
    lines = [
        f"metrosync track: {plural(int(a['frames']), 'frame')}, "
        f"{a['measured_fps']:.2f} fps measured ({a['nominal_fps']:.4g} nominal), "
        f"{plural(ds.sizes['metronome'], 'metronome')}, "
        f"common span {float(ds.time[0]):.1f} .. {float(ds.time[-1]):.1f} s",
        "  metronome  pivot (x, y px)  ticks/min  jitter (ms)  asymmetry (%)  "
        "amplitude (deg)  frames lost",
    ]
    import numpy as np

    amp = np.degrees(np.nanmedian(ds.amplitude.values, axis=1)) if ds.sizes["swing"] else []
    for j in range(ds.sizes["metronome"]):
        lines.append(
            f"  {j:9d}  {float(ds.pivot_x[j]):6.0f}, {float(ds.pivot_y[j]):6.0f}  "
            f"{float(ds.frequency_bpm[j]):9.3f}  {float(ds.period_jitter[0, j]) * 1e3:11.2f}  "
            f"{float(ds.asymmetry[j]):13.2f}  {amp[j]:15.1f}  "
            f"{float(ds.frames_lost[j]) * 100:10.1f}%"
        )
    lines.append(f"  sigma = {a['sigma_bpm']:.4f} BPM")
    lines.append(f"  equilibrium r (last {a['equilibrium_window']:.1f} s): {a['r_eq']:.4f}")
    if ds.sizes["metronome"] == 2:
        if np.isfinite(a["z"]):
            lines.append(f"  z = {a['z']:+.3f} (+1 in phase, -1 in anti-phase)")
        else:
            lines.append(f"  {a.get('z_note') or 'z not measured'}")
    if a.get("loss"):
        lines.append(f"  lost: {a['loss']}")
    source = a["readout_source"]
    if source == "given" or np.isfinite(a.get("readout_error", np.nan)):
        lines.append(f"  rolling shutter: {a['readout'] * 1e3:.1f} ms ({source})")
    else:  # no number was measured: say so, and what was assumed instead
        lines.append(f"  rolling shutter: {source}; taken as 0 (a global shutter), or give "
                     f"--readout")  # fmt: skip
    if a.get("sound"):
        lines.append(f"  sound: {a['sound']}")
    return "\n".join(lines)

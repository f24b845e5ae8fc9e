"""``metrosync calibrate``: estimate c_θ, M or c_φ (paper §5), with a plot of each fit."""

from __future__ import annotations

import math
import warnings

from ..errors import ParameterError
from ._io import FIGURE, check_output, read_dataset
from ._options import HelpFormatter, path_option

#: --bpm of `c-theta --log` when none is given.
DEFAULT_BPM = 192.0


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "calibrate",
        help="estimate c_theta, M or c_phi from measurements",
        description="Estimate the model's friction and drive parameters as in the paper's §5.",
        formatter_class=HelpFormatter,
    )
    sub = parser.add_subparsers(dest="quantity", required=True, metavar="QUANTITY")
    ct = sub.add_parser(
        "c-theta",
        help="c_theta from a free decay (drive off, rigid support)",
        description="Fit c_theta to the decaying swing of one metronome with the drive off "
        "on a rigid support, recorded by a light gate or simulated.",
        formatter_class=HelpFormatter,
    )
    src = ct.add_mutually_exclusive_group(required=True)
    src.add_argument("--log", type=path_option, help="light-gate log of the decay")
    src.add_argument("--trajectory", type=path_option,
                     help="NetCDF of `metrosync simulate --save-every 1 --set drive=0 "
                     "--set inertia=inf`")  # fmt: skip
    ct.add_argument("--offset", type=float, default=None,
                    help="gate angle, rad (with --log; required there)")  # fmt: skip
    ct.add_argument("--channel", type=int, default=0,
                    help="the metronome: its gate (--log) or its index (--trajectory)")  # fmt: skip
    ct.add_argument("--run", type=int, default=0, help="which run of --trajectory")
    ct.add_argument("--bpm", type=float, default=None,
                    help=f"the metronome's nominal BPM (with --log; default {DEFAULT_BPM:g}); "
                    "a trajectory file gives its own metronome")  # fmt: skip
    dr = sub.add_parser(
        "drive",
        help="M from a measured steady amplitude",
        description="Find the escapement impulse M for which one metronome on a rigid "
        "support, with the given c_theta, settles at the measured amplitude.",
        formatter_class=HelpFormatter,
    )
    dr.add_argument("--amplitude", type=float, required=True, help="steady amplitude, rad")
    dr.add_argument("--c-theta", type=float, required=True, help="c_theta, kg m²/s")
    dr.add_argument("--bpm", type=float, default=192.0, help="the metronome's nominal BPM")
    cp = sub.add_parser(
        "c-phi",
        help="c_phi from the synchronized disk's amplitude",
        description="Find the disk friction c_phi for which N identical metronomes in "
        "phase make the disk swing with the measured amplitude. Refuses when the amplitude "
        "hardly depends on c_phi (it is then not identifiable).",
        formatter_class=HelpFormatter,
    )
    cp.add_argument("--amplitude", type=float, required=True, help="disk amplitude, rad")
    cp.add_argument("--c-theta", type=float, required=True, help="c_theta, kg m²/s")
    cp.add_argument("--drive", type=float, required=True, help="M, N m s")
    cp.add_argument("--n", type=int, default=7, help="metronomes on the disk")
    cp.add_argument("--bpm", type=float, default=192.0, help="their nominal BPM")
    cp.add_argument("--bracket", type=float, nargs=2, default=(1e-3, 10.0), metavar=("LOW", "HIGH"),
                    help="c_phi range searched, kg m²/s")  # fmt: skip
    for p in (ct, dr, cp):
        p.add_argument("--plot", type=path_option, default=None,
                       help="write the fit to FILE.png (or .pdf, .svg, ...)")  # fmt: skip
        p.set_defaults(func=run)


def run(args) -> int:
    from .. import calibration as cal

    check_output(args.plot, "--plot", suffixes=FIGURE)
    if args.quantity == "c-theta":
        est = _c_theta(args)
    elif args.quantity == "drive":
        est = cal.fit_drive(args.amplitude, c_theta=args.c_theta, bpm=args.bpm)
    else:
        est = cal.fit_c_phi(args.amplitude, n=args.n, bpm=args.bpm, c_theta=args.c_theta,
                            drive=args.drive, bracket=tuple(args.bracket))  # fmt: skip
    print(est.summary())
    if args.plot is not None:
        est.plot(args.plot)
        print(f"wrote {args.plot}")
    return 0


def _c_theta(args):
    from .. import calibration as cal
    from ..model import MetronomeDesign

    if args.log is not None:
        if args.offset is None:
            raise ParameterError("`--offset` (the gate angle, rad) is needed with `--log`.")
        if args.run != 0:
            raise ParameterError("`--run` picks a run of `--trajectory`; a log holds one run.")
        design = MetronomeDesign()
        metronome = design.with_l2(design.l2_for_bpm(args.bpm or DEFAULT_BPM))
        return cal.c_theta_from_log(args.log, offset=args.offset, metronome=metronome,
                                    channel=args.channel)  # fmt: skip
    for option, value in (("--offset", args.offset), ("--bpm", args.bpm)):
        if value is not None:
            raise ParameterError(
                f"`{option}` applies to `--log` only; the trajectory file gives the "
                f"metronome (its L2 and weights) and needs no gate."
            )
    ds = read_dataset(args.trajectory, "trajectory")
    if "theta" not in ds:
        raise ParameterError(
            f"{str(args.trajectory)!r} has no `theta`; simulate with --save-every 1."
        )
    for name, dim, index in (("--run", "run", args.run), ("--channel", "metronome", args.channel)):
        size = ds.sizes[dim]
        if not 0 <= index < size:
            raise ParameterError(
                f"`{name}` {index} is out of range: {args.trajectory} has {size} {dim}(s), "
                f"indices 0..{size - 1}."
            )
    a = ds.attrs
    drive, disk = float(a.get("drive", math.nan)), float(a.get("disk_inertia", math.nan))
    if drive != 0 or disk != math.inf:
        warnings.warn(
            f"{args.trajectory} is not a free decay on a rigid support (drive = {drive:g} "
            f"N m s, disk inertia = {disk:g} kg m²); the fit assumes both, so c_theta will "
            f"be wrong (simulate with --set drive=0 --set inertia=inf).",
            UserWarning,
            stacklevel=2,
        )
    design = MetronomeDesign(
        **{k: float(a[k]) for k in ("w1", "w2", "l1", "g") if k in a},
        l2_bounds=tuple(float(b) for b in a.get("l2_bounds", MetronomeDesign().l2_bounds)),
    )
    metronome = design.with_l2(float(ds.l2.values[args.run, args.channel]))
    theta = ds.theta.isel(run=args.run, metronome=args.channel).values
    return cal.c_theta_from_trajectory(ds.time.values, theta, metronome=metronome)

"""``metrosync calibrate``: estimate c_θ, M or c_φ (paper §5), with a plot of each fit."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "calibrate",
        help="estimate c_theta, M or c_phi from measurements",
        description="Estimate the model's friction and drive parameters as in the paper's §5.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    sub = parser.add_subparsers(dest="quantity", required=True, metavar="QUANTITY")
    ct = sub.add_parser("c-theta", help="c_theta from a free decay (drive off, rigid support)")
    src = ct.add_mutually_exclusive_group(required=True)
    src.add_argument("--log", type=Path, help="light-gate log of the decay")
    src.add_argument("--trajectory", type=Path,
                     help="NetCDF of `simulate --save-every 1` (run 0, metronome 0)")  # fmt: skip
    ct.add_argument("--offset", type=float, default=None, help="gate angle, rad (with --log)")
    ct.add_argument("--channel", type=int, default=0, help="gate of the metronome (with --log)")
    ct.add_argument("--bpm", type=float, default=192.0, help="the metronome's nominal BPM")
    dr = sub.add_parser("drive", help="M from a measured steady amplitude")
    dr.add_argument("--amplitude", type=float, required=True, help="steady amplitude, rad")
    dr.add_argument("--c-theta", type=float, required=True, help="c_theta, kg m²/s")
    dr.add_argument("--bpm", type=float, default=192.0)
    cp = sub.add_parser("c-phi", help="c_phi from the synchronized disk's amplitude")
    cp.add_argument("--amplitude", type=float, required=True, help="disk amplitude, rad")
    cp.add_argument("--c-theta", type=float, required=True, help="c_theta, kg m²/s")
    cp.add_argument("--drive", type=float, required=True, help="M, N m s")
    cp.add_argument("--n", type=int, default=7)
    cp.add_argument("--bpm", type=float, default=192.0)
    cp.add_argument("--bracket", type=float, nargs=2, default=(1e-3, 10.0), metavar=("LOW", "HIGH"))
    for p in (ct, dr, cp):
        p.add_argument("--plot", type=Path, default=None, help="write the fit to FILE.png")
        p.set_defaults(func=run)


def run(args) -> int:
    from .. import calibration as cal
    from ..errors import ParameterError
    from ..model import MetronomeDesign

    if args.quantity == "c-theta":
        design = MetronomeDesign()
        metronome = design.with_l2(design.l2_for_bpm(args.bpm))
        if args.log is not None:
            if args.offset is None:
                raise ParameterError("`--offset` (the gate angle, rad) is needed with `--log`.")
            est = cal.c_theta_from_log(args.log, offset=args.offset, metronome=metronome,
                                       channel=args.channel)  # fmt: skip
        else:
            import xarray as xr

            with xr.open_dataset(args.trajectory, engine="h5netcdf") as ds:
                if "theta" not in ds:
                    raise ParameterError(
                        f"{args.trajectory} has no `theta`; simulate with --save-every."
                    )
                theta = ds.theta.isel(run=0, metronome=0).values
                est = cal.c_theta_from_trajectory(ds.time.values, theta, metronome=metronome)
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

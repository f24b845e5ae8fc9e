"""``metrosync critical``: ω_c(N) from a merged sweep, its N → ∞ limit, and a plot."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ParameterError


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "critical",
        help="critical frequency omega_c(N) from a bpm sweep",
        description=(
            "Estimate the critical frequency omega_c(N) from the peak of sigma_r and from the "
            "steepest rise of r(omega_0), with bootstrap error bars over runs, and extrapolate "
            "it to N -> infinity."
        ),
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("sweep", type=Path, help="merged sweep written by `metrosync sweep`")
    parser.add_argument("--bootstrap", type=int, default=1000, help="bootstrap replicas")
    parser.add_argument("--seed", type=int, default=0, help="seed of the bootstrap")
    parser.add_argument("--select", action="append", default=[], metavar="NAME=VALUE",
                        help="pick one value of another swept parameter (repeatable)")  # fmt: skip
    parser.add_argument("--plot", type=Path, default=None,
                        help="figure path (default: SWEEP with suffix _critical.png)")  # fmt: skip
    parser.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument("--out", type=Path, default=None, help="write the estimates to FILE.nc")
    parser.set_defaults(func=run)


def _open(path: Path, select: list[str]):
    import xarray as xr

    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds = ds.load()
    except (OSError, ValueError) as error:
        raise ParameterError(f"cannot read sweep {str(path)!r}: {error}") from None
    for item in select:
        name, sep, value = item.partition("=")
        if not sep or name not in ds.dims:
            raise ParameterError(
                f"`--select` expects NAME=VALUE with NAME a swept dimension {list(ds.dims)}, "
                f"got {item!r}."
            )
        try:
            ds = ds.sel({name: float(value)}, method="nearest").expand_dims(name)
        except ValueError:
            raise ParameterError(f"`--select {item}`: {value!r} is not a number.") from None
    return ds


def run(args) -> int:
    from ..sweeps.critical import METHODS, critical_frequency, plot_critical
    from ..sweeps.store import write_dataset

    ds = _open(args.sweep, args.select)
    result = critical_frequency(ds, n_boot=args.bootstrap, seed=args.seed)
    print(f"metrosync critical: {args.sweep} ({args.bootstrap} bootstrap replicas over runs)")
    print(f"  {'N':>6}  {'omega_c (sigma_r peak)':>24}  {'omega_c (steepest rise)':>24}")
    for n in result.n.values:
        one = result.sel(n=n)
        cells = [
            f"{float(one[f'omega_c_{m}']):8.2f} +- {float(one[f'omega_c_{m}_err']):5.2f} BPM"
            for m in METHODS
        ]
        print(f"  {n:>6}  {cells[0]:>24}  {cells[1]:>24}")
    a = result.attrs
    for m in METHODS:
        print(
            f"  N -> inf ({m}): omega_c = {a[f'omega_c_inf_{m}']:.2f} +- "
            f"{a[f'omega_c_inf_{m}_err']:.2f} BPM, fit {a[f'fit_form_{m}']} "
            f"(a = {a[f'fit_a_{m}']:.3g}, nu = {a[f'fit_nu_{m}']:.3g})"
        )
    if not args.no_plot:
        path = args.plot or args.sweep.with_name(args.sweep.stem + "_critical.png")
        plot_critical(result, path)
        print(f"wrote {path}")
    if args.out is not None:
        write_dataset(result, args.out)
        print(f"wrote {args.out}")
    return 0

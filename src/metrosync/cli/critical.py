"""``metrosync critical``: ω_c(N) from a merged sweep, its N → ∞ limit, and a plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ._io import FIGURE, NETCDF, check_output, read_dataset, write_outputs
from ._options import HelpFormatter, add_aliases


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "critical",
        help="critical frequency omega_c(N) from a bpm sweep",
        description=(
            "Estimate the critical frequency omega_c(N) from the peak of sigma_r and from the "
            "steepest rise of r(omega_0), with bootstrap error bars over runs, and extrapolate "
            "it to N -> infinity."
        ),
        formatter_class=HelpFormatter,
    )
    parser.add_argument("sweep", type=Path, help="merged sweep written by `metrosync sweep`")
    parser.add_argument("--bootstrap", type=int, default=1000, help="bootstrap replicas")
    parser.add_argument("--seed", type=int, default=0, help="seed of the bootstrap")
    parser.add_argument("--select", action="append", default=[], metavar="NAME=VALUE",
                        help="pick one value of another swept parameter (repeatable)")  # fmt: skip
    figure = parser.add_mutually_exclusive_group()
    figure.add_argument("--plot", type=Path, default=None,
                        help="figure path (default: SWEEP with suffix _critical.png)")  # fmt: skip
    figure.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument("--out", type=Path, default=None, help="write the estimates to FILE.nc")
    add_aliases(parser, n_boot="--bootstrap")
    parser.set_defaults(func=run)


def _open(path: Path, select: list[str]):
    ds = read_dataset(path, "sweep")
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

    plot = (
        None
        if args.no_plot
        else args.plot or args.sweep.with_name(args.sweep.stem + "_critical.png")
    )
    check_output(plot, "--plot", suffixes=FIGURE)
    check_output(args.out, "--out", suffixes=NETCDF)
    ds = _open(args.sweep, args.select)
    result = critical_frequency(ds, n_boot=args.bootstrap, seed=args.seed)
    print(f"metrosync critical: {args.sweep} ({args.bootstrap} bootstrap replicas over runs)")
    print(f"  {'N':>6}  {'omega_c (sigma_r peak)':>25}  {'omega_c (steepest rise)':>25}")
    bpm = result.bpm.values
    at_edge = False
    for n in result.n.values:
        one = result.sel(n=n)
        cells = []
        for m in METHODS:
            value = float(one[f"omega_c_{m}"])
            edge = bool(np.isclose(value, bpm[0]) or np.isclose(value, bpm[-1]))
            at_edge |= edge
            error = float(one[f"omega_c_{m}_err"])
            cells.append(f"{value:8.2f} +- {error:5.2f} BPM" + ("*" if edge else " "))
        print(f"  {n:>6}  {cells[0]:>25}  {cells[1]:>25}")
    a = result.attrs
    for m in METHODS:
        note = a[f"fit_note_{m}"]
        if note:  # an extrapolation the data do not support is not printed as a result
            print(f"  N -> inf ({m}): not extrapolated: {note}")
            continue
        print(
            f"  N -> inf ({m}): omega_c = {a[f'omega_c_inf_{m}']:.2f} +- "
            f"{a[f'omega_c_inf_{m}_err']:.2f} BPM, fit {a[f'fit_form_{m}']} "
            f"(a = {a[f'fit_a_{m}']:.3g}, nu = {a[f'fit_nu_{m}']:.3g})"
        )
    if at_edge:
        print(
            f"  * at an end of the bpm grid ({bpm[0]:g} .. {bpm[-1]:g} BPM): the transition "
            f"may lie outside it; widen the sweep's --bpm range or add runs."
        )
    write_outputs(result, out=args.out, plot=plot, plotter=plot_critical)
    return 0

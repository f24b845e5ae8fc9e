"""``metrosync critical``: ω_c(N) from a merged sweep, its N → ∞ limit, and a plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ._io import FIGURE, NETCDF, check_output, read_dataset, write_outputs
from ._options import HelpFormatter, add_aliases, path_option, seed


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
    parser.add_argument("sweep", type=path_option, help="merged sweep written by `metrosync sweep`")
    parser.add_argument("--bootstrap", type=int, default=1000, help="bootstrap replicas")
    parser.add_argument("--seed", type=seed, default=0, help="seed of the bootstrap")
    parser.add_argument("--select", action="append", default=[], metavar="NAME=VALUE",
                        help="pick one value of another swept parameter (repeatable)")  # fmt: skip
    figure = parser.add_mutually_exclusive_group()
    figure.add_argument("--plot", type=path_option, default=None,
                        help="figure path (default: NAME_critical.png in the current folder, NAME "
                        "the sweep file's name without .nc)")  # fmt: skip
    figure.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument(
        "--out", type=path_option, default=None, help="write the estimates to FILE.nc"
    )
    parser.add_argument(
        "--scaling",
        choices=("kuramoto", "free"),
        default=None,
        help=(
            "also collapse r_eq * N^(beta/nu) against (omega_0 - omega_c) * N^(1/nu) over all N "
            "(finite-size scaling) for omega_c(inf): 'kuramoto' fixes beta/nu = 1/5 and "
            "1/nu = 2/5, 'free' fits them; the error includes the spread over fit windows "
            "and N sets"
        ),
    )
    parser.add_argument(
        "--collapse-plot",
        type=path_option,
        default=None,
        help="collapse figure path (default: NAME_collapse.png in the current folder)",
    )
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

    plot = None if args.no_plot else args.plot or Path(args.sweep.stem + "_critical.png")
    check_output(plot, "--plot", suffixes=FIGURE)
    check_output(args.out, "--out", suffixes=NETCDF)
    collapse_plot = None
    if args.scaling is None:
        if args.collapse_plot is not None:
            raise ParameterError(
                "`--collapse-plot` needs `--scaling kuramoto` or `--scaling free`."
            )
    elif args.no_plot:
        if args.collapse_plot is not None:
            raise ParameterError("`--collapse-plot` and `--no-plot` exclude each other; give one.")
    else:
        collapse_plot = args.collapse_plot or Path(args.sweep.stem + "_collapse.png")
        check_output(collapse_plot, "--collapse-plot", suffixes=FIGURE)
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
        syst = a[f"omega_c_inf_{m}_syst"]
        spread = "" if np.isnan(syst) else f" +- {syst:.2f} leaving out the smallest or largest N"
        print(
            f"  N -> inf ({m}): omega_c = {a[f'omega_c_inf_{m}']:.2f} +- "
            f"{a[f'omega_c_inf_{m}_err']:.2f} BPM over runs{spread}, fit "
            f"{a[f'fit_form_{m}']} (a = {a[f'fit_a_{m}']:.3g}, nu = {a[f'fit_nu_{m}']:.3g})"
        )
    if at_edge:
        print(
            f"  * at an end of the bpm grid ({bpm[0]:g} .. {bpm[-1]:g} BPM): the transition "
            f"may lie outside it; widen the sweep's --bpm range or add runs."
        )
    if args.scaling is not None:
        _scaling(ds, result, args, collapse_plot)
    write_outputs(result, out=args.out, plot=plot, plotter=plot_critical)
    return 0


def _scaling(ds, result, args, path) -> None:
    """Collapse the sweep, print ω_c(∞) and the exponents, store them in ``result.attrs``."""
    from ..sweeps.scaling import mean_and_error, plot_collapse, sweep_scaling

    # the bootstrap refits the whole collapse, so it gets fewer replicas than ω_c(N)
    n_boot = min(args.bootstrap, 100)
    est, r = sweep_scaling(ds, exponents=args.scaling, n_boot=n_boot, seed=args.seed)
    best = est.best
    label = "fixed at 1/5, 2/5" if best.fixed else "fitted"
    print(
        f"  collapse over N = {list(best.sizes)} (exponents {label}, {best.points} points, "
        f"chi2/dof = {best.chi2_dof:.2f}, {n_boot} bootstrap replicas):"
    )
    print(
        f"    omega_c(inf) = {est.x_c:.2f} +- {est.x_c_err:.2f} BPM "
        f"(systematic {est.x_c_syst:.2f} over {len(est.variants)} fit windows and N sets)"
    )
    if not best.fixed:
        print(f"    beta/nu = {est.a:.3f} +- {est.a_err:.3f} (Kuramoto: 0.2)")
        print(f"    1/nu    = {est.b:.3f} +- {est.b_err:.3f} (Kuramoto: 0.4)")
    if best.chi2_dof > 3:
        print("    chi2/dof > 3: the data do not collapse on one curve; trust no number above.")
    result.attrs.update(
        {
            "scaling_exponents": args.scaling,
            "scaling_omega_c_inf": est.x_c,
            "scaling_omega_c_inf_err": est.x_c_err,
            "scaling_omega_c_inf_syst": est.x_c_syst,
            "scaling_beta_over_nu": est.a,
            "scaling_beta_over_nu_err": est.a_err,
            "scaling_inv_nu": est.b,
            "scaling_inv_nu_err": est.b_err,
            "scaling_chi2_dof": best.chi2_dof,
        }
    )
    if path is not None:
        mean, err = mean_and_error(r.values)
        plot_collapse(
            best,
            r.bpm.values,
            r.n.values,
            mean,
            err,
            path=path,
            x_label="ω₀",
            c_label="ω_c",
            units="BPM",
        )
        print(f"wrote {path}")

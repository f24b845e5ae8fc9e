"""``metrosync theory``: K(ω₀), α(ω₀) of the reduced phase model and the predicted ω_c(σ)."""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import ParameterError
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import HelpFormatter, add_aliases, add_platform_option, model_changes, path_option


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "theory",
        help="reduced Kuramoto-Sakaguchi theory: coupling K, lag alpha, predicted omega_c",
        description=(
            "Measure the coupling K(omega_0) and phase lag alpha(omega_0) of the reduced "
            "Kuramoto-Sakaguchi model on the full disk model (growth of r out of a splay "
            "state; or the locking curve of a detuned pair), set the analytic estimate "
            "beside them, and predict the critical frequency omega_c for each spread sigma "
            "from the exact Sakaguchi threshold. Measurements are cached."
        ),
        formatter_class=HelpFormatter,
    )
    g = parser.add_argument_group("model")
    g.add_argument("--preset", default="default", help="parameter preset (see `metrosync presets`)")
    add_platform_option(g)
    g.add_argument(
        "--set",
        dest="changes",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change one model parameter, e.g. --set drive=5e-5 (repeatable)",
    )
    g.add_argument(
        "--tuning",
        choices=("small-amplitude", "steady-swing"),
        default=None,
        help="how a nominal BPM sets the slider: small-amplitude tunes the small-swing "
        "frequency, steady-swing the tick rate at the steady swing; the same as --set "
        "tuning=NAME (default: the preset's own, as `metrosync presets` lists it)",
    )
    g = parser.add_argument_group("prediction")
    g.add_argument(
        "--bpm",
        default="150:230:10",
        metavar="SPEC",
        help="nominal BPM grid where K is measured (START:STOP:STEP or A,B,C)",
    )
    g.add_argument(
        "--sigma",
        default="0.5,0.75,1,1.25,1.5",
        metavar="SPEC",
        help="spreads of the nominal frequencies, BPM",
    )
    g.add_argument(
        "--n",
        default="inf",
        metavar="N",
        help="metronomes on the disk the prediction is for ('inf': N -> infinity)",
    )
    g.add_argument(
        "--method",
        choices=("growth", "pair"),
        default="growth",
        help="how K is measured (module metrosync.theory.coupling)",
    )
    g.add_argument(
        "--measure-n", type=int, default=32, help="metronomes in the growth method's runs (>= 16)"
    )
    o = parser.add_argument_group("output")
    o.add_argument(
        "--cache",
        type=path_option,
        default=None,
        help="folder of cached measurements (default: ~/.cache/metrosync/theory)",
    )
    o.add_argument("--no-cache", action="store_true", help="measure everything again")
    o.add_argument("--out", type=path_option, default=None, help="write the results to FILE.nc")
    o.add_argument("--plot", type=path_option, default=None, help="write the figure to FILE.png")
    o.add_argument(
        "--no-simulate",
        action="store_true",
        help="skip the reduced model's r(omega_0) curves (faster)",
    )
    o.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_aliases(
        parser,
        bpms="--bpm",
        bpm="--bpm",
        sigmas="--sigma",
        sigma_bpm="--sigma",
        measure_n="--measure-n",
        method="--method",
        changes="--set",
        n="--n",
        simulate_n="--no-simulate",
    )
    parser.set_defaults(func=run)


def _n(text: str) -> float | int:
    if text.strip().lower() in ("inf", "infinity"):
        return math.inf
    try:
        n = int(text)
    except ValueError:
        raise ParameterError(f"`--n` must be a whole number >= 1 or 'inf', got {text!r}.") from None
    if n < 1:
        raise ParameterError(f"`--n` must be a whole number >= 1 or 'inf', got {text!r}.")
    return n


def run(args) -> int:
    import sys

    from ..model import get_preset
    from ..sweeps.grid import parse_values
    from ..theory import default_cache_dir, plot_theory, reduced_theory

    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    bpms = parse_values("bpm", args.bpm)
    sigmas = parse_values("sigma_bpm", args.sigma)
    if len(bpms) < 2:
        raise ParameterError(f"`--bpm` needs at least 2 values to interpolate, got {args.bpm!r}.")
    n = _n(args.n)
    params = get_preset(args.preset, warn=False)
    changes = model_changes(args)
    given = changes.get("tuning")
    if args.tuning is not None and given is not None and given != args.tuning:
        raise ParameterError(
            f"`--tuning {args.tuning}` and `--set tuning={given}` disagree; give the tuning once."
        )
    if changes:
        params = params.with_changes(**changes)
    cache = None if args.no_cache else (args.cache or default_cache_dir())
    if cache is not None:
        _check_cache(cache)
    ds = reduced_theory(
        params,
        bpms=bpms,
        sigmas=sigmas,
        n=n,
        tuning=args.tuning,
        method=args.method,
        measure_n=args.measure_n,
        cache=cache,
        simulate_n=None if args.no_simulate else 20_000,
        progress=not args.no_progress and sys.stderr.isatty(),
    )
    _print(ds)
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_theory)
    return 0


def _check_cache(folder: Path) -> None:
    """Refuse a cache folder that cannot be written, before anything is measured."""
    import tempfile

    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise ParameterError(
            f"`--cache` {str(folder)!r} cannot hold files ({error.strerror or error}); choose "
            f"another folder, or --no-cache."
        ) from None


def _print(ds) -> None:
    a = ds.attrs
    n_text = "N -> inf" if a["n"] == "inf" else f"N = {a['n']}"
    print(
        f"metrosync theory: preset {a['preset']!r}, {a['tuning']} tuning, K measured by "
        f"'{a['method']}' and expressed for {n_text}"
    )
    print(
        f"  {'BPM':>6} {'ticks':>8} {'K (rad/s)':>18} {'alpha (deg)':>14} "
        f"{'K estimate':>11} {'alpha est.':>10}"
    )
    deg = 180 / math.pi
    for i, bpm in enumerate(ds.bpm.values):
        one = ds.isel(bpm=i)
        print(
            f"  {bpm:6.1f} {float(one.free_bpm):8.2f} "
            f"{float(one.k):9.4f} +- {float(one.k_err):6.4f} "
            f"{float(one.alpha) * deg:7.1f} +- {float(one.alpha_err) * deg:4.1f} "
            f"{float(one.k_estimate):11.4f} {float(one.alpha_estimate) * deg:10.1f}"
        )
    print(
        f"  predicted critical frequency omega_c ({n_text}; range from K +- 1 sigma), where "
        f"incoherence turns unstable:"
    )
    lo, hi = ds.bpm.values[0], ds.bpm.values[-1]
    for i, sigma in enumerate(ds.sigma.values):
        one = ds.isel(sigma=i)
        wc = float(one.omega_c)
        if math.isnan(wc):
            where = "below" if float(ds.k[0]) > float(ds.k_c.isel(sigma=i)[0]) else "above"
            print(
                f"    sigma = {sigma:5.2f} BPM: not within {lo:g}..{hi:g} BPM (it lies {where}); "
                f"widen --bpm"
            )
        else:
            half = float(one.omega_half) if "omega_half" in ds else math.nan
            print(
                f"    sigma = {sigma:5.2f} BPM: omega_c = {wc:6.1f} BPM "
                f"[{float(one.omega_c_low):.1f}, {float(one.omega_c_high):.1f}]"
                + ("" if math.isnan(half) else f"; reduced model: r = 1/2 at {half:.1f} BPM")
            )

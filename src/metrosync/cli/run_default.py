"""``metrosync run-default``: the default study that ``make run`` runs.

7 metronomes at 192 BPM with the default spread (0.75 BPM), 20 runs of 600 s;
writes r(t) as NetCDF and a PNG plot into the output folder.
"""

from __future__ import annotations

import time
from pathlib import Path

from .simulate import summary, write_netcdf


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "run-default", help="run the default study (what `make run` does)"
    )
    parser.add_argument("--out", type=Path, default=Path("results"), help="output folder")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..plots import plot_order
    from ..simulate import simulate

    started = time.perf_counter()
    ds = simulate(7, 192.0, sigma_bpm=0.75, runs=20, duration=600.0, seed=0)
    print(summary(ds, time.perf_counter() - started))
    args.out.mkdir(parents=True, exist_ok=True)
    write_netcdf(ds, args.out / "default.nc")
    plot_order(ds, args.out / "default.png")
    print(f"wrote {args.out / 'default.nc'} and {args.out / 'default.png'}")
    return 0

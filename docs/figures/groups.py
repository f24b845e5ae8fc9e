"""Draw docs/figures/groups.png: two groups of seven metronomes, 20 BPM apart, on one disk.

Each group falls into step on its own (its r_group rises to about 1), while the two
groups keep their own tempos: the global r then beats between |r1 - r2|/2 ≈ 0 and
(r1 + r2)/2 ≈ 1 at the groups' frequency difference, and averages about 2/π.

    .venv/bin/python docs/figures/groups.py            # writes docs/figures/groups.png
    .venv/bin/python docs/figures/groups.py --out g.png
"""

from __future__ import annotations

import argparse
from pathlib import Path

import metrosync as ms
from metrosync.plots import finish_figure, new_figure, order_axes, plot_order

GROUPS = [(7, 184.0), (7, 204.0)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).with_name("groups.png"))
    parser.add_argument("--runs", type=int, default=16)
    parser.add_argument("--duration", type=float, default=300.0)
    args = parser.parse_args()

    ds = ms.simulate(None, None, groups=GROUPS, sigma_bpm=0.25, runs=args.runs,
                     duration=args.duration, seed=3)  # fmt: skip
    fig = new_figure(args.out, figsize=(12, 4.2), layout="constrained")
    one, mean = fig.subplots(1, 2)
    run = ds.isel(run=0)
    t = ds.time.values
    one.plot(t, run.r_crossing, lw=0.6, color="0.3", label="global r (all 14)")
    for g, label in enumerate(ds.attrs["groups"].split()):
        one.plot(t, run.r_crossing_group.isel(group=g), lw=1.2, label=f"r of group {label}")
    one.set_title("one run (crossing phases)")
    order_axes(one, t[-1], None, xlabel="t (s)")
    plot_order(ds, ax=mean)
    groups = ", ".join(f"{v:.2f}" for v in ds.attrs["r_eq_group_mean"])
    mean.set_title(f"mean of {ds.sizes['run']} runs; r_eq: global {ds.attrs['r_eq_mean']:.2f}, "
                   f"groups {groups}")  # fmt: skip
    fig.suptitle("Two groups, 7 metronomes at 184 and 7 at 204 BPM (σ = 0.25 BPM), one disk")
    finish_figure(fig, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

"""Arnold tongue of one metronome driven through its disk: which pairs (forcing_bpm,
forcing_amplitude) lock it 1:1 to the drive, from a sweep over both.

    python docs/arnold_tongue.py                  # writes docs/figures/arnold_tongue.png
    python docs/arnold_tongue.py --quick          # a coarse grid in seconds, to try it
    python docs/arnold_tongue.py --data tongue.nc # also the grid's measurements

Every grid point is one `metrosync.simulate` run of one metronome (no spread) on a free
disk with the torque A sin(Ω t), Ω = π·BPM/60, from `metrosync.sweeps.Grid` over
``forcing_bpm`` × ``forcing_amplitude``. A point counts as locked when the drive's lag at
the metronome's upward crossings stays within π over the last ``--window`` seconds
(`metrosync.observables.entrainment`). The figure shows the beat between metronome and
drive (its mean beat rate minus the drive's) with the locked points outlined, and the
line fitted to the locking range's width against A. The forcing frequencies are
centred on the metronome's free-running rate at the same time step.

The default step is 0.002 s: the paper's 0.01 s quantises each kick to 1.5 % of a
period, which blurs the tongue's edges at small amplitudes (`tests/integrators/
test_forcing.py` measures the slope at 0.001 s by bisection: 122.6 BPM per N m).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from metrosync import simulate
from metrosync._files import write_netcdf
from metrosync.observables.entrainment import is_entrained, upward_crossings
from metrosync.plots import finish_figure, new_figure
from metrosync.progress import progress_bar
from metrosync.sweeps import Grid

FIGURE = Path(__file__).parent / "figures" / "arnold_tongue.png"
THETA0 = [0.76]  # rad: start at the steady swing, so that only locking takes time


def free_rate(dt: float, duration: float) -> float:
    """The unforced metronome's beat rate on the disk, BPM."""
    ds = simulate(1, 192, sigma_bpm=0.0, duration=duration, dt=dt, theta0=THETA0,
                  trajectories=True, record_every=10, progress=False)  # fmt: skip
    crossings = upward_crossings(ds.time.values, ds.theta.values[:, 0, 0])
    crossings = crossings[crossings > duration / 3]
    return 120.0 * (crossings.size - 1) / (crossings[-1] - crossings[0])


def measure(grid: Grid, window: float, show: bool) -> tuple[np.ndarray, np.ndarray]:
    """Locked (bool) and the metronome's beat rate (BPM) at every grid point, shaped
    like the grid."""
    locked = np.zeros(grid.shape, dtype=bool)
    rate = np.full(grid.shape, np.nan)
    with progress_bar(total=grid.size, unit="point", enabled=show) as bar:
        for point in grid.points():
            undriven = point.coords["forcing_amplitude"] == 0
            ds = simulate(**point.kwargs | {"record_every": 10}, theta0=THETA0,
                          trajectories=True, progress=False)  # fmt: skip
            time, theta = ds.time.values, ds.theta.values[:, 0, 0]
            # Undriven, nothing locks; the lag test would pass where the drive's rate
            # happens to equal the metronome's, so it is not asked.
            locked[point.index] = not undriven and is_entrained(
                time, theta, point.coords["forcing_bpm"], window=window
            )
            crossings = upward_crossings(time, theta)
            crossings = crossings[crossings >= time[-1] - window]
            rate[point.index] = 120.0 * (crossings.size - 1) / (crossings[-1] - crossings[0])
            bar.update(1)
    return locked, rate


def locking_widths(bpms: np.ndarray, locked: np.ndarray) -> np.ndarray:
    """Width (BPM) of the locked range at each amplitude: the locked grid points' span
    plus one grid step (each edge lies between a locked and an unlocked point)."""
    step = bpms[1] - bpms[0]
    return np.array([
        (bpms[row].max() - bpms[row].min() + step) if row.any() else 0.0 for row in locked
    ])  # fmt: skip


def draw(ds: xr.Dataset, path: Path):
    fig = new_figure(path, figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    detuning = ds.forcing_bpm.values - ds.attrs["free_rate_bpm"]
    amplitude = 1e3 * ds.forcing_amplitude.values
    beat = ds.tick_bpm.values - ds.forcing_bpm.values[None, :]
    limit = float(np.nanmax(np.abs(beat)))
    mesh = ax.pcolormesh(detuning, amplitude, beat, cmap="RdBu_r", vmin=-limit, vmax=limit,
                         shading="nearest")  # fmt: skip
    fig.colorbar(mesh, ax=ax, label="metronome's beat rate − drive's (BPM)")
    ax.contour(detuning, amplitude, ds.locked.values.astype(float), levels=[0.5],
               colors="k", linewidths=1.2)  # fmt: skip
    slope, intercept = ds.attrs["width_slope_bpm_per_n_m"], ds.attrs["width_intercept_bpm"]
    a = np.linspace(0, amplitude.max(), 50)
    half = 0.5 * (slope * a / 1e3 + intercept)
    ax.plot(-half, a, "k--", lw=0.9, label=f"width = {slope:.0f} BPM/(N m) × A")
    ax.plot(half, a, "k--", lw=0.9)
    ax.set_xlabel(f"forcing_bpm − free rate ({ds.attrs['free_rate_bpm']:.2f} BPM)")
    ax.set_ylabel("forcing_amplitude (mN m)")
    ax.set_title("One metronome driven through the disk: locked inside the outline")
    ax.legend(loc="upper right", fontsize="small")
    return finish_figure(fig, path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="coarse grid, short runs")
    parser.add_argument("--dt", type=float, default=0.002, help="time step, s")
    parser.add_argument("--duration", type=float, default=1200.0, help="each run, s")
    parser.add_argument("--window", type=float, default=800.0, help="final window judged, s")
    parser.add_argument("--out", type=Path, default=FIGURE, help="figure (PNG, PDF, SVG)")
    parser.add_argument("--data", type=Path, default=None, help="also write the grid (NetCDF)")
    args = parser.parse_args(argv)
    if args.quick:
        args.duration, args.window = 400.0, 250.0
        detunings, amplitudes = np.arange(-3, 3.01, 0.5), np.arange(0, 0.0401, 0.01)
    else:
        detunings, amplitudes = np.arange(-3, 3.001, 0.125), np.arange(0, 0.04001, 0.005)
    if not 0 < args.window < args.duration:
        parser.error(f"--window {args.window} must be > 0 and shorter than --duration")

    f0 = free_rate(args.dt, min(args.duration, 300.0))
    print(f"free-running rate at dt = {args.dt} s: {f0:.3f} BPM", flush=True)
    grid = Grid(
        axes={"forcing_amplitude": list(amplitudes), "forcing_bpm": list(f0 + detunings)},
        fixed={"n": 1, "sigma_bpm": 0.0, "runs": 1, "duration": args.duration, "dt": args.dt},
    )
    locked, rate = measure(grid, args.window, show=sys.stderr.isatty())
    bpms = np.array(grid.axes["forcing_bpm"])
    widths = locking_widths(bpms, locked)
    forced = amplitudes > 0
    slope, intercept = np.polyfit(amplitudes[forced], widths[forced], 1)
    print("forcing_amplitude (N m)  locked width (BPM)")
    for a, w in zip(amplitudes, widths, strict=True):
        print(f"  {a:10.4f}  {w:8.3f}")
    print(f"width = {slope:.1f} BPM per N m x A + {intercept:.3f} BPM "
          f"(grid step {bpms[1] - bpms[0]:.3f} BPM)")  # fmt: skip

    ds = xr.Dataset(
        {
            "locked": (
                ("forcing_amplitude", "forcing_bpm"),
                locked.astype(np.int8),
                {"long_name": "1:1 locked to the drive (1) or not (0)"},
            ),
            "tick_bpm": (
                ("forcing_amplitude", "forcing_bpm"),
                rate,
                {"units": "BPM", "long_name": "metronome's mean beat rate, final window"},
            ),
            "width": (("forcing_amplitude",), widths, {"units": "BPM"}),
        },
        coords={
            "forcing_amplitude": ("forcing_amplitude", amplitudes, {"units": "N m"}),
            "forcing_bpm": ("forcing_bpm", bpms, {"units": "BPM"}),
        },
        attrs={
            "free_rate_bpm": f0,
            "dt": args.dt,
            "duration": args.duration,
            "window": args.window,
            "width_slope_bpm_per_n_m": slope,
            "width_intercept_bpm": intercept,
        },
    )
    if args.data is not None:
        write_netcdf(ds, args.data)
        print(f"wrote {args.data}")
    draw(ds, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit("interrupted: nothing written")

"""The parameter-consistency table: what each preset implies, predicted and measured.

Contract: `consistency_table(bpms)` returns an `xarray.Dataset` with, for each preset,
the energy-balance steady amplitude 2M/(π c_θ), whether that overturns (> π/2), the
amplitude and overturn flag *measured* by simulating one metronome on the disk through
`metrosync.simulate`, and the slider position L2 each nominal BPM maps to (docs/model.md
§6.2), next to the paper's quoted L2 range. `markdown_table` renders it for REPORT.md.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import numpy as np
import xarray as xr

from ..model import PRESETS
from ..simulate import simulate

#: The L2 range the paper quotes for its metronomes, m.
PAPER_L2_RANGE = (0.019, 0.049)
#: Length of the single-metronome check and the final span whose max |θ| is its amplitude.
CHECK_DURATION = 120.0
CHECK_TAIL = 10.0


def consistency_table(bpms: Sequence[float], *, check_bpm: float = 192.0) -> xr.Dataset:
    """Predicted and measured swing of each preset, and L2 for each BPM.

    Parameters
    ----------
    bpms : (K,) nominal frequencies (BPM) used by the studies.
    check_bpm : where the single-metronome check runs, BPM.

    Returns
    -------
    Dataset with ``steady_amplitude``, ``overturns_predicted``, ``amplitude_measured``,
    ``overturns_measured`` (preset) and ``l2`` (preset, bpm), m.
    """
    names = list(PRESETS)
    bpms = sorted({float(b) for b in bpms})
    predicted, over_pred, measured, over_meas, l2 = [], [], [], [], []
    for name in names:
        params = PRESETS[name]
        predicted.append(params.balance_amplitude)
        over_pred.append(params.overturns)
        with warnings.catch_warnings():
            # The overturn warning is the point of this table; it is recorded, not shown.
            warnings.simplefilter("ignore")
            ds = simulate(
                1,
                check_bpm,
                preset=name,
                duration=CHECK_DURATION,
                theta0=[0.1],
                theta_dot0=[0.0],
                trajectories=True,
                progress=False,
            )
        tail = ds.time >= ds.time[-1] - CHECK_TAIL
        amp = float(np.abs(ds.theta.isel(run=0, metronome=0).where(tail, drop=True)).max())
        measured.append(amp)
        over_meas.append(bool(int(ds.status[0]) & 1))
        l2.append(params.metronome.l2_for_bpm(np.array(bpms)))
    return xr.Dataset(
        {
            "steady_amplitude": (
                "preset",
                predicted,
                {"units": "rad", "long_name": "energy-balance amplitude 2M/(pi c_theta)"},
            ),
            "overturns_predicted": ("preset", over_pred),
            "amplitude_measured": (
                "preset",
                measured,
                {
                    "units": "rad",
                    "long_name": f"max |theta| over the last {CHECK_TAIL:g} s, "
                    f"one metronome from 0.1 rad at {check_bpm:g} BPM",
                },
            ),
            "overturns_measured": ("preset", over_meas),
            "drive": ("preset", [PRESETS[n].metronome.drive for n in names], {"units": "N m s"}),
            "l2": (("preset", "bpm"), np.array(l2), {"units": "m"}),
        },
        coords={"preset": names, "bpm": ("bpm", bpms, {"units": "BPM"})},
        attrs={
            "paper_l2_range_m": list(PAPER_L2_RANGE),
            "check_bpm": check_bpm,
            "check_duration_s": CHECK_DURATION,
        },
    )


def markdown_table(ds: xr.Dataset) -> str:
    """The table as Markdown: one row per preset, then one row per BPM for L2."""
    lines = [
        "| preset | M (N m s) | steady amplitude 2M/(π c_θ) | overturns (predicted) "
        "| amplitude measured | overturns (measured) |",
        "|---|---|---|---|---|---|",
    ]
    for p in ds.preset.values:
        row = ds.sel(preset=p)
        amp = float(row.amplitude_measured)
        shown = f"{amp:.3f} rad" if amp < math.pi else f"{amp:.1f} rad (rotating)"
        lines.append(
            f"| {p} | {float(row.drive):.0e} | {float(row.steady_amplitude):.3f} rad "
            f"| {_yes(row.overturns_predicted)} | {shown} | {_yes(row.overturns_measured)} |"
        )
    lo, hi = ds.attrs["paper_l2_range_m"]
    lines += ["", f"L2 for each nominal BPM (same for every preset; paper quotes {lo}–{hi} m):", ""]
    lines += ["| ω₀ (BPM) | L2 (m) | inside the paper's range |", "|---|---|---|"]
    l2 = ds.l2.isel(preset=0)
    for bpm, value in zip(ds.bpm.values, l2.values, strict=True):
        lines.append(f"| {bpm:g} | {value:.4f} | {_yes(lo <= value <= hi)} |")
    return "\n".join(lines)


def _yes(flag) -> str:
    return "yes" if bool(flag) else "no"

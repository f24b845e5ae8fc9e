"""The rolling shutter: its readout time measured from how the moving rods look bent.

Contract: `estimate_readout(video, gauges, shape, times, seen, quality, skew)` returns
the readout time (top row to bottom row of the stored picture, s) and its standard
error, from every measured frame's rod skew (`metrosync.video.angles.RodGauge`);
`readout_verdict(readout, error, interval)` says whether that is a measurement, and
in words how it was found: a readout lies within 0 .. `longest_readout(interval)`, and
an error comparable to that range measures nothing (the rods turn too little across
the picture's rows for their skew to show it), so the readout is then taken as 0 (a
global shutter) and said to be unmeasured, not printed with its error.
"""

from __future__ import annotations

import math

import numpy as np

from .angles import MEASURED

#: Longest readout looked for, s (phones read a frame out in 5-35 ms).
MAX_READOUT = 0.05
#: Largest standard error, as a fraction of the range a readout can lie in, for an
#: estimate to count: at a quarter, ± two errors span half the range.
MAX_ERROR_SHARE = 0.25
#: Fewest frames measured cleanly for the skew to be fitted.
MIN_FRAMES = 20


def longest_readout(interval: float) -> float:
    """The longest possible readout, s: `MAX_READOUT`, or the frame interval (s) when
    shorter, since a sensor reads one frame out before it starts the next."""
    return min(MAX_READOUT, interval) if math.isfinite(interval) and interval > 0 else MAX_READOUT


def estimate_readout(video, gauges, shape, times, seen, quality, skew) -> tuple[float, float]:
    """The rolling shutter's readout time from the rods' skew, and its standard error, s.

    A rolling shutter exposes a rod's outer half at another moment than its inner half,
    so a rod turning at ω looks bent by ω · readout · (their rows' difference as a
    fraction of the stored picture). The skew of every measured frame (`RodGauge`)
    against ω times that difference, less each metronome's mean (a rod drawn slightly
    bent), gives the readout by least squares, within 0 .. `longest_readout` of the
    frames' median interval. NaN error when too few frames were measured.
    """
    longest = longest_readout(float(np.median(np.diff(times))) if len(times) > 1 else math.nan)
    xs, ys = [], []
    for j, gauge in enumerate(gauges):
        good = (quality[:, j] == MEASURED) & np.isfinite(skew[:, j])
        if good.sum() < MIN_FRAMES:
            continue
        phi = seen[:, j]
        omega = np.gradient(np.where(np.isfinite(phi), phi, 0.0), times)
        px, py = gauge.region.pivot
        rows = [video.stored_row(px + r * np.sin(phi), py - r * np.cos(phi), shape)
                for r in (gauge.radius_outer, gauge.radius_inner)]  # fmt: skip
        x = (omega * (rows[0] - rows[1]))[good]
        y = skew[good, j]
        keep = np.abs(y - np.median(y)) <= 5 * 1.4826 * np.median(np.abs(y - np.median(y))) + 1e-9
        xs.append(x[keep] - x[keep].mean())
        ys.append(y[keep] - y[keep].mean())
    if not xs:
        return 0.0, float("nan")
    x, y = np.concatenate(xs), np.concatenate(ys)
    sxx = float(np.dot(x, x))
    if sxx <= 0 or x.size < MIN_FRAMES:
        return 0.0, float("nan")
    slope = float(np.dot(x, y) / sxx)
    residual = y - slope * x
    error = float(np.sqrt(np.dot(residual, residual) / (x.size - 1) / sxx))
    return float(np.clip(slope, 0.0, longest)), error


def readout_verdict(readout: float, error: float, interval: float) -> tuple[float, float, str]:
    """(readout, error, how) for an estimate: the estimate itself when its error is
    small against the possible range, else (0, NaN, why it was not measured)."""
    longest = longest_readout(interval)
    if not math.isfinite(error):
        return 0.0, math.nan, "not measurable from the rods (too few frames measured cleanly)"
    if error > MAX_ERROR_SHARE * longest:
        why = (
            f"not measurable from the rods' skew: ± {error * 1e3:.0f} ms, where a readout lies "
            f"within 0..{longest * 1e3:.0f} ms (the rods turn too little across the picture's "
            f"rows for their skew to show it)"
        )
        return 0.0, math.nan, why
    return readout, error, f"estimated from the rods' skew, ± {error * 1e3:.1f} ms"

"""A rod's angle about its pivot in each picture, with a quality flag and a confidence.

Contract: a `RodGauge` is built once per metronome from its `Region` and the background
picture; ``gauge.measure(picture, gain)`` returns the angle (rad, from the picture's
upward direction, positive clockwise) and a strength, and `finish` turns the per-frame
measurements into angles with a quality flag and a confidence.

The picture is sampled on a polar grid about the pivot (angles across the swept sector
with a margin, radii along the rod), by bilinear interpolation at indices computed
once. What differs from the background there, summed along each ray (weighted by the
radius: far pixels tell the angle best), is the angular profile; the rod is its peak,
and the angle is the centroid of the peak's upper half. Several peaks (another rod
crossing the sector, where metronomes overlap in the picture) are told apart by
continuity: the one nearest the angle predicted from the previous two frames wins.
Identity is therefore tied to the pivot: a gauge only ever looks about its own pivot.

Quality flags: `MEASURED` (a clear peak), `INTERPOLATED` (no clear peak, filled from
the neighbours over a gap of at most ``max_gap`` frames), `LOST` (NaN).
"""

from __future__ import annotations

import numpy as np

from .sectors import Region

MEASURED, INTERPOLATED, LOST = 0, 1, 2
QUALITY_NAMES = "0 measured, 1 interpolated, 2 lost"
#: Extra angle on each side of the swept sector, rad.
MARGIN = 0.25


class RodGauge:
    """Measures one metronome's rod angle; see the module docstring."""

    def __init__(self, region: Region, bg: np.ndarray) -> None:
        h, w = bg.shape
        self.region = region
        px, py = region.pivot
        r_in = max(region.r_inner, 2.0)
        r_out = max(region.r_outer, r_in + 4.0)
        step = 1.0 / r_out  # a pixel at the far end; the centroid reads finer
        half = region.half_width + MARGIN
        self.angles = region.centre + np.arange(-half, half + step, step)
        radii = np.arange(r_in, r_out, 1.5)
        # the rod's inner and outer halves, read apart: a rolling shutter skews them
        self._split = max(1, radii.size // 2)
        self.radius_inner = float(np.average(radii[: self._split], weights=radii[: self._split]))
        self.radius_outer = float(np.average(radii[self._split :], weights=radii[self._split :]))
        a, r = np.meshgrid(self.angles, radii, indexing="ij")
        x = px + r * np.sin(a)
        y = py - r * np.cos(a)
        inside = (x >= 0) & (x <= w - 1) & (y >= 0) & (y <= h - 1)
        x, y = np.clip(x, 0, w - 1.001), np.clip(y, 0, h - 1.001)
        x0, y0 = np.floor(x).astype(np.intp), np.floor(y).astype(np.intp)
        fx, fy = (x - x0).astype(np.float32), (y - y0).astype(np.float32)
        base = y0 * w + x0
        self._index = np.stack([base, base + 1, base + w, base + w + 1])
        self._weight = np.stack([(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy])
        self._weight *= (inside * r).astype(np.float32)[None]
        # where on the rod the angle is read: the mean radius, weighted as the profile is
        mean_r = 2.0 / 3.0 * (r_out**3 - r_in**3) / (r_out**2 - r_in**2)
        self.point = (float(px + mean_r * np.sin(region.centre)),
                      float(py - mean_r * np.cos(region.centre)))  # fmt: skip
        self._bg = self._sample(bg.ravel())
        self._step = step
        self._prev: list[float] = []
        self._typical = 0.0  # running height of the rod's peak
        # the rod's angular width at mid-radius, in bins, sets the centroid's window
        self._half_window = int(np.clip(np.ceil(6.0 / (0.5 * (r_in + r_out)) / step), 2, 40))

    def _sample(self, flat: np.ndarray) -> np.ndarray:
        return np.einsum("kar,kar->ar", flat[self._index], self._weight)

    def measure(self, picture: np.ndarray, gain: float) -> tuple[float, float, float]:
        """(angle, strength, skew) in one grey picture (H, W) scaled by ``gain``: the
        strength is the peak's height over the rod's usual one; the skew is the angle of
        the rod's outer half less its inner half's. NaN angle when there is no peak."""
        differs = np.abs(self._sample(picture.ravel()) * gain - self._bg)
        inner = differs[:, : self._split].sum(axis=1)
        profile = inner + differs[:, self._split :].sum(axis=1)
        # the low quartile, not the median: other rods crossing the sector (metronomes
        # overlapping in the picture) raise the profile over many angles
        ranked = np.sort(profile)
        base = ranked[ranked.size // 4]
        # the spread of a normal profile from its quartile and median (one sort)
        spread = (ranked[ranked.size // 2] - base) / 0.6745 + 1e-6
        lifted = profile - base
        k = self._pick_peak(lifted, spread)
        if k is None:
            self._prev = []
            return float("nan"), 0.0, float("nan")
        lo, hi = max(0, k - self._half_window), min(lifted.size, k + self._half_window + 1)
        angle = _centroid(lifted[lo:hi], self.angles[lo:hi])
        outer = profile - inner
        skew = _centroid(outer[lo:hi] - outer[lo:hi].min(), self.angles[lo:hi]) - _centroid(
            inner[lo:hi] - inner[lo:hi].min(), self.angles[lo:hi]
        )
        self._prev = [*self._prev[-1:], angle]
        height = float(lifted[k])
        self._typical = height if not self._typical else 0.95 * self._typical + 0.05 * height
        return angle, height / self._typical, skew

    def _pick_peak(self, lifted: np.ndarray, spread: float) -> int | None:
        top = float(lifted.max())
        # a peak counts when it stands out of the profile's noise, or is as high as the
        # rod's usual peak (when other rods crowd the sector, its spread is no noise)
        if top < 6.0 * spread and not (self._typical and top >= 0.4 * self._typical):
            return None
        if len(self._prev) < 2:
            return int(np.argmax(lifted))
        predicted = 2 * self._prev[-1] - self._prev[-2]
        inner = lifted[1:-1]
        peaks = np.flatnonzero((inner >= lifted[:-2]) & (inner >= lifted[2:])
                               & (inner >= 0.5 * top)) + 1  # fmt: skip
        if peaks.size == 0:
            return int(np.argmax(lifted))
        return int(peaks[np.argmin(np.abs(self.angles[peaks] - predicted))])


def _centroid(profile: np.ndarray, angles: np.ndarray) -> float:
    """Centroid of the part of a peak above half its height."""
    weights = np.clip(profile - 0.5 * profile.max(), 0, None)
    total = weights.sum()
    return float(np.dot(weights, angles) / total) if total > 0 else float("nan")


def finish(
    angle: np.ndarray, strength: np.ndarray, time: np.ndarray, *, max_gap: int = 3
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quality and confidence for one metronome's per-frame measurements.

    angle, strength, time : (T,) from `RodGauge.measure` and the frame times.
    max_gap : longest run of frames without a clear peak that is interpolated.
    Returns (angle (T,) with short gaps filled, quality (T,) int8, confidence (T,) in
    [0, 1]). A measurement that jumps far from its neighbours' line (a wrong peak) is
    treated as lost. The confidence is the peak's height over the rod's usual one.
    """
    angle = np.array(angle, dtype=float)
    strength = np.asarray(strength, dtype=float)
    ok = np.isfinite(angle)
    if ok.sum() >= 5:
        idx = np.flatnonzero(ok)
        # a measurement far off the line through its neighbours is a wrong peak
        mid = 0.5 * (angle[idx[:-2]] + angle[idx[2:]])
        off = np.abs(angle[idx[1:-1]] - mid)
        scale = np.median(np.abs(np.diff(angle[idx]))) + 1e-6
        bad = idx[1:-1][off > 4.0 * scale + 0.05]
        angle[bad] = np.nan
        ok[bad] = False
    quality = np.where(ok, MEASURED, LOST).astype(np.int8)
    confidence = np.where(ok, np.clip(strength, 0, 1), 0.0)
    if ok.sum() >= 2:
        lost = np.flatnonzero(~ok)
        runs = np.split(lost, np.flatnonzero(np.diff(lost) > 1) + 1) if lost.size else []
        good = np.flatnonzero(ok)
        for run in runs:
            if run.size <= max_gap and run[0] > good[0] and run[-1] < good[-1]:
                angle[run] = np.interp(time[run], time[ok], angle[ok])
                quality[run] = INTERPOLATED
                confidence[run] = 0.5 * confidence[max(run[0] - 1, 0)]
    return angle, quality, confidence


def swing_middle_in_time(time: np.ndarray, angle: np.ndarray) -> float:
    """The angle seen when the rod is midway in time between its extremes, rad.

    time, angle : (T,) per-frame times and angles (NaN allowed). A swing that is
    symmetric about the vertical crosses it midway in time between a turn on one side
    and the next on the other; the angle seen then is the picture's image of the
    vertical, whatever the perspective does to the angles in between (it keeps their
    order, and so the times of the turns). Median over half-swings; NaN if none.
    """
    t = np.asarray(time, dtype=float)
    a = np.asarray(angle, dtype=float)
    ok = np.isfinite(a)
    if ok.sum() < 8:
        return float("nan")
    t, x = t[ok], a[ok]
    centre = np.median(x)
    big = 0.5 * np.percentile(np.abs(x - centre), 95)
    left, mid, right = x[:-2], x[1:-1], x[2:]
    curv = left - 2 * mid + right
    turn = np.flatnonzero(((mid > left) & (mid >= right) & (mid - centre > big))
                          | ((mid < left) & (mid <= right) & (centre - mid > big))) + 1  # fmt: skip
    if turn.size < 2:
        return float(centre)
    c = curv[turn - 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        shift = np.where(c != 0, 0.5 * (x[turn - 1] - x[turn + 1]) / c, 0.0)
    shift = np.clip(shift, -1, 1)
    step = np.where(shift >= 0, t[turn + 1] - t[turn], t[turn] - t[turn - 1])
    when = t[turn] + shift * step
    side = x[turn] > centre
    halves = np.flatnonzero(side[:-1] != side[1:])  # a turn, then one on the other side
    if halves.size == 0:
        return float(centre)
    middle = 0.5 * (when[halves] + when[halves + 1])
    return float(np.median(np.interp(middle, t, x)))

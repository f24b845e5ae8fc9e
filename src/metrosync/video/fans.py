"""Metronomes whose rod barely shows, found from the arc their bob sweeps.

Contract: `arc_regions(pictures, bg, gain, known)` returns a `Region` for each
swinging metronome that lies outside the ``known`` regions: one whose rod has nearly
its body's shade, so that no picture shows lines through its pivot.

Over the first seconds a pendulum sweeps a fan whose apex is its pivot; its bob, larger
than the rod and seldom of the body's shade too, sweeps an arc at the fan's far edge.
The per-pixel rms motion (what differs from the background, in units of the noise of
pixels of the same shade) shows that arc as a long, thin bright piece, lying across
the direction in which the rods rise. The fan's apex lies on the arc's perpendicular
through its middle, at a distance set by the arc's half chord: a swing of 0.3 to 0.5 rad
seen from 20 to 40° aside spans half a chord of 0.3 to 0.45 times the bob's radius.
Neither the arc's curvature nor the faint fan gives that distance better: seen from
aside the arc flattens into part of an ellipse, and the fan of a rod of its body's shade
moves barely above the noise. So such a pivot is rougher than one that rod lines give.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .sectors import Region, covers

#: Smallest rms motion of a bob's arc, in units of the noise.
ARC_RISE = 4.0
#: Smallest arc, as a fraction of the picture's pixels.
MIN_ARC = 1.5e-4
#: Shortest arc, as its length over its thickness (a thick short arc: a small swing).
ARC_LENGTH = 1.6
#: Distance from the middle of a bob's arc to its pivot, in half chords of the arc.
PIVOT_REACH = 2.7
#: Largest part of an arc that may lie in a known region's sector.
MAX_KNOWN = 0.3


def motion_map(pictures: np.ndarray, bg: np.ndarray, gain: np.ndarray) -> np.ndarray:
    """Per-pixel rms difference from the background (H, W) over the noise of the pixels
    of the same background shade (noise grows with brightness), smoothed: near 1 where
    nothing moves. Every fourth picture is enough for a swing's sweep."""
    sub = pictures[::4] * gain[::4, None, None] - bg[None]
    rms = np.sqrt(np.mean(sub * sub, axis=0))
    shade = np.clip((bg // 16).astype(int), 0, 15)
    # most pixels of each shade stand still: their median motion (over every other
    # row and column, which is plenty) is the noise
    level = ndimage.median(rms[::2, ::2], shade[::2, ::2], index=np.arange(16))
    level = np.asarray(level, dtype=float)
    level = np.where(np.isfinite(level), level, np.median(rms))
    return ndimage.gaussian_filter(rms / np.maximum(level[shade], 0.5), 1.0)


def arc_regions(pictures: np.ndarray, bg: np.ndarray, gain: np.ndarray,
                known: list[Region]) -> list[Region]:  # fmt: skip
    """Regions of the metronomes whose bob's arc lies outside the ``known`` regions.

    pictures : (F, H, W) grey pictures.   bg, gain : from `detection.background`.
    known : regions found already; their rods give the direction in which rods rise
        (upward in the picture when there is none).
    """
    z = motion_map(pictures, bg, gain)
    h, w = z.shape
    # the metronomes stand on one table: their rods rise the same way
    up = float(np.angle(np.mean([np.exp(1j * r.centre) for r in known]))) if known else 0.0
    labels, _ = ndimage.label(z > ARC_RISE)
    found: list[Region] = []
    for index, box in enumerate(ndimage.find_objects(labels), start=1):
        ys, xs = np.nonzero(labels[box] == index)
        if ys.size < MIN_ARC * h * w:
            continue
        xs = xs + float(box[1].start)
        ys = ys + float(box[0].start)
        seen = np.zeros(xs.size, dtype=bool)
        for region in known + found:  # a known rod's own bob, or its pieces
            seen |= covers(region, xs, ys)
        if seen.mean() > MAX_KNOWN:
            continue
        region = _from_arc(xs, ys, up)
        if region is not None:
            found.append(region)
    return found


def _from_arc(xs: np.ndarray, ys: np.ndarray, up: float) -> Region | None:
    """The region of the rod whose bob swept the piece (xs, ys), rods rising in the
    direction ``up`` (rad from the picture's upward, clockwise); None if no arc."""
    mx, my = xs.mean(), ys.mean()
    values, vectors = np.linalg.eigh(np.cov(np.stack([xs - mx, ys - my])))
    if values[1] < ARC_LENGTH**2 * max(values[0], 1e-6):  # a blob, not an arc
        return None
    ex, ey = vectors[:, 1]  # along the arc
    ux, uy = np.sin(up), -np.cos(up)
    if abs(ex * ux + ey * uy) > 0.5:  # an arc lies across the rods, not along them
        return None
    half_chord = float(np.percentile(np.abs((xs - mx) * ex + (ys - my) * ey), 95))
    px, py = mx - PIVOT_REACH * half_chord * ux, my - PIVOT_REACH * half_chord * uy
    dx, dy = xs - px, ys - py
    off = np.angle(np.exp(1j * (np.arctan2(dx, -dy) - up)))
    lo, hi = np.percentile(off, [5, 95])
    radius = np.hypot(dx, dy)
    return Region(pivot=(float(px), float(py)),
                  centre=float(np.angle(np.exp(1j * (up + 0.5 * (lo + hi))))),
                  half_width=float(0.5 * (hi - lo)),
                  r_inner=float(0.5 * np.percentile(radius, 5)),
                  r_outer=float(np.percentile(radius, 95)), support=0.0)  # fmt: skip

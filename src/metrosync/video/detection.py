"""Finding the metronomes in a video: where the picture moves, and about which pivot.

Contract: `find_metronomes(pictures, count=None)` takes grey pictures (F, H, W) from the
first seconds of a video and returns one `Region` per metronome, sorted left to right:
its pivot (pixels), the directions its rod sweeps (from the pivot) and the radii its
rod covers. No marker is needed; only that the rods swing and the camera stands still.

The method:

1. the background is the per-pixel median of the pictures, after each picture's
   brightness is scaled to the median's (lighting flicker);
2. in each picture, what differs from the background by more than the noise is a
   moving part; each connected piece of it that is long and thin is a rod, and
   gives a line (its principal axis);
3. every line votes along its length into an accumulator: the lines of one rod, at
   different moments, all pass through its pivot, so pivots are the accumulator's
   peaks, while lines of different rods cross at scattered points;
4. the lines near each pivot give the swept sector and the radii (a peak a few pixels
   off its pivot is moved to the best supported point near it); a peak just behind
   another pivot, where neighbouring rods' lines prolonged past their pivots meet,
   and a peak inside another's sector, a point on that rod, are dropped;
5. a rod of its body's shade gives no lines: its bob's arc gives it (`fans`).

`regions_given` builds the regions for pivots or boxes given by hand (``--regions``).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .._words import plural
from ..errors import MetrosyncError
from .fans import arc_regions
from .sectors import Region, covers

#: Fewest pictures in which a rod is seen through a pivot, as a fraction, for it to count.
MIN_SUPPORT = 0.25
#: Fewest pictures, as a fraction, in which a pivot with few votes must be seen.
FAINT_SUPPORT = 0.7
#: Largest amplitude of a swing, as seen, rad.
MAX_SWING = 1.0
#: Weakest pivot kept, as a fraction of the strongest one's votes: where rods overlap in
#: the picture, their lines cross at points between the pivots too, with fewer votes.
MIN_PEAK = 0.4
#: What differs from the background by more than RISE times the noise (and MIN_RISE grey
#: levels) is a moving part: 4 and 8 rather than 6 and 12 found the right number in 37
#: of 48 generated scenes instead of 30, and never one too many.
RISE, MIN_RISE = 4.0, 8.0
#: Smallest moving piece that can give a line, as a fraction of the picture's pixels:
#: a faint rod moves in short pieces (6e-5 rather than 2e-4: 40 of 48 scenes instead of 37).
MIN_PIECE = 6e-5


class DetectionError(MetrosyncError, ValueError):
    """No metronome, or not the number asked for, could be found in the picture."""


def background(pictures: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(median picture (H, W), per-picture brightness gain (F,)) of pictures (F, H, W).

    The median is taken over at most 61 pictures spread over the stretch: enough for a
    rod, which passes any point in a small part of the time, to vanish from it."""
    pictures = np.asarray(pictures)
    every = max(1, int(np.ceil(len(pictures) / 61)))
    bg = np.median(pictures[::every], axis=0).astype(np.float32)
    level = float(bg[::4, ::4].mean()) + 1e-6
    gain = level / (pictures[:, ::4, ::4].mean(axis=(1, 2)) + 1e-6)
    return bg, gain.astype(np.float32)


def rod_lines(pictures: np.ndarray, bg: np.ndarray, gain: np.ndarray) -> list[np.ndarray]:
    """Per picture, the lines of the long thin moving pieces: (L, 5) arrays of
    centroid x, y, direction ux, uy (unit), and half-length (pixels)."""
    diff = np.abs(pictures * gain[:, None, None] - bg[None])
    sample = diff[:: max(1, len(diff) // 16)]
    level = np.median(sample)
    noise = 1.4826 * np.median(np.abs(sample - level))
    # low enough for a rod of nearly its body's shade: a dark rod on a dark body, or a
    # light one on a light body, differs from the background by a few grey levels only
    threshold = max(RISE * noise + level, MIN_RISE)
    min_pixels = max(12, int(MIN_PIECE * bg.size))
    return [_lines(frame > threshold, min_pixels) for frame in diff]


def _lines(mask: np.ndarray, min_pixels: int) -> np.ndarray:
    """(L, 5) principal axes of the connected pieces of ``mask`` that are long and thin."""
    labels, count = ndimage.label(mask)
    if count == 0:
        return np.empty((0, 5))
    ys, xs = np.nonzero(labels)
    lab = labels[ys, xs]
    xs, ys = xs.astype(float), ys.astype(float)
    n = np.bincount(lab, minlength=count + 1)[1:]
    big = n >= min_pixels
    if not big.any():
        return np.empty((0, 5))

    def total(w):
        return np.bincount(lab, weights=w, minlength=count + 1)[1:][big]

    n = n[big].astype(float)
    cx, cy = total(xs) / n, total(ys) / n
    sxx = total(xs * xs) / n - cx**2
    syy = total(ys * ys) / n - cy**2
    sxy = total(xs * ys) / n - cx * cy
    # eigenvalues and the major axis of each piece's 2x2 covariance
    half_trace, det = 0.5 * (sxx + syy), sxx * syy - sxy**2
    root = np.sqrt(np.maximum(half_trace**2 - det, 0.0))
    major, minor = half_trace + root, half_trace - root
    angle = 0.5 * np.arctan2(2 * sxy, sxx - syy)
    thin = (major > 0) & (minor <= 0.2 * major)
    return np.stack([cx, cy, np.cos(angle), np.sin(angle), 2.0 * np.sqrt(np.maximum(major, 0))],
                    axis=1)[thin]  # fmt: skip


def vote(lines: list[np.ndarray], shape: tuple[int, int]) -> np.ndarray:
    """Accumulator (H, W): each line adds 1 along its length, extended to twice it each
    way (the pivot lies beyond the moving piece's end)."""
    h, w = shape
    acc = np.zeros(shape)
    for frame_lines in lines:
        seen = np.zeros(shape, dtype=bool)
        for cx, cy, ux, uy, half in frame_lines:
            s = np.arange(-2.0 * half, 2.0 * half, 0.7)
            x = np.rint(cx + s * ux).astype(int)
            y = np.rint(cy + s * uy).astype(int)
            inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
            seen[y[inside], x[inside]] = True
        acc += seen
    return ndimage.gaussian_filter(acc, 1.5)


def find_metronomes(pictures: np.ndarray, *, count: int | None = None) -> list[Region]:
    """The metronomes in pictures (F, H, W) of the first seconds; see the module docstring.

    count : the number of metronomes; default: every pivot that enough lines cross.
    Raises `DetectionError` when nothing moves, or fewer than ``count`` are found.
    """
    pictures = np.asarray(pictures, dtype=np.float32)
    f, h, w = pictures.shape
    bg, gain = background(pictures)
    per_picture = rod_lines(pictures, bg, gain)
    moving = sum(len(x) > 0 for x in per_picture)
    if moving < max(3, 0.2 * f):
        raise DetectionError(
            f"nothing swings in the first {plural(f, 'frame')}: no rod moves against the "
            f"background. Check that the metronomes are running and in view, and that the "
            f"camera stands still; or give the pivots by hand with `regions`."
        )
    acc = vote(per_picture, (h, w))
    lines = _stack(per_picture)
    peaks = _peaks(acc, min_distance=max(4, int(0.02 * max(h, w))))
    floor = max(MIN_PEAK * acc[peaks[0][1], peaks[0][0]], 0.1 * f) if peaks else 0.0
    chosen = [p for p in peaks if acc[p[1], p[0]] >= floor]
    regions = [r for r in (_region(p, lines, f) or _nearby(p, lines, f) for p in chosen) if r]
    # A faint rod (dark on a dark body) gives short, scattered lines: few votes, but
    # through its pivot in most pictures, which crossings of other rods never are.
    faint = [p for p in peaks if 0.25 * floor <= acc[p[1], p[0]] < floor]
    regions += [r for r in (_region(p, lines, f) for p in faint)
                if r is not None and r.support >= FAINT_SUPPORT]  # fmt: skip
    # a rod of its body's shade gives no lines at all, but its bob sweeps an arc
    regions += arc_regions(pictures, bg, gain, regions)
    if count is not None:  # the strongest `count`, if not much weaker than the best
        weaker = [p for p in peaks if 0.6 * floor <= acc[p[1], p[0]] < floor]
        more = [r for r in (_region(p, lines, f) for p in weaker) if r is not None]
        regions = (regions + [r for r in more if r.support >= 2 * MIN_SUPPORT])[:count]
    if count is not None and len(regions) < count:
        raise DetectionError(
            f"found {len(regions)} swinging metronomes, not the {count} asked for by `count`. "
            f"Check that every rod swings in view in the first seconds, or give the pivots "
            f"by hand with `regions`."
        )
    if not regions:
        raise DetectionError(
            "things move in the picture but no rod swings about a fixed pivot. Check that "
            "the camera stands still, or give the pivots by hand with `regions`."
        )
    regions = _drop_duplicates(regions)
    return sorted(regions, key=lambda r: (r.pivot[0], r.pivot[1]))


def _peaks(acc: np.ndarray, min_distance: int) -> list[tuple[int, int]]:
    """Local maxima (x, y) of ``acc``, strongest first."""
    top = ndimage.maximum_filter(acc, size=2 * min_distance + 1)
    ys, xs = np.nonzero((acc == top) & (acc > 0))
    order = np.argsort(-acc[ys, xs])
    return [(int(xs[i]), int(ys[i])) for i in order]


def _stack(lines: list[np.ndarray]) -> np.ndarray:
    """The lines of every picture in one (M, 6) array: the picture's index, then the line."""
    if not any(len(x) for x in lines):
        return np.empty((0, 6))
    return np.concatenate([np.column_stack([np.full(len(x), i), x])
                           for i, x in enumerate(lines) if len(x)])  # fmt: skip


def _region(pivot, lines: np.ndarray, frames: int) -> Region | None:
    """The sector swept by the lines (`_stack`) that pass near ``pivot`` (the rod's lines)."""
    px, py = pivot
    frame, cx, cy, ux, uy, half = lines.T
    dx, dy = cx - px, cy - py
    dist = np.abs(dx * uy - dy * ux)  # distance of the pivot from the line
    along = np.hypot(dx, dy)
    # the pivot lies beyond the end of a rod's piece, not inside it (where rods cross)
    near_line = (dist < np.maximum(3.0, 0.08 * along)) & (along > 0.8 * half)
    # in each picture, the line that passes nearest
    order = np.flatnonzero(near_line)[np.lexsort((dist[near_line], frame[near_line]))]
    best = order[np.unique(frame[order], return_index=True)[1]]
    angles = np.arctan2(dx[best], -dy[best])
    near = np.maximum(along[best] - half[best], 0.0)
    far = along[best] + half[best]
    support = len(angles) / frames
    if support < MIN_SUPPORT or len(angles) < 3:
        return None
    a = np.unwrap(np.array(angles))
    lo, hi = np.percentile(a, [2, 98])
    if hi - lo > 2 * MAX_SWING:  # lines through the point from all sides: rods crossing
        return None
    centre = float(np.angle(np.exp(1j * 0.5 * (lo + hi))))
    return Region(
        pivot=(float(px), float(py)),
        centre=centre,
        half_width=float(max(0.5 * (hi - lo), 0.05)),
        r_inner=float(np.percentile(near, 20)),
        r_outer=float(np.percentile(far, 90)),
        support=float(support),
    )


def _nearby(pivot, lines: np.ndarray, frames: int, reach: int = 8) -> Region | None:
    """The best supported region about the points within ``reach`` pixels of ``pivot``.

    The votes of a rod whose pieces reach nearly to its pivot can peak a few pixels
    inside them, where `_region` finds no line ending short of the point."""
    best = None
    for dy in range(-reach, reach + 1, 2):
        for dx in range(-reach, reach + 1, 2):
            region = _region((pivot[0] + dx, pivot[1] + dy), lines, frames)
            if region is not None and (best is None or region.support > best.support):
                best = region
    return best


def _drop_duplicates(regions: list[Region]) -> list[Region]:
    """A peak inside another's swept sector is a point on that rod (where its pieces'
    lines meet, at the bob): keep the better supported of the two. A peak just behind
    another's pivot, on the far side from its rod, is where the lines of neighbouring
    rods, prolonged past their pivots, meet: drop it, however well supported."""
    ghosts = [r for r in regions if any(_behind(k, *r.pivot) for k in regions if k is not r)]
    kept: list[Region] = []
    for r in sorted((r for r in regions if r not in ghosts), key=lambda r: -r.support):
        if not any(covers(k, *r.pivot) for k in kept):
            kept.append(r)
    return kept


def _behind(region: Region, x: float, y: float) -> bool:
    """Whether (x, y) lies in ``region``'s sector mirrored through its pivot, within half
    its outer radius (the rod's lines prolonged past the pivot)."""
    dx, dy = x - region.pivot[0], y - region.pivot[1]
    off = np.angle(np.exp(1j * (np.arctan2(dx, -dy) - region.centre - np.pi)))
    radius = np.hypot(dx, dy)
    return bool(4.0 <= radius <= 0.5 * region.r_outer and abs(off) <= region.half_width + 0.15)


def regions_given(
    regions: list[tuple[float, ...]], pictures: np.ndarray, *, scale: float = 1.0
) -> list[Region]:
    """Regions for metronomes given by hand, in the pictures' pixels: a pivot ``(x, y)``
    gets the sector of the rod seen about it (upward ± 45° when none is seen inside the
    picture; a `DetectionError` outside it); a box ``(x0, y0, x1, y1)`` is searched for
    one metronome. ``scale`` : the pictures' pixels per video pixel, for messages."""
    pictures = np.asarray(pictures, dtype=np.float32)
    f, h, w = pictures.shape
    bg, gain = background(pictures)
    lines = _stack(rod_lines(pictures, bg, gain))
    out = []
    for given in regions:
        shown = "(" + ", ".join(f"{v / scale:.0f}" for v in given) + ")"  # the video's pixels
        if len(given) == 4:
            x0, y0 = int(max(0, given[0])), int(max(0, given[1]))
            x1, y1 = int(min(w, np.ceil(given[2]))), int(min(h, np.ceil(given[3])))
            if x1 - x0 < 8 or y1 - y0 < 8:
                raise DetectionError(
                    f"the box {shown} is smaller than 8 pixels or outside the picture "
                    f"({w}x{h} as analysed); check the regions file."
                )
            try:
                (found,) = find_metronomes(pictures[:, y0:y1, x0:x1], count=1)
            except DetectionError:
                raise DetectionError(
                    f"no rod swings about a fixed pivot inside the box {shown}; give its "
                    f"pivot instead ('x y')."
                ) from None
            px, py = found.pivot
            out.append(Region((px + x0, py + y0), found.centre, found.half_width,
                              found.r_inner, found.r_outer, found.support))  # fmt: skip
            continue
        x, y = given
        region = _region((x, y), lines, f)
        if region is None and not (0 <= x <= w - 1 and 0 <= y <= h - 1):
            # the guess below looks up from the pivot, which outside the picture sees nothing
            raise DetectionError(
                f"no rod is seen swinging about the pivot {shown}, "
                f"outside the video's picture: a pivot out of view needs its rod to swing in "
                f"view in the first seconds; check its coordinates, or give a box round the "
                f"swing instead."
            )
        if region is None:
            region = Region((float(x), float(y)), 0.0, np.pi / 4, 3.0, 0.2 * max(h, w), 0.0)
        out.append(region)
    return out

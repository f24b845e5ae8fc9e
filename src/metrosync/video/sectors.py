"""Where a metronome is in the picture: its pivot and the sector its rod sweeps.

Contract: `Region` describes one metronome's swept sector; `covers(region, x, y)` says
which points lie in it. Both the rod lines of `detection` and the arcs of `fans` give
regions, and each stage must know what the others have found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Angle, rad, by which a sector is widened when asking what it covers: a rod's
#: pieces and its bob reach a little beyond the directions its lines were seen in.
MARGIN = 0.15


@dataclass(frozen=True)
class Region:
    """Where one metronome is in the picture.

    pivot : (x, y) of the rod's pivot, pixels (x right, y down).
    centre : direction of the middle of the swing from the pivot, rad, measured from
        the picture's upward direction, positive clockwise (to the right).
    half_width : half the swept angle, rad (the swing's amplitude seen in the picture).
    r_inner, r_outer : radii from the pivot that the rod covers, pixels.
    support : fraction of the pictures in which this rod was seen through its pivot
        (0 for a rod found from its bob's arc alone).
    """

    pivot: tuple[float, float]
    centre: float
    half_width: float
    r_inner: float
    r_outer: float
    support: float


def covers(region: Region, x, y) -> np.ndarray:
    """Whether the points (x, y) (arrays or numbers, pixels) lie in the sector that
    ``region``'s rod sweeps, or within 4 pixels of its pivot."""
    dx = np.asarray(x, dtype=float) - region.pivot[0]
    dy = np.asarray(y, dtype=float) - region.pivot[1]
    radius = np.hypot(dx, dy)
    off = np.angle(np.exp(1j * (np.arctan2(dx, -dy) - region.centre)))
    return (radius <= 1.1 * region.r_outer) & (
        (radius < 4.0) | (np.abs(off) <= region.half_width + MARGIN)
    )

"""Metronomes given by hand (``--regions FILE``), for when finding them fails.

Contract: `read_regions(path)` reads a text file with one metronome per line, in the
pixels of the video as it is shown (upright, full size; x from the left, y from the
top), and returns a list of tuples:

* ``x y``: the rod's pivot;
* ``x0 y0 x1 y1``: a box around the rod's whole swing; the pivot is found inside it.

Numbers are separated by spaces or commas; ``#`` starts a comment; blank lines are
ignored. Any other line is a `ParameterError` naming the file, the line and the fix.

A pivot may lie outside the picture: a pendulum hung from above the frame is filmed
with its pivot out of view, and the rod's angle is read where the rod shows, about the
pivot given (`metrosync.video.angles`). How far outside is bounded by `OUTSIDE_REACH`,
and a box must overlap the picture, since its pivot is found in what it shows;
`check_in_frame` says so once the video's size is known.
"""

from __future__ import annotations

import math
from pathlib import Path

from .._input_files import check_input_file
from ..errors import ParameterError

FORMAT = (
    "each line 'x y' (a pivot) or 'x0 y0 x1 y1' (a box), in the video's pixels (x from the "
    "left, y from the top)"
)
#: Farthest a given pivot may lie outside the picture, as a multiple of the picture's
#: longer side: its rod must reach into view, and a rod longer than the picture seen
#: from farther off crosses the picture almost straight, with too little of its swing
#: in view to time it; a number much beyond that is a typing error.
OUTSIDE_REACH = 1.0
#: Fewest pixels by which a box must overlap the picture each way (as `detection` needs).
MIN_BOX = 8


def read_regions(path: str | Path) -> list[tuple[float, ...]]:
    """The pivots and boxes in ``path``; see the module docstring."""
    path = check_input_file(path, "`regions` file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        why = error.strerror if isinstance(error, OSError) else "not a text file"
        raise ParameterError(f"cannot read `regions` file {str(path)!r} ({why}).") from None
    out = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].replace(",", " ").strip()
        if not line:
            continue
        try:
            values = tuple(float(v) for v in line.split())
        except ValueError:
            values = ()
        if len(values) not in (2, 4) or not all(math.isfinite(v) for v in values):
            raise ParameterError(
                f"`regions` file {str(path)!r} line {number}: {line!r} is not {FORMAT}."
            )
        if len(values) == 4 and (values[2] <= values[0] or values[3] <= values[1]):
            raise ParameterError(
                f"`regions` file {str(path)!r} line {number}: the box {line!r} must give its "
                f"top-left corner (x0 y0) before its bottom-right one (x1 y1)."
            )
        out.append(values)
    if not out:
        raise ParameterError(f"`regions` file {str(path)!r} holds no region; write {FORMAT}.")
    return out


def check_in_frame(regions: list[tuple[float, ...]], size: tuple[int, int]) -> None:
    """Refuse (`ParameterError`) a region the video of ``size`` (width, height as shown)
    cannot show: a pivot farther outside than `OUTSIDE_REACH`, a box that misses it."""
    w, h = size
    reach = OUTSIDE_REACH * max(w, h)
    for k, given in enumerate(regions, start=1):
        which = f"`regions` {k} of {len(regions)}"
        if len(given) == 2:
            x, y = given
            off = [
                (-x, "left of"), (x - (w - 1), "right of"), (-y, "above"), (y - (h - 1), "below"),
            ]  # fmt: skip
            beyond = [(d, side) for d, side in off if d > reach]
            if beyond:
                d, side = max(beyond)
                raise ParameterError(
                    f"{which}, the pivot ({x:g}, {y:g}), lies {d:.0f} px {side} the video's "
                    f"{w}x{h} picture; a pivot must lie inside it (x 0..{w - 1}, y 0..{h - 1}), "
                    f"or outside by at most {reach:.0f} px (a pendulum hung above the frame) "
                    f"with its rod in view. Check its coordinates, in the video's pixels."
                )
            continue
        x0, y0, x1, y1 = given
        if min(x1, w) - max(x0, 0) < MIN_BOX or min(y1, h) - max(y0, 0) < MIN_BOX:
            raise ParameterError(
                f"{which}, the box ({x0:g}, {y0:g}) .. ({x1:g}, {y1:g}), shows less than "
                f"{MIN_BOX} px of the video's {w}x{h} picture (x 0..{w - 1}, y 0..{h - 1}); "
                f"the pivot is looked for inside the box, so it must cover the swing in view."
            )

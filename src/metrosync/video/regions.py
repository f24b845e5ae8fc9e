"""Metronomes given by hand (``--regions FILE``), for when finding them fails.

Contract: `read_regions(path)` reads a text file with one metronome per line, in the
pixels of the video as it is shown (upright, full size; x from the left, y from the
top), and returns a list of tuples:

* ``x y``: the rod's pivot;
* ``x0 y0 x1 y1``: a box around the rod's whole swing; the pivot is found inside it.

Numbers are separated by spaces or commas; ``#`` starts a comment; blank lines are
ignored. Any other line is a `ParameterError` naming the file, the line and the fix.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import ParameterError

FORMAT = "each line 'x y' (a pivot) or 'x0 y0 x1 y1' (a box), in the video's pixels"


def read_regions(path: str | Path) -> list[tuple[float, ...]]:
    """The pivots and boxes in ``path``; see the module docstring."""
    path = Path(path)
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
        if len(values) not in (2, 4) or not all(math.isfinite(v) and v >= 0 for v in values):
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

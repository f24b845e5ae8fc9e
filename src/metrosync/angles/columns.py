"""Which columns of a table are a pendulum's time and angle: `AngleColumns`, `swings`.

Contract: `swings(table, columns)` returns one `Swing` per pendulum in the table:
its times in seconds and a coordinate that crosses its rest value when the bob passes
the bottom of its swing (the vertical), with the table line of every sample. Each
group of columns (a Tracker track, see `table`) holds one pendulum or more; a column
under no group label (Tracker's shared ``t``) belongs to every group.

A pendulum's coordinate is, in this order of preference:

1. an angle column (auto: named ``theta``, ``θ``, ``angle``, ``phi``, ``φ``, Tracker's
   ``θ_{r}``, each maybe followed by a label, ``theta 2``, ``angle_B``; each one a
   pendulum), in its own unit;
2. the bob's ``x`` and ``y`` (auto: named so, maybe with a label, ``x1``/``y1``), as
   the angle about a pivot given for it, θ = atan2(x − X, Y − y) unwrapped, in rad
   (y up or down, and wherever the vertical points, the rest is measured, not assumed);
3. ``x`` and ``y`` without a pivot: the bob's position along the principal axis of its
   path. On a circle about the pivot, the position along the tangent at the bottom is
   L·sin(θ − θ_rest), which crosses its rest value exactly when θ does, so the passes
   are the angle's; only the swing's size is then a length, not an angle.

Units: the time column's unit is read from its header (``t (s)``, ``time_ms``,
``millis``, ``micros``; default seconds), the angle's (``deg``, ``°``, ``rad``; default
unknown, and only the reported rest angle and swing need it) unless given. A
column named or numbered that the table lacks is an `AngleTableError` listing the
columns it has.
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._words import plural
from ..errors import ParameterError
from .table import AngleTableError, Column, Table

#: Seconds per unit of time, by the unit's names in headers.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
_TIME_WORDS = {"s": "s", "sec": "s", "secs": "s", "second": "s", "seconds": "s",
               "ms": "ms", "msec": "ms", "millis": "ms", "millisecond": "ms",
               "milliseconds": "ms", "us": "us", "µs": "us", "μs": "us", "micros": "us",
               "microsecond": "us", "microseconds": "us"}  # fmt: skip
_ANGLE_WORDS = {"deg": "deg", "degree": "deg", "degrees": "deg", "°": "deg", "rad": "rad",
                "radian": "rad", "radians": "rad"}  # fmt: skip
_TIME_NAMES = {"t", "time", "times", "timestamp", "seconds", "sec", "millis", "micros"}
_ANGLE_NAMES = ("theta", "θ", "angle", "phi", "φ", "ang")
#: Tracker's angles of velocity, acceleration and momentum: not the pendulum's angle.
_NOT_ANGLES = re.compile(r"^(θ|theta)_?\{?[vap]\}?$")
#: Tracker's polar angle of the position about its origin: the pendulum's angle only
#: where the origin was put on the pivot, so x and y are preferred to it.
_POLAR = re.compile(r"^(θ|theta)_?\{?r\}?$")
_LABEL = r"(?:[ _\-]?\{?[0-9a-z]{1,3}\}?)?"
_ANGLE = re.compile(rf"^(?:{'|'.join(_ANGLE_NAMES)}){_LABEL}$")
_XY = {axis: re.compile(rf"^{axis}{_LABEL}$") for axis in "xy"}


@dataclass(frozen=True)
class AngleColumns:
    """Which columns hold the pendulums, and in what units.

    time : the time column's name or 1-based number; None: the one named as a time.
    angle : names or numbers of angle columns (each a pendulum, in every group);
        empty: those named as angles.
    x, y : the name or number of the bob's position columns, used where there is no
        angle column; None: those named ``x`` and ``y``.
    pivot : one (X, Y) per pendulum in the table's unit of length; empty: the
        crossings are found along the path's principal axis (module docstring).
    time_unit : ``"auto"`` (from the header, default s), ``"s"``, ``"ms"`` or ``"us"``.
    angle_unit : ``"auto"`` (from the header, else not stated), ``"deg"`` or ``"rad"``.
    """

    time: str | None = None
    angle: tuple[str, ...] = ()
    x: str | None = None
    y: str | None = None
    pivot: tuple[tuple[float, float], ...] = ()
    time_unit: str = "auto"
    angle_unit: str = "auto"

    def __post_init__(self) -> None:
        if self.time_unit not in ("auto", *TIME_UNITS):
            raise ParameterError(
                f"`time_unit` must be 'auto', 's', 'ms' or 'us', got {self.time_unit!r}."
            )
        if self.angle_unit not in ("auto", "deg", "rad"):
            raise ParameterError(
                f"`angle_unit` must be 'auto', 'deg' or 'rad', got {self.angle_unit!r}."
            )
        if (self.x is None) != (self.y is None):
            raise ParameterError(
                f"give both `x` and `y` (the bob's position columns), got x={self.x!r}, "
                f"y={self.y!r}."
            )
        for p in self.pivot:
            if len(p) != 2 or not all(np.isfinite(v) for v in p):
                raise ParameterError(f"each `pivot` must be two finite numbers X, Y, got {p!r}.")
        if self.pivot and self.angle:
            raise ParameterError("`pivot` is for x and y columns; angle columns need none.")


@dataclass(frozen=True)
class Swing:
    """One pendulum's sampled coordinate.

    name : how the summary names it (``"mass A"``, ``"theta2"``, ``"column 2"``).
    time : (S,) s, as the table gives it.
    value : (S,) the coordinate, NaN where a cell is blank.
    unit : ``"rad"``, ``"deg"``, ``""`` (an angle in a unit not stated) or ``"length"``.
    lines : (S,) 1-based table line of each sample.
    source : how the coordinate was made, for the report.
    """

    name: str
    time: np.ndarray
    value: np.ndarray
    unit: str
    lines: np.ndarray
    source: str


def swings(table: Table, columns: AngleColumns = AngleColumns()) -> list[Swing]:
    """Every pendulum of ``table``; see the module docstring."""
    groups = table.groups or [""]
    shared = [c for c in table.columns if not c.group]
    found: list[tuple[str, Column, list[Column] | tuple[Column, Column]]] = []
    skipped = []
    for group in groups:
        own = [c for c in table.columns if c.group == group] if group else list(table.columns)
        pool = own + [c for c in shared if c not in own]
        time = _time_column(table, pool, columns, group)
        rest = [c for c in pool if c is not time]
        angles = _angle_columns(table, rest, columns, group)
        if angles:
            found += [(group, time, [a]) for a in angles]
            continue
        pairs = _xy_pairs(table, rest, columns, group)
        if pairs:
            found += [(group, time, pair) for pair in pairs]
        else:
            skipped.append(group)
    if not found:
        raise AngleTableError(
            f"{table.source}: no pendulum found: no angle column (named theta, θ, angle or "
            f"phi) and no x and y columns among {table.listing()}; name them with "
            f"`angle`, or `x` and `y` (CLI: --angle-column, or --x-column and --y-column)."
        )
    if skipped and any(skipped):
        warnings.warn(
            f"{table.source}: {', '.join(map(repr, skipped))} holds no angle and no x, y "
            f"columns: left out.",
            UserWarning,
            stacklevel=3,
        )
    if columns.pivot and len(columns.pivot) != len(found):
        raise ParameterError(
            f"`pivot` gives {plural(len(columns.pivot), 'pivot')} but {table.source} holds "
            f"{plural(len(found), 'pendulum')}; give one X,Y per pendulum, in order."
        )
    one_each = Counter(g for g, _, _ in found)
    out = []
    for k, (group, time, coords) in enumerate(found):
        seconds = _seconds(table, time, columns)
        name = group if group and one_each[group] == 1 else _name(group, coords)
        if len(coords) == 1:
            (a,) = coords
            unit = columns.angle_unit if columns.angle_unit != "auto" else _angle_unit(a.header)
            value = a.values
            if unit in ("deg", "rad"):  # an encoder that wraps at a full turn
                value = _unwrapped(value, 360.0 if unit == "deg" else 2 * np.pi)
            source = f"angle {a.shown}" + ("" if unit else " (unit not stated)")
        else:
            x, y = coords
            if columns.pivot:
                px, py = columns.pivot[k]
                value, unit = _about_pivot(x.values, y.values, px, py), "rad"
                source = f"x, y {x.shown}, {y.shown} about the pivot ({px:g}, {py:g})"
            else:
                value, unit = _along_axis(x.values, y.values), "length"
                source = f"x, y {x.shown}, {y.shown} along the swing (no pivot given)"
        out.append(Swing(name, seconds, value, unit, table.lines, source))
    return out


def _base(header: str) -> str:
    """The header's name without its unit: ``'Theta (deg)'`` → ``'theta'``."""
    text = re.sub(r"[\(\[].*?[\)\]]", "", header.lower()).replace("°", "").strip()
    words = re.split(r"[ _]+", text)
    while len(words) > 1 and (words[-1] in _TIME_WORDS or words[-1] in _ANGLE_WORDS):
        words.pop()
    return "_".join(w for w in words if w)


def _unit_words(header: str) -> list[str]:
    text = header.lower()
    inside = re.findall(r"[\(\[](.*?)[\)\]]", text)
    words = re.split(r"[ _]+", re.sub(r"[\(\[\)\]]", " ", text).strip())
    return [w.strip() for w in inside] + words[1:] + (["°"] if "°" in text else [])


def _angle_unit(header: str) -> str:
    return next((_ANGLE_WORDS[w] for w in _unit_words(header) if w in _ANGLE_WORDS), "")


def _time_unit(header: str) -> str | None:
    words = _unit_words(header)
    base = _base(header)
    if base in ("millis", "micros"):
        return _TIME_WORDS[base]
    return next((_TIME_WORDS[w] for w in words if w in _TIME_WORDS), None)


def _pick(table: Table, pool: list[Column], wanted: str, what: str, group: str) -> Column:
    """The column ``wanted`` (a header or a 1-based number) in ``pool``."""
    text = wanted.strip()
    if text.isdigit():
        hit = [c for c in table.columns if c.number == int(text)]
    else:
        low = " ".join(text.lower().split())
        hit = [c for c in pool if " ".join(c.header.lower().split()) == low]
        hit = hit or [c for c in pool if _base(c.header) == _base(text) and _base(text)]
    if not hit:
        where = f" in {group!r}" if group else ""
        raise AngleTableError(
            f"{table.source}: no column {wanted!r}{where}, asked for as the {what}; its "
            f"columns are {table.listing()}."
        )
    return hit[0]


def _time_column(table: Table, pool: list[Column], columns: AngleColumns, group: str) -> Column:
    if columns.time is not None:
        return _pick(table, pool, columns.time, "time column", group)
    named = [c for c in pool if _base(c.header) in _TIME_NAMES]
    if named:
        return named[0]
    if not any(c.header for c in table.columns):
        return pool[0]  # no header: the first column is the time, as a logger writes it
    raise AngleTableError(
        f"{table.source}: no time column (named t, time or millis) among "
        f"{table.listing()}; name it with `time` (CLI: --time-column)."
    )


def _angle_columns(table: Table, pool: list[Column], columns: AngleColumns, group: str):
    if columns.angle:
        return [_pick(table, pool, a, "angle column", group) for a in columns.angle]
    if columns.x is not None:
        return []
    named = [c for c in pool if _ANGLE.match(_base(c.header)) and not _NOT_ANGLES.match(
        _base(c.header))]  # fmt: skip
    if not named and not any(c.header for c in table.columns) and len(pool) == 1:
        return pool  # no header: time, angle
    plain = [c for c in named if not _POLAR.match(_base(c.header))]
    if plain or _xy_pairs(table, pool, columns, group):
        return plain
    return named


def _xy_pairs(table: Table, pool: list[Column], columns: AngleColumns, group: str):
    if columns.x is not None and columns.y is not None:
        return [(_pick(table, pool, columns.x, "x column", group),
                 _pick(table, pool, columns.y, "y column", group))]  # fmt: skip
    xs = [c for c in pool if _XY["x"].match(_base(c.header))]
    ys = [c for c in pool if _XY["y"].match(_base(c.header))]
    return list(zip(xs, ys, strict=False)) if len(xs) == len(ys) else []


def _seconds(table: Table, time: Column, columns: AngleColumns) -> np.ndarray:
    unit = columns.time_unit if columns.time_unit != "auto" else _time_unit(time.header)
    seconds = time.values * TIME_UNITS[unit or "s"]
    steps = np.diff(seconds[np.isfinite(seconds)])
    if unit is None and steps.size and np.median(steps) >= 1.0:
        warnings.warn(
            f"{table.source}: the time column {time.shown} states no unit and is read in "
            f"seconds, but its samples are {np.median(steps):g} s apart; if it counts "
            f"milliseconds, give `time_unit` 'ms'.",
            UserWarning,
            stacklevel=4,
        )
    return seconds


def _name(group: str, coords: Sequence[Column]) -> str:
    first = coords[0]
    label = first.header or f"column {first.number}"
    if len(coords) == 2:
        label = f"{label}, {coords[1].header or f'column {coords[1].number}'}"
    return f"{group} {label}" if group else label


def _about_pivot(x: np.ndarray, y: np.ndarray, px: float, py: float) -> np.ndarray:
    """θ about the pivot from the downward vertical of a y-up frame, unwrapped, rad;
    in a y-down frame it is near ±π, which the rest angle takes out."""
    return _unwrapped(np.arctan2(x - px, py - y), 2 * np.pi)


def _unwrapped(angle: np.ndarray, period: float) -> np.ndarray:
    """``angle`` without jumps of a full turn, across its blank cells (NaN) too."""
    out = np.array(angle, dtype=float)
    ok = np.isfinite(out)
    out[ok] = np.unwrap(out[ok], period=period)
    return out


def _along_axis(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The position along the principal axis of the (x, y) path."""
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 2:
        return np.full(x.shape, np.nan)
    centred = np.stack([x[ok] - np.median(x[ok]), y[ok] - np.median(y[ok])], axis=1)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    return np.where(ok, (x - np.median(x[ok])) * axis[0] + (y - np.median(y[ok])) * axis[1],
                    np.nan)  # fmt: skip

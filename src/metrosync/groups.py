"""Groups of metronomes tuned to different frequencies on one disk.

Contract: a `Group` is N metronomes whose natural frequencies are drawn from
Normal(bpm, sigma_bpm), as one ungrouped ensemble's are. `as_groups` checks what a
user gives ``simulate(groups=...)`` (tuples ``(n, bpm)`` or ``(n, bpm, sigma_bpm)``,
`Group` objects, or the command line's ``"N@BPM[:SIGMA]"``, which `parse_group` reads)
and fills in the ensemble's spread where a group gives none. `shifted` moves every
group after the first by an offset in BPM, the axis a sweep varies
(``group_offset_bpm``). Groups are laid out one after the other along the metronome
axis, so group g is metronomes ``group_bounds(groups)[g]`` to
``group_bounds(groups)[g + 1] - 1``; the kernels use these bounds to record each
group's order parameter.

The paper's closing section names this study: "systems where the metronomes or groups
of metronomes are fixed to different natural frequencies".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, describe
from .model.quantity import NON_NEGATIVE, declared, quantity


@dataclass(frozen=True)
class Group:
    """One group: ``n`` metronomes at nominal ``bpm``, natural frequencies spread with
    standard deviation ``sigma_bpm`` (None: the ensemble's ``sigma_bpm``); the units
    and bounds are declared on the fields."""

    n: int
    bpm: float = quantity(unit="BPM")
    sigma_bpm: float | None = quantity(None, unit="BPM", bounds=NON_NEGATIVE)

    def label(self) -> str:
        """The group as the command line writes it, ``N@BPM:SIGMA``."""
        text = f"{self.n}@{self.bpm:g}"
        return text if self.sigma_bpm is None else f"{text}:{self.sigma_bpm:g}"


def as_groups(groups, sigma_bpm: float | None) -> tuple[Group, ...]:
    """Checked groups from ``simulate(groups=...)``, each with its spread resolved.

    ``groups`` : a non-empty sequence of `Group`, tuples ``(n, bpm)`` /
    ``(n, bpm, sigma_bpm)`` or texts ``"N@BPM[:SIGMA]"``. ``sigma_bpm`` : the spread
    of groups that give none (None leaves it unset, for a sweep to fill per point).
    """
    if isinstance(groups, str | bytes) or not isinstance(groups, Sequence) or not groups:
        raise ParameterError(
            f"`groups` must be a non-empty list of (n, bpm) or (n, bpm, sigma_bpm) tuples, "
            f"e.g. [(7, 184.0), (7, 200.0)]; got {describe(groups)}."
        )
    out = []
    for k, item in enumerate(groups):
        where = f"`groups` entry {k}"
        if isinstance(item, str):
            try:
                item = parse_group(item)
            except ValueError as error:
                raise ParameterError(f"{where}: {error}.") from None
        if isinstance(item, Group):
            item = (item.n, item.bpm, item.sigma_bpm)
        if (
            isinstance(item, str | bytes)
            or not isinstance(item, Sequence | np.ndarray)
            or len(item) not in (2, 3)
        ):
            raise ParameterError(
                f"{where} must be (n, bpm) or (n, bpm, sigma_bpm), got {describe(item)}."
            )
        n, bpm, *rest = item
        sigma = rest[0] if rest and rest[0] is not None else sigma_bpm
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ParameterError(f"{where}: the count n must be an integer >= 1, got {n!r}.")
        spread = None if sigma is None else _spread(where, sigma)
        out.append(Group(int(n), _number(where, "bpm", bpm), spread))
    return tuple(out)


def shifted(groups: Sequence[Group], offset_bpm: float) -> tuple[Group, ...]:
    """The groups with ``offset_bpm`` added to the BPM of every group after the first."""
    return tuple(
        g if k == 0 else Group(g.n, g.bpm + offset_bpm, g.sigma_bpm) for k, g in enumerate(groups)
    )


def parse_group(text: str) -> Group:
    """A group from the command line's ``N@BPM`` or ``N@BPM:SIGMA``, e.g. ``7@200:0.5``.

    Raises `ValueError` with a message that shows the expected form (argparse adds
    the option's name).
    """
    count, at, rest = text.partition("@")
    bpm, colon, sigma = rest.partition(":")
    form = "expected N@BPM or N@BPM:SIGMA, e.g. 7@184 or 7@200:0.5"
    if not at or not count.strip() or not bpm.strip() or (colon and not sigma.strip()):
        raise ValueError(f"{form}; got {text!r}")
    try:
        n = int(count)
    except ValueError:
        raise ValueError(f"the count N must be a whole number ({form}); got {text!r}") from None
    if n < 1:
        raise ValueError(f"the count N must be >= 1; got {text!r}")
    try:
        values = [float(bpm)] + ([float(sigma)] if colon else [])
    except ValueError:
        raise ValueError(f"BPM and SIGMA must be numbers ({form}); got {text!r}") from None
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"BPM and SIGMA must be finite; got {text!r}")
    if colon and values[1] < 0:
        raise ValueError(f"SIGMA must be >= 0 BPM; got {text!r}")
    return Group(n, *values)


def group_bounds(groups: Sequence[Group]) -> np.ndarray:
    """(G + 1,) int64: group g is metronomes bounds[g] .. bounds[g + 1] - 1."""
    return np.concatenate(([0], np.cumsum([g.n for g in groups]))).astype(np.int64)


def describe_groups(groups: Sequence[Group]) -> str:
    """The groups as one attribute string, ``7@184:0.75 7@200:0.5``."""
    return " ".join(g.label() for g in groups)


def _number(where: str, name: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise ParameterError(f"{where}: `{name}` must be a finite number, got {value!r}.")
    return number


def _spread(where: str, value) -> float:
    number = _number(where, "sigma_bpm", value)
    bounds, unit = declared(Group, "sigma_bpm", "bounds"), declared(Group, "sigma_bpm")
    if not bounds.admits(number):
        raise ParameterError(f"{where}: `sigma_bpm` must {bounds} {unit}, got {value!r}.")
    return number

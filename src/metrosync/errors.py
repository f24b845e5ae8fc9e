"""The project's documented error and warning types.

Every error raised for bad user input is a `ParameterError` (a `ValueError`) whose
message names the argument, the value it got, and how to fix it.
"""

from __future__ import annotations

import math
from typing import Any


class MetrosyncError(Exception):
    """Base class of every error metrosync raises on purpose."""


class ParameterError(MetrosyncError, ValueError):
    """A parameter is out of range, of the wrong shape, or not a finite number."""


class OverturnWarning(UserWarning):
    """The chosen parameters make the pendulums swing past the horizontal."""


def require_finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"`{name}` must be a finite number, got {value!r}.")
    return value


def require_positive(name: str, value: float, *, allow_zero: bool = False, unit: str = "") -> float:
    value = require_finite(name, value)
    if value < 0 or (value == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ParameterError(
            f"`{name}` must be {bound}{' ' + unit if unit else ''}, got {value!r}."
        )
    return value


def describe(value: Any) -> str:
    """Short repr for error messages (arrays are summarised, not dumped)."""
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."

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


class EscapementWarning(UserWarning):
    """Some escapement cannot fire: its angle lies beyond the pendulum's swing."""


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


def shown_range(low: float, high: float, value: float, *, digits: int = 2) -> tuple[str, str, str]:
    """``value``, ``low`` and ``high`` as a message prints them: the bounds with the
    fewest decimals (at least ``digits``) that leave ``value`` on its true side of them.

    >>> shown_range(84.6543, 236.71996, 236.72)
    ('236.72', '84.65430', '236.71996')
    >>> shown_range(84.6543, 236.71996, 300)
    ('300', '84.65', '236.72')
    """
    inside = low <= value <= high
    for places in range(digits, 13):
        lo, hi = f"{low:.{places}f}", f"{high:.{places}f}"
        for shown in (f"{value:.6g}", f"{value:.{places}f}"):
            if inside == (float(lo) <= float(shown) <= float(hi)):
                return shown, lo, hi
    return repr(value), repr(low), repr(high)


def describe(value: Any) -> str:
    """Short repr for error messages (arrays are summarised, not dumped)."""
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


class LogFormatError(MetrosyncError, ValueError):
    """A light-gate log cannot be read: it is empty, malformed, or inconsistent.

    The message names the file (when known), the line number and what to do.
    """


class EmptyLogError(LogFormatError):
    """A light-gate log holds no gate record at all."""


class ChannelCountError(LogFormatError):
    """The number of gates per record changes in the middle of a log (or between logs)."""


class TimestampError(LogFormatError):
    """Timestamps go backwards in a way that no counter wrap explains."""


class StrictModeError(LogFormatError):
    """A line was not a gate record, and strict reading was asked for."""


class AnalysisError(MetrosyncError, ValueError):
    """Cleaned light-gate data do not allow the requested analysis (too few passes)."""


class CalibrationError(MetrosyncError, ValueError):
    """A parameter cannot be estimated from the data given (no solution, or not unique)."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) stopped long work; ``kept`` says what survives and how to resume.

    Raised in place of the bare `KeyboardInterrupt` by work that keeps partial results
    (a sweep's finished points), so that the command line can say what was kept.
    """

    def __init__(self, kept: str) -> None:
        super().__init__(kept)
        self.kept = kept

"""Choosing the gates of a capture: one check of a gate list, and the gates never used.

Contract: `check_channels` checks a list of gate indices (0-based) against a logger's
gate count and returns it (every gate when None); a bad list is a `ParameterError`
that gives the valid range. `analyze`, the live panel of ``record`` and ``analyze
--follow`` all check with it, so they accept and refuse the same lists. `never_changed`
finds the gates whose level never changed in a capture (an unwired gate, or a
metronome that never swung through its beam), and `never_changed_text` says so in
the one wording the warnings of `analyze` and the live panel share.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ParameterError


def check_channels(channels: Sequence[int] | None, k: int, *, where: str = "") -> list[int]:
    """The gates chosen among ``k``: ``channels`` checked, or every gate when None.

    where : what has the ``k`` gates, for the message (e.g. " (the logger on COM3 sends
        7 gates per line)").

    Raises `ParameterError` for an index outside [0, k-1], a repeated one, or none.
    """
    if channels is None:
        return list(range(k))
    chosen = [int(c) for c in channels]
    bad = [c for c in chosen if not 0 <= c < k]
    if bad or not chosen or len(set(chosen)) != len(chosen):
        raise ParameterError(
            f"`channels` must be distinct gate indices in [0, {k - 1}]{where}, got "
            f"{list(channels)!r}."
        )
    return chosen


def never_changed(levels: np.ndarray) -> list[int]:
    """Gates (columns of ``levels``, (R, K)) whose level is the same in every record."""
    levels = np.asarray(levels)
    if levels.shape[0] == 0:
        return list(range(levels.shape[1]))
    return [int(k) for k in np.flatnonzero(np.all(levels == levels[:1], axis=0))]


def never_changed_text(gates: Sequence[int]) -> str:
    """The words for gates that never changed: "gate 7 never changed (...)"."""
    gates = [int(g) for g in gates]
    which = f"gate {gates[0]}" if len(gates) == 1 else f"gates {', '.join(map(str, gates))}"
    return f"{which} never changed (not wired, or no pendulum passes its beam)"

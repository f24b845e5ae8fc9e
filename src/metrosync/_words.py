"""Counts in words for messages: ``plural(1, "time") == "1 time"``.

Every message that prints a count with its noun goes through `plural`, so that a count
of one never reads "restarted 1 times".
"""

from __future__ import annotations


def plural(count: int, noun: str, many: str | None = None) -> str:
    """``count`` and ``noun``, in the plural (``many``, default ``noun + "s"``) unless the
    count is 1: ``plural(2, "run") == "2 runs"``, ``plural(1, "pass", "passes") == "1 pass"``.
    """
    return f"{count} {noun if count == 1 else (many or noun + 's')}"

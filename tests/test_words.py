"""Counts in messages: one of a thing is singular, everywhere."""

import re
from pathlib import Path

from metrosync._words import plural

SRC = Path(__file__).parents[1] / "src" / "metrosync"


def test_plural_is_singular_for_one_only():
    assert plural(1, "time") == "1 time"
    assert [plural(n, "run") for n in (0, 2, 13)] == ["0 runs", "2 runs", "13 runs"]
    assert plural(1, "missed pass", "missed passes") == "1 missed pass"
    assert plural(3, "missed pass", "missed passes") == "3 missed passes"


#: Nouns that messages count, whose count can be 1.
COUNTED = ("times", "records", "lines", "wraps", "flickers", "gaps", "clicks", "frames",
           "samples", "swings", "missed passes", "gates", "ticks", "steps")  # fmt: skip


def test_no_message_prints_a_bare_count_before_these_plural_nouns():
    """A placeholder straight before one of `COUNTED` ("restarted {n} times") prints
    "1 times" for a count of one: such counts go through `plural`."""
    # ... but not a rate ("{rate} records/s") or a ratio ("{x} ticks per beat").
    nouns = "|".join(map(re.escape, COUNTED))
    pattern = re.compile(r"\{[^{}]+\} (" + nouns + r")\b(?!/| per\b)")
    found = []
    for path in sorted(SRC.rglob("*.py")):
        for number, line in enumerate(path.read_text().splitlines(), 1):
            for match in pattern.finditer(line):
                # A module constant is never 1, and a formatted float ("{x:.3g} steps")
                # is a magnitude, not a count.
                placeholder = match[0][: match[0].rindex("}") + 1]
                if not re.fullmatch(r"\{[A-Z_]+\}", placeholder) and ":" not in placeholder:
                    found.append(f"{path.relative_to(SRC)}:{number}: {match[0]}")
    assert not found, "\n".join(found)


def test_no_message_hedges_a_count_with_s_in_brackets():
    """ "{n} metronome(s)" reads badly for every n: counts go through `plural`."""
    pattern = re.compile(r"\{[^{}]+\} [a-z]\w*\(s\)")
    found = [
        f"{path.relative_to(SRC)}:{number}: {match[0]}"
        for path in sorted(SRC.rglob("*.py"))
        for number, line in enumerate(path.read_text().splitlines(), 1)
        for match in pattern.finditer(line)
    ]
    assert not found, "\n".join(found)

"""Reading a delimited table of numbers: a rotary encoder's CSV, Tracker's exported data.

Contract: `parse_table(text)` (`read_table(path)` for a file) returns a `Table`: its
numeric columns, each with the header text above it and the label of the group it
belongs to, the line of every data row, and an account of every line that is neither
header nor data. It knows no physics; `columns` picks a pendulum's time and angle.

What it accepts, as such files come:

* the delimiter: of a tab, a semicolon, a comma and runs of spaces, the one that
  splits the most lines into numbers (``1,5 2,5`` is two numbers, ``1,5,2`` three);
* the decimal mark: a point, or a comma where the delimiter is not a comma and the
  numbers have a comma and no point (Tracker in a German locale: ``0,033``);
* header rows: the text rows before the first row of numbers. The last is the
  columns' names (``t  x  y``, ``time,theta``). The one before it, if any, labels
  groups of columns: a label stands over the first column of its group, and the group
  runs to the next label. That is how Tracker writes several tracks side by side::

      #multi:
      <tab>mass A<tab><tab>mass B
      t<tab>x<tab>y<tab>x<tab>y
      0.000<tab>0.120<tab>-0.301<tab>...

  (``t`` under no label belongs to every group), and one track as ``mass A`` over
  ``t x y``. Earlier header rows are titles. Lines starting with ``#`` are comments;
* no header at all: the columns are named by their number;
* blank cells (a mass not marked in a frame): NaN. Text rows after the data began, and
  blank lines, are skipped and counted with their line numbers.

It refuses, with an `AngleTableError`, text with no row of numbers, or one column only.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._input_files import check_input_file
from .._words import plural
from ..errors import MetrosyncError

#: Lines looked at to tell the delimiter and the decimal mark.
_SNIFF_LINES = 200
_COMMA_DECIMAL = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")


class AngleTableError(MetrosyncError, ValueError):
    """An angle table cannot be read, or holds no usable time and angle."""


@dataclass(frozen=True, eq=False)  # a column is itself: its values are an array
class Column:
    """One numeric column.

    header : its name as written (``""`` where the table has none).
    group : the label of its group (``""``: it belongs to none, or to all).
    values : (R,) float, NaN for a blank cell.
    number : its place in a row, 1-based.
    """

    header: str
    group: str
    values: np.ndarray
    number: int

    @property
    def shown(self) -> str:
        """The column as a message names it: ``'x' (mass A)``, or ``column 3``."""
        name = repr(self.header) if self.header else f"column {self.number}"
        return f"{name} ({self.group})" if self.group else name


@dataclass(frozen=True)
class Table:
    """A parsed table.

    columns : every column, in order.
    lines : (R,) 1-based line of each data row.
    skipped : (line, reason) of each line that is neither header nor data.
    n_lines : lines in the text.
    delimiter : ``"\\t"``, ``";"``, ``","`` or ``" "`` (runs of spaces).
    decimal : ``"."`` or ``","``.
    source : file name or ``"<text>"``.
    """

    columns: tuple[Column, ...]
    lines: np.ndarray
    skipped: tuple[tuple[int, str], ...]
    n_lines: int
    delimiter: str
    decimal: str
    source: str = "<text>"

    @property
    def groups(self) -> list[str]:
        """The group labels, in order of their first column (none: ``[]``)."""
        return list(dict.fromkeys(c.group for c in self.columns if c.group))

    def listing(self) -> str:
        """Every column, as an error message lists them."""
        return ", ".join(c.shown for c in self.columns)


def read_table(path: str | Path) -> Table:
    """`parse_table` of a file (UTF-8, or Windows' code page where it is not UTF-8)."""
    path = check_input_file(path, "angle table", error=AngleTableError)
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("cp1252", errors="replace")
    return parse_table(text, source=str(path))


def parse_table(text: str, *, source: str = "<text>") -> Table:
    """Parse the text of a table; see the module docstring."""
    lines = text.splitlines()
    content = [(n, line) for n, line in enumerate(lines, 1) if line.strip()]
    content = [(n, line) for n, line in content if not line.lstrip().startswith("#")]
    sample = [line for _, line in content[:_SNIFF_LINES]]
    delimiter = _delimiter(sample)
    cells = [(n, _split(line, delimiter)) for n, line in content]
    decimal = _decimal(cells, delimiter)
    parsed = [(n, row, _numbers(row, decimal)) for n, row in cells]
    first = next((i for i, (_, _, values) in enumerate(parsed) if values is not None), None)
    if first is None:
        raise AngleTableError(
            f"{source}: no row of numbers in {plural(len(lines), 'line')}: is it a table "
            f"of times and angles (a header such as 't,theta', then one row per sample)?"
        )
    header = [row for _, row, _ in parsed[:first]]
    rows: list[list[float]] = []
    numbers: list[int] = []
    skipped: list[tuple[int, str]] = []
    for n, _row, row_values in parsed[first:]:
        if row_values is None:
            skipped.append((n, "not a row of numbers"))
        else:
            rows.append(row_values)
            numbers.append(n)
    skipped += [(n, "blank line") for n, line in enumerate(lines, 1)
                if not line.strip() and n > numbers[0]]  # fmt: skip
    width = max(len(r) for r in rows)
    if width < 2:
        raise AngleTableError(
            f"{source}: one column of numbers only; a table needs a time column and an "
            f"angle column (or x and y)."
        )
    values = np.full((len(rows), width), np.nan)
    for i, r in enumerate(rows):
        values[i, : len(r)] = r
    names = header[-1] if header else []
    groups = _group_labels(header[-2], width) if len(header) >= 2 else [""] * width
    columns = tuple(
        Column(names[j].strip() if j < len(names) else "", groups[j], values[:, j], j + 1)
        for j in range(width)
    )
    return Table(columns, np.array(numbers, dtype=np.int64), tuple(sorted(skipped)),
                 len(lines), delimiter, decimal, source)  # fmt: skip


def _delimiter(sample: list[str]) -> str:
    """The mark that splits most lines into two or more numbers (ties: the first of tab,
    semicolon, comma, space); without rows of numbers, a tab if any, else a semicolon or
    comma on most lines, else spaces."""
    fits = {mark: sum(_all_numbers(_split(line, mark), mark) for line in sample)
            for mark in ("\t", ";", ",", " ")}  # fmt: skip
    best = max(fits, key=lambda mark: fits[mark])  # the first of the best
    if fits[best]:
        return best
    if any("\t" in line for line in sample):
        return "\t"
    for mark in (";", ","):
        if sum(mark in line for line in sample) > len(sample) / 2:
            return mark
    return " "


def _all_numbers(cells: list[str], delimiter: str) -> bool:
    """Two or more cells, each blank or a number (with a decimal comma unless the cells
    were split at commas)."""
    if len(cells) < 2:
        return False
    comma = delimiter != ","
    return all(not c or _is_number(c) or (comma and _is_number(c.replace(",", ".")))
               for c in cells)  # fmt: skip


def _split(line: str, delimiter: str) -> list[str]:
    return line.split() if delimiter == " " else [c.strip() for c in line.split(delimiter)]


def _decimal(cells: list[tuple[int, list[str]]], delimiter: str) -> str:
    """``","`` where the numbers are written with a decimal comma, else ``"."``."""
    if delimiter == ",":
        return "."
    counts: Counter[str] = Counter()
    for _, row in cells[:_SNIFF_LINES]:
        for cell in row:
            if _COMMA_DECIMAL.match(cell):
                counts[","] += 1
            elif "." in cell and _is_number(cell):
                counts["."] += 1
    return "," if counts[","] > counts["."] else "."


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _numbers(row: list[str], decimal: str) -> list[float] | None:
    """The row's values (NaN for a blank cell), or None for a row that is not numbers."""
    out = []
    for cell in row:
        if not cell:
            out.append(np.nan)
            continue
        try:
            out.append(float(cell.replace(",", ".") if decimal == "," else cell))
        except ValueError:
            return None
    # A trailing delimiter (Tracker ends rows with a tab) leaves blank cells, not columns.
    while out and np.isnan(out[-1]) and not row[len(out) - 1]:
        out.pop()
    return out if out else None


def _group_labels(row: list[str], width: int) -> list[str]:
    """Each column's group: the nearest label at or before it in ``row``; columns before
    the first label belong to none."""
    labels, current = [], ""
    for j in range(width):
        cell = row[j].strip() if j < len(row) else ""
        current = cell or current
        labels.append(current)
    return labels

"""Angle logs of other instruments: a rotary encoder's CSV, Tracker's exported data.

A pendulum's angle sampled in time, or its bob's x and y, analysed as the light gate's
passes are (`metrosync.observables.crossings`): its passes through the vertical are
the crossings of its rest angle, one direction kept per period.

``table``    a delimited text table → `Table` (delimiter, decimal mark, header rows,
             Tracker's groups of columns, blank cells)
``columns``  which columns are each pendulum's time and angle (`AngleColumns`), and
             its angle from x and y
``passes``   the model: a sampled angle → its passes through the vertical
``analyze``  the entry point: table files → the light gate's `xarray.Dataset`
"""

from .analyze import analyze_angles
from .columns import AngleColumns, Swing, swings
from .passes import Passes, passes
from .table import AngleTableError, Column, Table, parse_table, read_table

__all__ = [
    "AngleColumns",
    "AngleTableError",
    "Column",
    "Passes",
    "Swing",
    "Table",
    "analyze_angles",
    "parse_table",
    "passes",
    "read_table",
    "swings",
]

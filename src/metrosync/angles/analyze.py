"""`analyze_angles`: angle tables → r(t), frequencies and σ, as the light gate's dataset.

Contract: ``analyze_angles(paths, *, columns=None, ...)`` reads each table
(`table`), finds its pendulums (`columns`) and their passes through the vertical
(`passes`), and measures them as `metrosync.lightgate.analyze` measures a light gate's
kept passes, with the same functions (`metrosync.observables.crossings`). Several
tables are repeated runs: r(t) is computed per table on one grid t = k·dt (seconds
from each table's first row) and averaged. The dataset has the light-gate analysis's
names, so that its summary, plot and readers serve both:

    r, r_runs (log, time), frequency_bpm (metronome), frequency_bpm_runs,
    period_jitter, passes_kept, passes_bridged, intervals_irregular (log, metronome),
    path (log)

and, of the tables' own,

    rest_value, swing  (log, metronome)   θ_rest and the median half peak-to-peak
                                          swing, in ``unit`` (rad where the table's
                                          angle unit is known)
    unit, coordinate   (log, metronome)   the unit, and the columns each came from
    crossing_time      (log, metronome, swing)   the kept passes, s (NaN-padded)
    time_origin        (log)              the table's first time, s
    name               (metronome)        the pendulum's name (Tracker's track)

with attrs ``r_eq``, ``equilibrium_window``, ``sigma_bpm``, ``sigma_beats_per_tick``
(per 64 µs, the paper's logger tick, for its tables' unit), ``instrument`` ("angle
table"), ``report`` (the reading, per table and pendulum) and the options.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from .._words import plural
from ..errors import AnalysisError, ParameterError
from ..lightgate.channels import check_channels
from ..lightgate.reader import DEFAULT_TICK
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from .columns import AngleColumns, swings
from .passes import MAX_GAP, Passes, passes
from .table import AngleTableError, Table, read_table


def analyze_angles(
    paths: Sequence[str | Path] | str | Path,
    *,
    columns: AngleColumns | None = None,
    channels: Sequence[int] | None = None,
    grid_dt: float = 0.1,
    equilibrium_window: float | None = None,
) -> xr.Dataset:
    """Analyse angle tables of one or more repeated runs.

    Parameters
    ----------
    paths : table files; several are repeated runs and are averaged.
    columns : which columns hold each pendulum, and their units (default: found by
        their names, `AngleColumns`).
    channels : pendulums to analyse (0-based, in the table's order); default all.
    grid_dt : spacing of the r(t) grid, s.
    equilibrium_window : seconds at the end of the grid averaged for ``r_eq``;
        default a quarter of it.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    if not paths:
        raise ParameterError("`paths` is empty: give at least one angle table.")
    if not (math.isfinite(grid_dt) and grid_dt > 0):
        raise ParameterError(f"`grid_dt` must be a time > 0 s, got {grid_dt!r}.")
    columns = AngleColumns() if columns is None else columns
    tables = [read_table(p) for p in paths]
    found = [swings(t, columns) for t in tables]
    k = len(found[0])
    for table, sw in zip(tables[1:], found[1:], strict=True):
        if len(sw) != k:
            raise AngleTableError(
                f"{table.source} holds {plural(len(sw), 'pendulum')} but {tables[0].source} "
                f"{k}; repeated runs must hold the same pendulums."
            )
    chosen = check_channels(channels, k, where=f" ({tables[0].source} holds {k})")
    runs = [[passes(sw[j], t.source) for j in chosen] for t, sw in zip(tables, found,
                                                                        strict=True)]  # fmt: skip
    origins = [_origin(run) for run in runs]
    spans = [(max(float(p.kept[0]) for p in run) - t0, min(float(p.kept[-1]) for p in run) - t0)
             for run, t0 in zip(runs, origins, strict=True)]  # fmt: skip
    grid = ph.common_grid(spans, grid_dt)
    if grid.size < 2:
        shown = ", ".join(f"{s:.3f} .. {e:.3f}" for s, e in spans)
        raise AnalysisError(
            f"the tables' pendulums share no common span of two `grid_dt` ({grid_dt:g} s) "
            f"where each has a phase (spans {shown} s); give a smaller `grid_dt`, or leave "
            f"out a pendulum that stops early (`channels`)."
        )
    window = ph.equilibrium_window(grid, equilibrium_window)
    ds = _dataset(tables, runs, origins, chosen, grid, window)
    ds.attrs.update(
        grid_dt=grid_dt,
        time_column=columns.time or "auto",
        angle_columns=",".join(columns.angle) or "auto",
        pivots=";".join(f"{x:g},{y:g}" for x, y in columns.pivot),
        time_unit=columns.time_unit,
        angle_unit=columns.angle_unit,
        report="\n".join(_report(t, run, chosen, t0) for t, run, t0 in zip(tables, runs,
                                                                            origins, strict=True)),
    )  # fmt: skip
    _warn_bridged(tables, runs)
    return ds


def _origin(run: list[Passes]) -> float:
    """The table's first time, s: the clock's zero of its phases and r."""
    return float(min(np.nanmin(p.swing.time) for p in run))


def _dataset(tables: list[Table], runs: list[list[Passes]], origins, chosen, grid, window):
    shifted = [[(p.kept - t0, p.cycles) for p in run] for run, t0 in zip(runs, origins,
                                                                          strict=True)]  # fmt: skip
    r_runs = np.stack([ph.order_on_grid(run, grid) for run in shifted])
    r = r_runs.mean(axis=0)
    freq = np.array([[ph.mean_frequency_bpm(p.kept, p.cycles) for p in run] for run in runs])
    jitter = np.array([[ph.period_jitter(p.kept, p.cycles) for p in run] for run in runs])
    factor = [[math.pi / 180 if p.swing.unit == "deg" else 1.0 for p in run] for run in runs]
    rest = np.array([[p.rest for p in run] for run in runs]) * np.array(factor)
    swing = np.array([[p.amplitude for p in run] for run in runs]) * np.array(factor)
    unit = np.array([["rad" if p.swing.unit in ("deg", "rad") else p.swing.unit or "not stated"
                      for p in run] for run in runs])  # fmt: skip
    width = max(p.kept.size for run in runs for p in run)
    crossing = np.full((len(runs), len(chosen), width), np.nan)
    for i, (run, t0) in enumerate(zip(runs, origins, strict=True)):
        for j, p in enumerate(run):
            crossing[i, j, : p.kept.size] = p.kept - t0
    mean_freq = freq.mean(axis=0)
    sigma = ph.frequency_spread(mean_freq)
    per_pendulum = ("log", "metronome")
    data = {
        "r": (("time",), r, {"long_name": "Kuramoto order parameter, mean over tables"}),
        "r_runs": (("log", "time"), r_runs, {"long_name": "Kuramoto order parameter per table"}),
        "frequency_bpm": (("metronome",), mean_freq,
                          {"units": "BPM", "long_name": "mean frequency (two beats per "
                                                        "period), averaged over tables"}),
        "frequency_bpm_runs": (per_pendulum, freq,
                               {"units": "BPM", "long_name": "mean frequency per table"}),
        "period_jitter": (per_pendulum, jitter,
                          {"units": "s", "long_name": "std of single-period intervals"}),
        "passes_kept": (per_pendulum, np.array([[p.kept.size for p in run] for run in runs]),
                        {"long_name": "upward passes through the rest angle"}),
        "passes_bridged": (per_pendulum, np.array([[p.bridged for p in run] for run in runs]),
                           {"long_name": "passes missed (gaps, blank cells) and bridged"}),
        "intervals_irregular": (per_pendulum,
                                np.array([[p.irregular for p in run] for run in runs]),
                                {"long_name": "intervals more than 1/4 period off a whole "
                                              "number of periods"}),
        "rest_value": (per_pendulum, rest,
                       {"long_name": "rest value (median) of the coordinate, in `unit`"}),
        "swing": (per_pendulum, swing,
                  {"long_name": "median half peak-to-peak swing, in `unit`"}),
        "unit": (per_pendulum, unit, {"long_name": "unit of rest_value and swing"}),
        "coordinate": (per_pendulum, np.array([[p.swing.source for p in run] for run in runs]),
                       {"long_name": "the columns each pendulum was read from"}),
        "crossing_time": (("log", "metronome", "swing"), crossing,
                          {"units": "s", "long_name": "kept upward passes, since the table's "
                                                      "first time"}),
        "time_origin": (("log",), np.array(origins),
                        {"units": "s", "long_name": "the table's first time"}),
        "name": (("metronome",), np.array([p.swing.name for p in runs[0]]),
                 {"long_name": "pendulum (Tracker's track, or the column)"}),
        "path": (("log",), np.array([t.source for t in tables]), {"long_name": "angle table"}),
    }  # fmt: skip
    attrs = {
        "instrument": "angle table",
        "r_eq": float(equilibrium_order(r, grid, window)),
        "equilibrium_window": window,
        "sigma_bpm": sigma,
        "sigma_beats_per_tick": ph.bpm_to_beats_per_tick(sigma, DEFAULT_TICK),
        "tick": DEFAULT_TICK,
        "max_gap_steps": MAX_GAP,
        "metrosync_version": __version__,
    }
    coords = {
        "time": ("time", grid, {"units": "s", "long_name": "time since each table's first row"}),
        "metronome": ("metronome", np.array(chosen),
                      {"long_name": "pendulum index in the table (0-based)"}),
        "log": ("log", np.arange(len(tables)), {"long_name": "table index, in argument order"}),
    }  # fmt: skip
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _report(table: Table, run: list[Passes], chosen: list[int], t0: float) -> str:
    """The account of one table: its layout and rows, then each pendulum's reading."""
    step = float(np.median([p.step for p in run]))
    layout = {"\t": "tab", ";": "semicolon", ",": "comma", " ": "space"}[table.delimiter]
    comma = ", decimal comma" if table.decimal == "," else ""
    end = max(float(np.nanmax(p.swing.time)) for p in run)
    lines = [
        f"{table.source}: angle table, {plural(len(table.lines), 'row')} in "
        f"{plural(table.n_lines, 'line')} ({layout}-separated{comma}), t = {t0:g} .. "
        f"{end:g} s (counted from {t0:g} s), a sample every {1e3 * step:.4g} ms",
    ]
    for j, p in zip(chosen, run, strict=True):
        unit = {"deg": "°", "rad": " rad", "length": " (length)", "": ""}[p.swing.unit]
        gaps = f", {plural(p.gaps, 'gap')} in time" if p.gaps else ""
        lines.append(
            f"  metronome {j} = {p.swing.name}: {p.swing.source}; rest {p.rest:.4g}{unit}, "
            f"swing ±{p.amplitude:.3g}{unit}; {plural(p.kept.size, 'pass', 'passes')} kept, "
            f"{p.bridged} bridged{gaps}"
        )
    lines.append(f"  skipped {plural(len(table.skipped), 'line')}" + (
        " (lines " + ", ".join(str(n) for n, _ in table.skipped[:12])
        + (", ..." if len(table.skipped) > 12 else "") + ")" if table.skipped else ""))  # fmt: skip
    return "\n".join(lines)


def _warn_bridged(tables: list[Table], runs: list[list[Passes]]) -> None:
    for table, run in zip(tables, runs, strict=True):
        missed = [f"{p.swing.name}: {plural(p.bridged, 'pass', 'passes')}"
                  for p in run if p.bridged]  # fmt: skip
        if missed:
            warnings.warn(
                f"{table.source}: passes missed and bridged ({'; '.join(missed)}): blank "
                f"cells, gaps in time, or swings smaller than the hysteresis there; the "
                f"frequencies hold, the jitter leaves those periods out.",
                UserWarning,
                stacklevel=3,
            )

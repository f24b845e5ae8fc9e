"""`analyze`: light-gate logs → r(t), frequencies and σ, as an `xarray.Dataset`.

Contract: ``analyze(paths, *, tick=64e-6, ...)`` reads each log (`reader`), cleans
each gate (`cleaning`), and measures (`phases`). Several logs are repeated runs of
one experiment: r(t) is computed per log on one grid t = k·dt (seconds from each
log's first record) and averaged over the logs, as the paper averages 10
experiments. The dataset holds

    r                  (time)              r averaged over logs
    r_runs             (log, time)         r of each log
    frequency_bpm      (metronome)         mean frequency, averaged over logs, BPM
    frequency_bpm_runs (log, metronome)    mean frequency per log, BPM
    period_jitter      (log, metronome)    std of single periods, s
    passes_kept, passes_dropped, lines_skipped, counter_wraps, records_lost
                                           counts per log
                                           (and metronome)
    passes_bridged, intervals_irregular (log, metronome)   missed passes bridged
                                           (an interval of k periods counts k) and
                                           intervals off the period grid; a warning
                                           names each gate that has any
    direction_ambiguous, interrupted_level (log, metronome)   what the cleaning
                                           and the reader found about each gate
    path               (log)               the log files

and attrs ``r_eq`` (mean r over the final ``equilibrium_window``, default the last
quarter of the grid), ``sigma_bpm`` (σ of ``frequency_bpm``, ddof=1),
``sigma_beats_per_tick`` (the same in the unit of the paper's tables), the
options used, and the reading and cleaning reports.

A gate whose level never changes in a log (an unwired gate of the 8-gate firmware, or
a metronome that does not swing through its beam) is left out, with a warning that
names it, and listed in attrs ``gates_never_changed`` (text, e.g. ``"7"``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from .._words import plural
from ..errors import AnalysisError, ChannelCountError, ParameterError
from ..observables import crossings as ph
from ..observables.order import equilibrium_order
from .channels import check_channels, never_changed, never_changed_text
from .cleaning import (
    DEFAULT_GLITCH,
    DEFAULT_MAX_INTERRUPTION,
    DEFAULT_MIN_ASYMMETRY,
    clean_log,
    cleaning_report,
)
from .gatelog import GateLog
from .reader import DEFAULT_TICK, read_log


def analyze(
    paths: Sequence[str | Path] | str | Path,
    *,
    tick: float = DEFAULT_TICK,
    counter_bits: int | str | None = "auto",
    polarity: int | str = "auto",
    strict: bool = False,
    channels: Sequence[int] | None = None,
    glitch: float = DEFAULT_GLITCH,
    max_interruption: float = DEFAULT_MAX_INTERRUPTION,
    min_asymmetry: float = DEFAULT_MIN_ASYMMETRY,
    grid_dt: float = 0.1,
    equilibrium_window: float | None = None,
) -> xr.Dataset:
    """Analyse light-gate logs of one or more repeated runs.

    Parameters
    ----------
    paths : log files; several files are repeated runs and are averaged.
    tick : seconds per logger tick.
    counter_bits : counter width (bits), ``"auto"``, or None for no wrapping.
    polarity : ``"auto"`` or the level (0/1) that means "interrupted".
    strict : refuse any line that is not a record.
    channels : gates to analyse (0-based); default all.
    glitch, max_interruption, min_asymmetry : cleaning options, see `clean_channel`.
    grid_dt : spacing of the r(t) grid, s.
    equilibrium_window : seconds at the end of the grid averaged for ``r_eq``, at most
        the grid's span; default a quarter of it.

    Returns
    -------
    xarray.Dataset, described in the module docstring.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    paths = [Path(p) for p in paths]
    if not paths:
        raise ParameterError("`paths` is empty: give at least one light-gate log.")
    if not (np.isfinite(grid_dt) and grid_dt > 0):
        raise ParameterError(f"`grid_dt` must be a time > 0 s, got {grid_dt!r}.")
    logs = [read_log(path, tick=tick, counter_bits=counter_bits, polarity=polarity,
                     strict=strict) for path in paths]  # fmt: skip
    return analyze_logs(logs, counter_bits=counter_bits, polarity=polarity, channels=channels,
                        glitch=glitch, max_interruption=max_interruption,
                        min_asymmetry=min_asymmetry, grid_dt=grid_dt,
                        equilibrium_window=equilibrium_window)  # fmt: skip


def analyze_logs(
    logs: Sequence[GateLog],
    *,
    counter_bits: int | str | None = "auto",
    polarity: int | str = "auto",
    channels: Sequence[int] | None = None,
    glitch: float = DEFAULT_GLITCH,
    max_interruption: float = DEFAULT_MAX_INTERRUPTION,
    min_asymmetry: float = DEFAULT_MIN_ASYMMETRY,
    grid_dt: float = 0.1,
    equilibrium_window: float | None = None,
) -> xr.Dataset:
    """`analyze` of logs already read (`read_log`, or `LogFollower.log` for a growing one).

    counter_bits, polarity : the reading options the logs were read with (recorded in
    attrs); the other parameters are `analyze`'s.
    """
    if not logs:
        raise ParameterError("`logs` is empty: give at least one light-gate log.")
    if not (np.isfinite(grid_dt) and grid_dt > 0):
        raise ParameterError(f"`grid_dt` must be a time > 0 s, got {grid_dt!r}.")
    tick = logs[0].tick
    options = dict(glitch=glitch, max_interruption=max_interruption, min_asymmetry=min_asymmetry)
    cleaned = [clean_log(log, **options) for log in logs]
    k = logs[0].channels
    for log in logs[1:]:
        if log.channels != k:
            raise ChannelCountError(
                f"{log.source} has {plural(log.channels, 'gate')} but {logs[0].source} has {k}; "
                f"repeated runs must use the same gates."
            )
    asked = check_channels(channels, k)
    chosen = _skip_never_changed(logs, asked)
    per_log = [[c[j] for j in chosen] for c in cleaned]

    spans = []
    for log, chans in zip(logs, per_log, strict=True):
        ch_spans = [
            ph.channel_span(c.kept, log.source, j) for j, c in zip(chosen, chans, strict=True)
        ]
        spans.append((max(s for s, _ in ch_spans), min(e for _, e in ch_spans)))
    grid = ph.common_grid(spans, grid_dt)
    if grid.size < 2:
        start, end = max(s for s, _ in spans), min(e for _, e in spans)
        shown = ", ".join(f"{s:.3f} .. {e:.3f}" for s, e in spans)
        if end > start:  # there is a common span; the grid is too coarse for it
            raise ParameterError(
                f"`grid_dt` = {grid_dt:g} s leaves fewer than two grid times in the logs' "
                f"common span {start:.3f} .. {end:.3f} s; give `grid_dt` <= "
                f"{(end - start) / 2:.3g} s."
            )
        raise AnalysisError(
            f"the logs share no common span where every gate has a phase (spans {shown} s); "
            f"analyse them separately or leave out a gate that stops early (`channels=`)."
        )
    r_runs = np.stack([ph.order_on_grid([(c.kept, c.cycles) for c in chans], grid)
                       for chans in per_log])  # fmt: skip
    r = r_runs.mean(axis=0)
    freq = np.array([[ph.mean_frequency_bpm(c.kept, c.cycles) for c in chans] for chans in per_log])
    jitter = np.array([[ph.period_jitter(c.kept, c.cycles) for c in chans] for chans in per_log])
    kept = np.array([[c.kept.size for c in chans] for chans in per_log])
    bridged = np.array([[c.bridged for c in chans] for chans in per_log])
    irregular = np.array([[c.irregular for c in chans] for chans in per_log])
    extra = np.array([[c.dropped.get("duplicate", 0) for c in chans] for chans in per_log])
    _warn_missed_passes([log.source for log in logs], chosen, bridged, extra, irregular, kept)
    dropped = np.array([[sum(c.dropped.values()) for c in chans] for chans in per_log])
    ambiguous = np.array([[c.direction_ambiguous for c in chans] for chans in per_log])
    levels = np.array([log.interrupted_level[chosen] for log in logs], dtype=np.int8)
    mean_freq = freq.mean(axis=0)
    window = ph.equilibrium_window(grid, equilibrium_window)
    r_eq = float(equilibrium_order(r, grid, window))
    sigma = ph.frequency_spread(mean_freq)
    reports = "\n".join(
        log.report() + "\n" + cleaning_report(c, log.source)
        for log, c in zip(logs, cleaned, strict=True)
    )
    data = {
        "r": (("time",), r, {"long_name": "Kuramoto order parameter, mean over logs"}),
        "r_runs": (("log", "time"), r_runs, {"long_name": "Kuramoto order parameter per log"}),
        "frequency_bpm": (("metronome",), mean_freq,
                          {"units": "BPM", "long_name": "mean frequency, averaged over logs"}),
        "frequency_bpm_runs": (("log", "metronome"), freq,
                               {"units": "BPM", "long_name": "mean frequency per log"}),
        "period_jitter": (("log", "metronome"), jitter,
                          {"units": "s", "long_name": "std of single-period intervals"}),
        "passes_kept": (("log", "metronome"), kept,
                        {"long_name": "passes kept (one per period, one direction)"}),
        "passes_dropped": (("log", "metronome"), dropped,
                           {"long_name": "passes and interruptions dropped by the cleaning"}),
        "passes_bridged": (("log", "metronome"), bridged,
                           {"long_name": "missed passes bridged (an interval of k periods "
                                         "counts k)"}),
        "intervals_irregular": (("log", "metronome"), irregular,
                                {"long_name": "intervals more than 1/4 period off a whole "
                                              "number of periods"}),
        "direction_ambiguous": (("log", "metronome"), ambiguous.astype(np.int8),
                                {"long_name": "1: gate too central to tell the directions"}),
        "interrupted_level": (("log", "metronome"), levels,
                              {"long_name": "gate level read as 'interrupted' (-1 unknown)"}),
        "lines_skipped": (("log",), np.array([len(log.skipped) for log in logs]),
                          {"long_name": "lines that are not gate records"}),
        "counter_wraps": (("log",), np.array([log.wraps for log in logs]),
                          {"long_name": "times the logger's counter wrapped"}),
        "records_lost": (("log",), np.array([log.records_lost for log in logs]),
                         {"long_name": "records the logger reported lost (buffer overflow)"}),
        "path": (("log",), np.array([log.source for log in logs]), {"long_name": "log file"}),
    }  # fmt: skip
    attrs = {
        "gates_never_changed": ",".join(str(g) for g in asked if g not in chosen),
        "r_eq": r_eq,
        "equilibrium_window": window,
        "sigma_bpm": sigma,
        "sigma_beats_per_tick": ph.bpm_to_beats_per_tick(sigma, tick),
        "tick": tick,
        "grid_dt": grid_dt,
        "glitch": glitch,
        "max_interruption": max_interruption,
        "min_asymmetry": min_asymmetry,
        "counter_bits": "auto" if counter_bits == "auto" else str(counter_bits),
        "polarity": str(polarity),
        "report": reports,
        "metrosync_version": __version__,
    }
    return xr.Dataset(
        data,
        coords={
            "time": (
                "time",
                grid,
                {"units": "s", "long_name": "time since each log's first record"},
            ),
            "metronome": ("metronome", np.array(chosen), {"long_name": "gate index (0-based)"}),
            "log": ("log", np.arange(len(logs)), {"long_name": "log index, in argument order"}),
        },
        attrs=attrs,
    )


def _warn_missed_passes(sources, chosen, bridged, extra, irregular, kept) -> None:
    """One warning per log whose gates missed passes, saw extra ones, or irregular
    intervals: the frequency and jitter of those gates rest on bridged data."""
    for path, b_row, e_row, i_row, k_row in zip(sources, bridged, extra, irregular, kept,
                                                strict=True):  # fmt: skip
        gates = []
        for gate, b, e, i, k in zip(chosen, b_row, e_row, i_row, k_row, strict=True):
            found = [f"{plural(n, *what)}{done}" for n, what, done in (
                     (b, ("missed pass", "missed passes"), " bridged"),
                     (e, ("extra pass", "extra passes"), " dropped"),
                     (i, ("irregular interval",), "")) if n]  # fmt: skip
            if found:
                periods = max(int(k) - 1 + int(b), 1)
                gates.append(f"gate {gate}: {', '.join(found)} in {plural(periods, 'period')}")
        if gates:
            warnings.warn(
                f"{path}: {'; '.join(gates)}. Frequencies and period jitter there rest on "
                f"bridged passes: a gate near the end of the swing misses passes when the "
                f"swing shrinks; mount it nearer the centre (passes_bridged in the dataset).",
                UserWarning,
                stacklevel=3,
            )


def _skip_never_changed(logs: Sequence[GateLog], chosen: list[int]) -> list[int]:
    """The chosen gates less those that never changed in some log, with a warning."""
    dead = {g: [log.source for log in logs if g in never_changed(log.levels)] for g in chosen}
    dead = {g: sources for g, sources in dead.items() if sources}
    if not dead:
        return chosen
    kept = [g for g in chosen if g not in dead]
    every = len(logs) > 1 and all(len(s) == len(logs) for s in dead.values())
    where = "every log" if every else ", ".join(sorted({s for v in dead.values() for s in v}))
    if not kept:
        raise AnalysisError(
            f"every gate chosen ({', '.join(map(str, chosen))}) never changed in {where}: no "
            f"pendulum passed a beam. Check the wiring and the gates' places (docs/logger.md)."
        )
    warnings.warn(
        f"{where}: {never_changed_text(list(dead))}: left out; the analysis uses gates "
        f"{', '.join(map(str, kept))}. Give `channels` to choose the gates yourself.",
        UserWarning,
        stacklevel=3,
    )
    return kept

"""Plot of an `analyze_audio` result: waveform and ticks, beats, acoustic order.

Panels, on one time axis: the waveform (channel mix) with every detected tick,
coloured by the metronome it was given to (grey: none, or two at once); the beat of
each tick (time to the same metronome's next tick) in its metronome's colour, ticks
and tocks as two markers, so that a metronome out of beat shows two lines; the
acoustic order parameter R with its floor for independent metronomes and the distinct
ticks per beat; and, when metronomes were told apart, each one's ticks' phase in
metronome 0's beat.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._words import plural
from ..plots import finish_figure, new_figure

#: Colour of metronome m: METRONOME_COLOURS[m % 10]; ticks of none are grey.
METRONOME_COLOURS = tuple(f"C{i}" for i in range(10))
UNATTRIBUTED = "0.6"
#: Columns of the drawn waveform, at most (a screen's width; more only slows drawing).
MAX_COLUMNS = 3000
MARKERS = ("o", "s")


def plot_audio(ds, path: Path | str | None = None):
    """Draw the panels described in the module docstring; returns the figure.

    ds : a dataset from `metrosync.analyze_audio`.
    path : write the figure there (PNG, PDF, SVG, ...) when given.
    """
    phase = ds.phase_difference.values
    with_phase = bool(np.isfinite(phase).any())
    rows = 4 if with_phase else 3
    fig = new_figure(path, figsize=(9, 2.2 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, 1, sharex=True)
    t = ds.tick_time.values
    label = ds.tick_metronome.values
    tock = ds.tick_is_tock.values
    a = ds.attrs

    ax = axes[0]
    ax.fill_between(*_columns(ds, MAX_COLUMNS), color="0.35", lw=0)
    height = 10 ** (ds.tick_strength.values / 20)
    for m in sorted(set(label.tolist())):
        sel = label == m
        name = f"metronome {m}" if m >= 0 else "not attributed"
        ax.plot(t[sel], height[sel], "|", ms=6, color=colour(m),
                label=f"{name}: {plural(int(sel.sum()), 'tick')}")  # fmt: skip
    ax.set_ylabel("waveform")
    ax.legend(loc="upper right", fontsize="small")
    sure = f", attribution {a['attribution_sureness']}" if a.get("attribution_sureness") else ""
    tempo = "no common beat" if a.get("no_common_beat") else f"{a['bpm_ensemble']:.2f} BPM"
    ax.set_title(
        f"{Path(a['path']).name}: {tempo}, {plural(int(a['metronomes']), 'metronome')}{sure}"
    )

    ax = axes[1]
    interval = ds.tick_interval.values * 1e3
    if np.isfinite(interval).any():
        for m in sorted(set(label[label >= 0].tolist())):
            for kind, name in ((0, "tick→tock"), (1, "tock→tick")):
                sel = (label == m) & (tock == kind) & np.isfinite(interval)
                who = f"metronome {m}, " if ds.sizes.get("metronome", 1) > 1 else ""
                ax.plot(t[sel], interval[sel], MARKERS[kind], ms=2.5, color=colour(m),
                        label=f"{who}{name}")  # fmt: skip
        ax.set_ylabel("beat (ms)")
    else:
        ax.plot(ds.window.values, ds.beat_period.values * 1e3, color="C0",
                label="beat period (ticks not told apart)")  # fmt: skip
        ax.set_ylabel("beat period (ms)")
    ax.legend(loc="upper right", fontsize="small", ncol=2)

    ax = axes[2]
    if a.get("no_common_beat"):
        ax.text(0.5, 0.5, "R not computed: the metronomes keep different tempi, so "
                "their ticks share no beat", ha="center", va="center",
                transform=ax.transAxes)  # fmt: skip
        ax.set_yticks([])
    else:
        _plot_order(ax, ds)

    if with_phase:
        ax = axes[3]
        for m in sorted(set(label[np.isfinite(phase)].tolist())):
            ok = np.isfinite(phase) & (label == m)
            ax.plot(t[ok], np.degrees(phase[ok]), ".", ms=2, color=colour(m),
                    label=f"metronome {m}")  # fmt: skip
        ax.set_ylim(-180, 180)
        ax.set_yticks([-180, -90, 0, 90, 180])
        ax.set_ylabel("phase in 0's beat (°)")
        ax.legend(loc="upper right", fontsize="small")
    axes[-1].set_xlabel("time in the recording (s)")
    return finish_figure(fig, path)


def colour(metronome: int) -> str:
    """The colour of a metronome's ticks (grey for −1: none)."""
    return METRONOME_COLOURS[metronome % 10] if metronome >= 0 else UNATTRIBUTED


def _columns(ds, most: int):
    """(time, min, max) of the waveform, merged into at most ``most`` columns."""
    t, lo, hi = ds.wave.values, ds.wave_min.values, ds.wave_max.values
    k = -(-t.size // most)
    if k <= 1:
        return t, lo, hi
    cut = t.size - t.size % k
    parts = [(t[:cut].reshape(-1, k).mean(1), lo[:cut].reshape(-1, k).min(1),
              hi[:cut].reshape(-1, k).max(1))]  # fmt: skip
    if cut < t.size:
        parts.append((t[cut:].mean(keepdims=True), lo[cut:].min(keepdims=True),
                      hi[cut:].max(keepdims=True)))  # fmt: skip
    return tuple(np.concatenate(p) for p in zip(*parts, strict=True))


def _plot_order(ax, ds) -> None:
    """R over the windows with its floor, and the distinct ticks per beat."""
    w = ds.window.values
    ax.plot(w, ds.r_acoustic.values, color="C0", label="acoustic order parameter R")
    ax.plot(w, ds.r_floor.values, "--", color="0.4", lw=1, label="floor: independent metronomes")
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("R")
    twin = ax.twinx()
    twin.step(w, ds.clusters.values, where="mid", color="C1", lw=0.8, alpha=0.8)
    twin.set_ylabel("distinct ticks per beat", color="C1")
    twin.set_ylim(0, max(2.0, float(np.nanmax(ds.clusters.values)) + 1))
    ax.legend(loc="lower right", fontsize="small")

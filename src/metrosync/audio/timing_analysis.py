"""A recording analysed by the timing model: onsets, then metronomes that explain them.

The chain (docs/sound.md, "The timing model"): the detector's onsets and strengths
(`detection`, as `analyze_audio` finds them), explained as metronomes and clutter by
`decompose` (candidate tempi by epoch folding, each metronome a timing model with its
tick learned from the recording). It is the analysis that is to replace the stages of
`analyze_audio`; until it meets the corpus's bar, `analyze` does not use it, and the
benchmark (`benchmarks/audio_corpus.py --analysis timing`) scores it beside them.

Contract: `analyze_timing(path)` returns an `xarray.Dataset` with the variables of
`analyze_audio` that a score needs: ``tick_time`` (s) and ``tick_metronome`` per tick,
``bpm``, ``jitter``, ``limp`` per metronome, and in ``attrs`` the number of metronomes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from . import detection as det
from .decompose import decompose
from .reader import open_recording

#: Shortest time between two onsets, s: the detector's resolution, shorter than any gap
#: between a tick's impacts.
RESOLUTION = 3e-3


def analyze_timing(path: str | Path, *, sensitivity: float = det.DEFAULT_SENSITIVITY):
    """Onsets of the recording at ``path``, explained as metronomes (module docstring)."""
    recording = open_recording(path)
    scan = det.scan(recording, sensitivity=sensitivity)
    hops = det.pick_ticks(scan, max(1, round(RESOLUTION / (scan.hop / recording.sample_rate))))
    onsets = det.refine(recording, scan, hops)
    order = np.argsort(onsets.time, kind="stable")
    times, strengths = onsets.time[order], onsets.strength[order]
    heard, _ = decompose(times, strengths) if times.size else ([], None)
    tick_time = [times[h.ticks] for h in heard]
    label = [np.full(h.ticks.size, m) for m, h in enumerate(heard)]
    flat = np.concatenate(tick_time) if heard else np.zeros(0)
    whose = np.concatenate(label) if heard else np.zeros(0, dtype=np.int64)
    by_time = np.argsort(flat, kind="stable")
    timing = [h.followed.timing for h in heard]
    # the tempo a listener counts: the mean over the beats heard, drift and all
    tempo = [
        t.mean_bpm(int(h.beats.min()), int(h.beats.max()))
        for t, h in zip(timing, heard, strict=True)
    ]
    return xr.Dataset(
        {
            "tick_time": ("tick", flat[by_time], {"units": "s"}),
            "tick_metronome": ("tick", whose[by_time]),
            "bpm": ("metronome", tempo, {"units": "1/min"}),
            "jitter": ("metronome", [t.jitter for t in timing], {"units": "s"}),
            "limp": ("metronome", [t.limp for t in timing]),
        },
        attrs={"metronomes": len(heard), "onsets": int(times.size), "path": str(path)},
    )

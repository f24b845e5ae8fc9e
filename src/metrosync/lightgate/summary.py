"""The printed summary of an `analyze` dataset: frequencies, jitter, σ, r_eq, cleaning."""

from __future__ import annotations

from .._words import plural


def summary_text(ds) -> str:
    """The printed summary: frequencies, jitter, σ, r_eq and the cleaning report."""
    a = ds.attrs
    lines = [
        f"metrosync analyze: {plural(ds.sizes['log'], 'log')}, "
        f"{plural(ds.sizes['metronome'], 'metronome')}, "
        f"common span {float(ds.time[0]):.1f} .. {float(ds.time[-1]):.1f} s",
        "  metronome  frequency (BPM)  period jitter (ms, mean over logs)  passes bridged",
    ]
    jitter = ds.period_jitter.mean("log").values * 1e3
    bridged = ds.passes_bridged.sum("log").values
    rows = zip(ds.metronome.values, ds.frequency_bpm.values, jitter, bridged, strict=True)
    for m, f, j, b in rows:
        lines.append(f"  {int(m):9d}  {f:15.3f}  {j:34.3f}  {int(b):14d}")
    lines += [
        f"  sigma = {a['sigma_bpm']:.4f} BPM ({a['sigma_beats_per_tick']:.3g} beats per tick)",
        f"  equilibrium r (last {a['equilibrium_window']:.1f} s): {a['r_eq']:.4f}",
        a["report"],
    ]
    return "\n".join(lines)

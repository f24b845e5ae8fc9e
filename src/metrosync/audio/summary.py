"""The printed summary of an `analyze_audio` dataset, in plain words."""

from __future__ import annotations

import numpy as np

from .._words import plural


def _quarter_mean(values: np.ndarray, last: bool) -> float:
    values = np.asarray(values, dtype=float)
    q = max(1, values.size // 4)
    part = values[-q:] if last else values[:q]
    part = part[np.isfinite(part)]
    return float(part.mean()) if part.size else float("nan")


def summary_text(ds) -> str:
    """Lines: the file, the ticks and tempo, each metronome's beat, the synchrony."""
    a = ds.attrs
    k = ds.sizes["tick"]
    n = int(a["metronomes"])
    apart = a.get("no_common_beat", "")
    beat = (
        "no common beat (each metronome's tempo is below)"
        if apart
        else f"beat {1e3 * a['beat_period']:.2f} ms = {a['bpm_ensemble']:.2f} BPM "
        f"({a['tempo_source']}); {a['ticks_per_beat']:.2f} ticks per beat"
    )
    lines = [
        f"metrosync analyze: {a['path']} ({a['format']}, {plural(int(a['channels']), 'channel')}, "
        f"{a['sample_rate']} Hz, {a['duration']:.1f} s)",
        f"  ticks: {k}, {beat}",
        f"  impacts heard: {a['impacts']}, {a['tick_structure']}"
        + (
            f"; {plural(int(a['ticks_recovered']), 'tick')} hidden by others found again "
            f"where their metronome's beat put them"
            if a.get("ticks_recovered")
            else ""
        ),
        f"  metronomes: {n} ({a['metronomes_source']})"
        + (f"; not told apart ({a['attribution_note']})" if a["attribution_note"] else ""),
    ]
    if a.get("metronomes_hidden"):
        lines.append(f"  {a['hidden_note']}")
    if "metronome" in ds.dims:
        for m in range(ds.sizes["metronome"]):
            lines.append(
                f"  metronome {m}: {float(ds.bpm[m]):.3f} ± {float(ds.bpm_error[m]):.3f} BPM, "
                f"jitter {1e3 * float(ds.jitter[m]):.2f} ms, {plural(int(ds.ticks[m]), 'tick')}"
                + (
                    f" ({plural(int(ds.missed_beats[m]), 'beat')} missed)"
                    if int(ds.missed_beats[m])
                    else ""
                )
            )
            lines.append(f"    {str(ds.beat_verdict.values[m])}")
            if "tick_impacts" in ds:
                lines.append(f"    its sound: {str(ds.tick_impacts.values[m])}")
    if a.get("attribution_sureness"):
        lines.insert(
            5 if a.get("metronomes_hidden") else 4,
            f"  attribution: {a['attribution_sureness']} (confidence "
            f"{a['attribution_confidence']:.2f}: "
            + a.get(
                "attribution_meaning",
                "share of ticks in a train x share of beats heard x how far apart the sounds are",
            )
            + ")",
        )
    phase = ds.phase_difference.values
    label = ds.tick_metronome.values
    for m in range(1, ds.sizes.get("metronome", 0)):
        mine = phase[(label == m) & np.isfinite(phase)]
        if not mine.size:
            continue
        last = mine[-max(1, mine.size // 4) :]
        z = np.exp(1j * last).mean()
        spread = np.degrees(np.sqrt(max(0.0, -2 * np.log(max(abs(z), 1e-12)))))
        state = "drifting: not locked" if spread > 60 else "locked"
        lines.append(
            f"  phase difference of the ticks ({m} in 0's beat), last quarter: "
            f"{np.degrees(np.angle(z)):.1f}° ± {spread:.1f}° ({state}; 0°: together; the "
            f"pendulums differ by half this, or half plus 180°)"
        )
    if ds.sizes.get("metronome", 0) > 1 and np.isfinite(a.get("r_eq", np.nan)):
        lines.append(
            f"  sigma = {a['sigma_bpm']:.4f} BPM; equilibrium r of the pendulums (last quarter, "
            f"ticks as passes one way) {a['r_eq']:.3f}"
        )
    if apart:
        lines.append(
            f"  acoustic order parameter R and distinct ticks per beat: not computed: {apart}"
        )
    elif n > 1 or k and "metronome" not in ds.dims:
        r0, r1 = _quarter_mean(ds.r_acoustic, False), _quarter_mean(ds.r_acoustic, True)
        f1 = _quarter_mean(ds.r_floor, True)
        c0, c1 = _quarter_mean(ds.clusters, False), _quarter_mean(ds.clusters, True)
        lines += [
            f"  acoustic order parameter R (window {a['order_window']:.1f} s): first quarter "
            f"{r0:.3f}, last quarter {r1:.3f} (independent metronomes: about {f1:.3f}; "
            f"1: all tick together)",
            f"  distinct ticks per beat: first quarter {c0:.1f}, last quarter {c1:.1f}",
        ]
    return "\n".join(lines)

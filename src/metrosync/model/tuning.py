"""Tunings: how a nominal BPM becomes a slider position (docs/model.md §6.1–6.3).

``"small-amplitude"`` (the default) inverts the small-amplitude frequency on a rigid
    support in closed form (`MetronomeDesign.small_amplitude_l2`).
``"steady-swing"`` puts the *tick rate at the steady swing* on the nominal BPM, as a real
    metronome's marking does (`metrosync.model.steady_swing`: single-pendulum mechanics,
    solved once per design and cached; it needs scipy, loaded on first use).

This module is the one place that knows the tunings by name: `TUNINGS`, the range a
design tunes over (`bpm_range`), the slider position for a BPM (`l2_for_bpm`, which
`MetronomeDesign.l2_for_bpm` calls with the design's own tuning), and `with_tuning`.
"""

from __future__ import annotations

from dataclasses import replace

from ..errors import ParameterError

#: Tuning names: how a nominal BPM becomes a slider position (module docstring).
TUNINGS = ("small-amplitude", "steady-swing")

#: What a nominal BPM means under each tuning, as a summary says it to a user.
MEANINGS = {
    "small-amplitude": "the nominal BPM tunes the small-swing frequency; a wider swing "
    "ticks slower",
    "steady-swing": "the nominal BPM is the tick rate at the steady swing, as a real "
    "metronome's marking",
}


def check_tuning(tuning) -> None:
    """Raise `ParameterError` unless ``tuning`` is one of `TUNINGS`."""
    if not isinstance(tuning, str) or tuning not in TUNINGS:
        raise ParameterError(f"unknown `tuning` {tuning!r}; choose one of {list(TUNINGS)}.")


def bpm_range(design) -> tuple[float, float]:
    """Lowest and highest nominal BPM the slider of ``design`` reaches, under its tuning."""
    if design.tuning == "steady-swing":
        from .steady_swing import steady_swing_bpm_range  # needs scipy; loaded on use

        return steady_swing_bpm_range(design)
    return design.small_amplitude_range()


def l2_for_bpm(design, bpm, *, tuning: str = "small-amplitude"):
    """Slider position ``L2`` (m) for ``bpm`` under the named ``tuning`` (one of `TUNINGS`).

    Scalars or arrays; raises `ParameterError` for a BPM outside the tuning's range
    (`MetronomeDesign.check_tunable`: the design's one range check and message, which
    names the range and a fix).
    """
    check_tuning(tuning)
    tuned = design if tuning == design.tuning else replace(design, tuning=tuning)
    tuned.check_tunable(bpm)
    if tuning == "steady-swing":
        from .steady_swing import steady_swing_l2  # needs scipy; loaded on use

        return steady_swing_l2(design, bpm)
    return design.small_amplitude_l2(bpm)


def with_tuning(params, tuning: str | None):
    """``params`` whose design uses ``tuning``; None keeps the design's own.

    The theory's functions take ``tuning=`` beside ``params``; this is the one place
    where the two meet, so that what is computed, labelled, stored and cached is the
    design's ``tuning`` and nothing else.
    """
    if tuning is None or tuning == params.metronome.tuning:
        return params
    check_tuning(tuning)
    return params.with_changes(tuning=tuning)

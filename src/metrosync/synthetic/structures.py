"""Tick structures: how many impacts a make's tick has, in which order, how regular
each one is.

What real metronomes do, measured on a phone recording of a Neewer mechanical
metronome (96.4 BPM, limp 3.9 %, 44.1 kHz, 15 s): before 21 of its 24 loud impacts, a
quieter impact 11–42 ms earlier, whose lead wanders from tick to tick (the quiet
impacts' times spread by about 9 ms, the loud ones' by under 1 ms); later impacts as
`metrosync.synthetic.ticks` draws them; tick and tock of different strength and
structure. Makes differ in this, so a corpus draws several structures:

- ``"classic"``: what `Voice.draw` has always drawn: a main impact, one to three later
  ones 15–35 ms after it, the tock the same impacts at other resonances, 0.6–0.85 as
  loud (`metrosync.synthetic.ticks`);
- ``"uneven"``: tick and tock of different structure and strength: the tock's later
  impacts its own (zero to three, drawn apart from the tick's), the tock 0.45–0.85 as
  loud as the tick;
- ``"precursor"``: ``"uneven"``, and before the loud impact of most ticks a quieter one
  (a `Precursor`, one for the ticks and one for the tocks): it comes before
  `PRECURSOR_SHARE` (75–95 %) of them, `PRECURSOR_LEAD` (22–32 ms) early on average
  with a spread of `PRECURSOR_SPREAD` (4–10 ms) from tick to tick, truncated to
  `metrosync.synthetic.ticks.PRECURSOR_LEADS` (10–45 ms), `PRECURSOR_GAIN` (0.2–0.6)
  times as high as the loud impact, with its sound.

The time of a tick is that of its loud impact, the most regular one: a precursor's
lead wanders by milliseconds, the loud impact only by the escapement's jitter.

`widen(voice, structure)` adds a structure's traits to a voice drawn as ever, from a
generator of its own ([33, structure's key, voice's seed]): the classic voice of a seed
is unchanged by it, and a widened voice is reproducible from (seed, structure).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .ticks import SUB_GAIN_RANGE, Precursor, Voice, later_delays

#: How often a precursor comes before a tick of its kind (the Neewer: 21 of 24).
PRECURSOR_SHARE = (0.75, 0.95)
#: Its mean lead before the loud impact, s (the Neewer's leads: 11–42 ms).
PRECURSOR_LEAD = (0.022, 0.032)
#: The spread of its lead from tick to tick, s (the Neewer's: about 9 ms).
PRECURSOR_SPREAD = (0.004, 0.010)
#: Its height relative to the loud impact.
PRECURSOR_GAIN = (0.2, 0.6)
#: How loud the tock is relative to the tick, where tick and tock differ in strength.
UNEVEN_TOCK_GAIN = (0.45, 0.85)


@dataclass(frozen=True)
class TickStructure:
    """What a make's ticks are made of, beyond the classic voice.

    name : its name in `STRUCTURES`.
    key : the first number of the seed of its draws (each structure draws apart).
    tock_impacts : the tock's later impacts drawn apart from the tick's.
    tock_gain : range the tock's loudness relative to the tick is drawn from, or None
        to keep the classic voice's.
    precursor : a `Precursor` drawn before the ticks and one before the tocks.
    """

    name: str
    key: int
    tock_impacts: bool = False
    tock_gain: tuple[float, float] | None = None
    precursor: bool = False


#: The structures a voice can be drawn with, by name.
STRUCTURES: dict[str, TickStructure] = {
    "classic": TickStructure("classic", 0),
    "uneven": TickStructure("uneven", 1, tock_impacts=True, tock_gain=UNEVEN_TOCK_GAIN),
    "precursor": TickStructure(
        "precursor", 2, tock_impacts=True, tock_gain=UNEVEN_TOCK_GAIN, precursor=True
    ),
}


def structure_named(name: str) -> TickStructure:
    """The structure called ``name``; an unknown name lists the known ones."""
    if name not in STRUCTURES:
        raise ParameterError(
            f"`structure` must be one of {', '.join(map(repr, STRUCTURES))}, got {name!r}."
        )
    return STRUCTURES[name]


def widen(voice: Voice, structure: str | TickStructure) -> Voice:
    """``voice`` with the traits of ``structure`` (a name in `STRUCTURES` or a
    `TickStructure`), drawn from the voice's seed; "classic" returns it as it is."""
    if isinstance(structure, str):
        structure = structure_named(structure)
    if not (structure.tock_impacts or structure.tock_gain or structure.precursor):
        return voice
    rng = np.random.default_rng([33, structure.key, int(voice.seed)])
    changes: dict = {}
    if structure.tock_impacts:
        count = int(rng.integers(0, 4))
        changes["tock_sub_delays"] = tuple(float(d) for d in later_delays(count, rng))
        changes["tock_sub_gains"] = tuple(float(g) for g in rng.uniform(*SUB_GAIN_RANGE, count))
    if structure.tock_gain is not None:
        changes["tock_gain"] = float(rng.uniform(*structure.tock_gain))
    if structure.precursor:
        for name in ("precursor", "tock_precursor"):
            changes[name] = Precursor(
                lead=float(rng.uniform(*PRECURSOR_LEAD)),
                spread=float(rng.uniform(*PRECURSOR_SPREAD)),
                gain=float(rng.uniform(*PRECURSOR_GAIN)),
                share=float(rng.uniform(*PRECURSOR_SHARE)),
            )
    return dataclasses.replace(voice, **changes)

"""Readings of the paper's parameters, and the claims map that tries each one.

Contract: a `Reading` is one candidate interpretation of the numbers the paper prints
where they do not add up (docs/model.md §6): the unit of Tables 1–2's σ, the tuning
rule, the drive and friction, the disk's inertia J(N), and whether the escapement's
reaction acts on the disk. `READINGS` is the Cartesian product of the first four, and
today's reading without the reaction. `reading_studies(reading, level)` turns the
paper's studies into that reading's versions (`metrosync.paper.studies`), with the statistics of a
`ClaimStatistics` level (`SCREEN` for every reading, `BEST` for the best readings
again in ``--full``). The claims map that runs them is `metrosync.paper.claims_map`.

The axes (each value is an overridable model parameter, never a hidden constant):

``sigma``    ``beat``: 8×10⁻⁷ per 64 µs tick read as beats per tick (0.75 BPM, today's
             default); ``period``: as periods per tick, twice the spread (1.5 BPM).
``tuning``   ``small-amplitude`` (today's) or ``steady-swing`` (the slider puts the
             *tick rate* at the steady swing on the nominal BPM).
``drive``    ``published``: c_θ = 5×10⁻⁵, M = 6×10⁻⁴ (overturns, 7.6 rad);
             ``M/10``: M = 6×10⁻⁵ (today's default, 0.76 rad); ``c_theta*10``:
             c_θ = 5×10⁻⁴ with the published M (0.76 rad: the other possible misprint).
``inertia``  ``law``: J(N) = J₀ + N j (today's); ``constant``: J = 0.25515 kg m² for
             every N (the top of the published range).

``reaction`` ``on``: the escapement's torque −Σ𝕄_i acts on the disk, as eq. (metron2a)
             writes it; ``off``: the kicks drive the pendulums only
             (``escapement_reaction`` = false). Only today's reading is tried without
             it: the whole product again would double the map's cost, and the
             screen shows what the switch alone does.

The z-study (claim 5) is read through each reading too: the paper's two drives,
6×10⁻⁵ ("small") and 6×10⁻⁴ ("large, realistic"), are one tenth of and equal to its
published M; a reading that corrects M or c_θ corrects both regimes alike, so its
z-study runs free (c_θ = c_φ = M = 0), small (the reading's c_θ, M/10) and large
(the reading's c_θ and M). The free regime has no steady swing to tune to, so it
keeps the small-amplitude tuning (its swing starts at 0.1 rad, where both agree); so
does the large regime of a drive that overturns. Claims 1–4 of a steady-swing reading
whose drive overturns are not simulated: there is no swing to tune to. A reading whose
tunable range is narrower than a study's ω₀ (the steady-swing tuning with c_θ × 10
reaches only 212.7 BPM) runs that study on the ω₀ it can reach, 5 σ inside the range.

Seeds depend only on the study's and the cell's names, so every reading draws the
same frequencies and starts (common random numbers), and a point whose resolved
parameters coincide between readings is simulated once.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

from ..errors import ParameterError
from ..model import TUNINGS
from .studies import (
    FIG8_BOTTOM,
    FIG8_TOP,
    FIG10,
    FIG11,
    FREE,
    Z_STUDY,
    Case,
    Regime,
    Statistics,
    SweepGrid,
)
from .studies import ZGrid as _ZGrid

SIGMA_FACTORS = {"beat": 1.0, "period": 2.0}
#: (c_θ kg m²/s, M N m s) of each drive reading.
DRIVES = {"published": (5e-5, 6e-4), "M/10": (5e-5, 6e-5), "c_theta*10": (5e-4, 6e-4)}
#: The top of the published J range, kg m² (paper §5).
J_CONSTANT = 0.25515
INERTIAS = ("law", "constant")
REACTIONS = ("on", "off")
#: Score of a verdict when readings are ranked (sum over claims 1–5).
SCORES = {"reproduced": 1.0, "partly reproduced": 0.5}


@dataclass(frozen=True)
class Reading:
    """One reading of the paper's parameters (see the module docstring)."""

    sigma: str = "beat"
    tuning: str = "small-amplitude"
    drive: str = "M/10"
    inertia: str = "law"
    reaction: str = "on"

    def __post_init__(self) -> None:
        for name, value, allowed in (
            ("sigma", self.sigma, SIGMA_FACTORS),
            ("tuning", self.tuning, TUNINGS),
            ("drive", self.drive, DRIVES),
            ("inertia", self.inertia, INERTIAS),
            ("reaction", self.reaction, REACTIONS),
        ):
            if value not in allowed:
                raise ParameterError(f"unknown `{name}` {value!r}; choose one of {list(allowed)}.")

    @property
    def name(self) -> str:
        """A short unique name, e.g. ``σ-beat/small-amplitude/M/10/J-law`` (with
        ``/no-reaction`` when the escapement's reaction is off)."""
        name = f"σ-{self.sigma}/{self.tuning}/{self.drive}/J-{self.inertia}"
        return name if self.reaction == "on" else f"{name}/no-reaction"

    @property
    def sigma_factor(self) -> float:
        return SIGMA_FACTORS[self.sigma]

    def changes(self, *, drive_factor: float = 1.0, tuned: bool = True) -> dict:
        """Model changes from the `default` preset for this reading.

        drive_factor : scales the reading's M (the z-study's small regime uses 0.1).
        tuned : False keeps the small-amplitude tuning (the undriven z regime).
        """
        c_theta, drive = DRIVES[self.drive]
        out: dict = {}
        if c_theta != 5e-5:
            out["c_theta"] = c_theta
        if drive * drive_factor != 6e-5:
            out["drive"] = float(f"{drive * drive_factor:.12g}")
        if self.inertia == "constant":
            out["inertia"] = J_CONSTANT
        if tuned and self.tuning != "small-amplitude":
            out["tuning"] = self.tuning
        if self.reaction == "off":
            out["escapement_reaction"] = False
        return out

    def params(self, *, tuned: bool = True):
        """The `default` preset with this reading's changes (see `changes`)."""
        from ..model import get_preset

        return get_preset("default", warn=False).with_changes(**self.changes(tuned=tuned))

    @property
    def overturns(self) -> bool:
        """True when the reading's energy-balance swing passes the horizontal: there is
        then no steady swing, and the steady-swing tuning has nothing to tune to."""
        return self.params(tuned=False).overturns

    @property
    def tunable(self) -> bool:
        """Whether the reading's tuning can be applied at its own drive."""
        return self.tuning == "small-amplitude" or not self.overturns

    def bpm_range(self) -> tuple[float, float]:
        """The nominal BPMs the slider reaches under this reading (its tuning, friction
        and drive): the steady-swing range is narrower than the small-amplitude one."""
        return self.params().metronome.bpm_range()

    def describe(self) -> str:
        c_theta, drive = DRIVES[self.drive]
        return (
            f"σ per {self.sigma} (Fig. 10: {0.75 * self.sigma_factor:g} BPM), {self.tuning} "
            f"tuning, c_θ = {c_theta:g}, M = {drive:g}, J "
            + ("by the law J₀ + N j" if self.inertia == "law" else f"= {J_CONSTANT} kg m²")
            + ("" if self.reaction == "on" else ", no escapement reaction on the disk")
        )


#: Today's reading (the reproduction's studies).
TODAY = Reading()
#: Every reading of the map, today's first.
READINGS: tuple[Reading, ...] = (
    TODAY,
    *(
        reading
        for values in itertools.product(SIGMA_FACTORS, TUNINGS, DRIVES, INERTIAS)
        if (reading := Reading(*values)) != TODAY
    ),
    Reading(reaction="off"),
)


@dataclass(frozen=True)
class ClaimStatistics:
    """How much each claim's study simulates at one level of the claims map.

    fig11 : claim 1 (N = 2…64, σ = 0).   fig8 : claims 2 and 3 (N = 7 over ω₀; N = 2…7).
    fig10 : claim 4's sweep.   z : claim 5's θ₂(0) grid and run length.
    """

    fig11: Statistics
    fig8: Statistics
    fig10: SweepGrid
    z: _ZGrid


def axes_changed(reading: Reading, base: Reading | None = None) -> int:
    """How many axes of ``reading`` differ from ``base`` (today's reading)."""
    base = TODAY if base is None else base
    axes = ("sigma", "tuning", "drive", "inertia", "reaction")
    return sum(getattr(reading, a) != getattr(base, a) for a in axes)


def _both(study, stats):
    """``study`` with ``stats`` in both modes (the claims map runs it in quick mode)."""
    return replace(study, quick=stats, full=stats)


def reading_studies(reading: Reading, level: ClaimStatistics) -> dict[int, object]:
    """Claim number -> the study that checks it under ``reading`` at ``level``.

    The studies keep the names of the reproduction's (their seeds follow from them).
    """
    changes = tuple(sorted(reading.changes().items()))
    f = reading.sigma_factor
    reach = _reach(reading)
    scaled = {
        study.name: replace(
            _both(study, level.fig8),
            cases=tuple(
                Case(c.n, c.bpm, c.sigma_bpm * f, c.label)
                for c in study.cases
                if reach(c.bpm, c.sigma_bpm * f)
            ),
            changes=changes,
        )
        for study in (FIG8_TOP, FIG8_BOTTOM)
    }
    sigma10 = FIG10.sigma_bpm * f
    fig10 = replace(level.fig10, bpms=tuple(b for b in level.fig10.bpms if reach(b, sigma10)))
    c_theta, drive = DRIVES[reading.drive]
    regimes = (
        Regime("no friction, no drive", changes=tuple(sorted(
            {**reading.changes(tuned=False), **dict(FREE)}.items()))),
        Regime(f"c_θ = {c_theta:g}, M = {drive / 10:g} (small)",
               changes=tuple(sorted(reading.changes(drive_factor=0.1).items()))),
        # An overturning drive has no steady swing to tune to: small-amplitude tuning.
        Regime(f"c_θ = {c_theta:g}, M = {drive:g} (large)", changes=tuple(sorted(
            reading.changes(tuned=reading.tunable).items()))),
    )  # fmt: skip
    return {
        1: replace(_both(FIG11, level.fig11), changes=changes),
        2: scaled[FIG8_TOP.name],
        3: scaled[FIG8_BOTTOM.name],
        4: replace(_both(FIG10, fig10), sigma_bpm=sigma10, changes=changes),
        5: replace(_both(Z_STUDY, level.z), regimes=regimes),
    }


#: Standard deviations of the frequency draws kept inside the tunable range: a study's
#: ω₀ closer than this to an end of the reading's range is left out (one draw in 3×10⁶
#: would fall outside and fail its point).
RANGE_MARGIN_SIGMAS = 5.0


def _reach(reading: Reading):
    """``reach(bpm, sigma)``: whether an ensemble at ``bpm`` with spread ``sigma`` stays
    within the reading's tunable range. An untunable reading is not simulated at all
    (`claims_map`), so every ω₀ is kept for it."""
    if not reading.tunable:
        return lambda bpm, sigma: True
    low, high = reading.bpm_range()
    return lambda bpm, sigma: (
        low + RANGE_MARGIN_SIGMAS * sigma <= bpm <= high - RANGE_MARGIN_SIGMAS * sigma
    )


def _bpms(start: float, stop: float, step: float) -> tuple[float, ...]:
    count = int(round((stop - start) / step)) + 1
    return tuple(float(start + i * step) for i in range(count))


#: Every reading at these statistics, in both modes ("quick statistics for all"): claim 4
#: on N = 7 and 64 every 10 BPM, the rest a fifth of the paper's runs, or fewer.
SCREEN = ClaimStatistics(
    fig11=Statistics(8, 300.0),
    fig8=Statistics(20, 300.0),
    fig10=SweepGrid(ns=(7, 64), bpms=_bpms(150.0, 220.0, 10.0), stats=Statistics(8, 300.0)),
    z=_ZGrid(theta2=tuple(round(x, 6) for x in _bpms(-0.1, 0.1, 0.02)), duration=1500.0),
)
#: The best readings at the reproduction's --full statistics. Claim 4 runs on N = 7, 64
#: and 128 every 5 BPM with Fig. 10's runs, durations and seeds, so that today's
#: reading reuses Fig. 10's own points.
BEST = ClaimStatistics(
    fig11=FIG11.full,
    fig8=FIG8_TOP.full,
    fig10=SweepGrid(ns=(7, 64, 128), bpms=_bpms(150.0, 220.0, 5.0), stats=FIG10.full.stats),
    z=Z_STUDY.full,
)

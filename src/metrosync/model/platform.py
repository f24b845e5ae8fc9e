"""The platform that carries the metronomes: the paper's freely rotating disk (§4–5),
or a board on rollers (Pantaleone, Am. J. Phys. 70, 992 (2002)).

Both are one generalized coordinate φ that the pendulums' pivots follow: the disk
turns by φ (rad) and moves each pivot R φ along the rim; the board translates by φ
(m) and moves each pivot by φ. Written with the *lever* ℓ (R for the disk, 1 m for the
board) and the platform's own inertia J_p (J for the disk, kg m²; the board's mass
with the rollers' effective mass and the metronomes' cases, kg), the equations of
motion are the same (docs/model.md §3 and §9), so the platform is a term of the model,
not of the integrators: `Platform.terms` gives every integrator the constants it reads.

The disk
--------

The disk's own moment of inertia ``J`` includes the metronome boxes. The paper gives
only its range, J ∈ [0.0729, 0.25515] kg m², for 0 to 7 metronomes. We adopt the
linear law that matches both ends (docs/model.md §6.6),

    J(N) = J0 + N·j,   J0 = 0.0729 kg m² (1 kg × R²),   j = (0.25515 − 0.0729)/7,

which makes the coupling mean-field as N grows. A fixed ``J`` (or ``inf`` for a rigid
support) overrides the law.

Beyond the paper, two switches of the disk's equation (metron2a), both off by default:
an external periodic torque τ(t) = A sin(Ω t) with Ω = π·BPM/60 (the metronomes'
convention, so forcing at a metronome's BPM is resonant), and ``escapement_reaction``,
which the paper has on: the escapement's torque −Σ𝕄_i reacts on the disk.

Besides the paper's viscous bearing friction −c_φ φ̇, the disk may have dry (Coulomb)
friction, as Goldsztein, English, Behta, Finder, Nadeau and Strogatz measured for real
metronome platforms (Chaos 32, 043119, 2022): the disk sticks while the torque needed to
hold it stays within ``disk_dry_friction`` and slips against a torque of that size
otherwise. Off (0) by default, as in the paper.

The board
---------
A board of mass ``board_mass`` resting on rolling cylinders, carrying the metronomes'
cases (``box_mass`` each) and their pendulums, which swing along it. A cylinder of mass
m_c, radius a and moment of inertia I_c rolling without slipping between table and board
moves at half the board's speed and turns at ẋ/(2a): its kinetic energy is
½ (m_c + I_c/a²)/4 · ẋ², so it counts as the mass (m_c + I_c/a²)/4 on the board (m_c/2
for a thin-walled can); ``roller_mass`` is the sum of these over the rollers. The board
feels viscous damping ``board_damping`` and Coulomb friction ``board_dry_friction``, and
the applied force A sin(Ω t) (``forcing_amplitude`` in N). The escapement's torque acts
between a pendulum and its case about an axis across the board, so it exerts no net
force along the board: on the board there is no escapement reaction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .quantity import (
    NON_NEGATIVE,
    POSITIVE,
    check_quantities,
    declared,
    documented,
    quantity,
    units,
)

PAPER_J_MIN = 0.0729
PAPER_J_MAX = 0.25515
PAPER_N_MAX = 7

#: The platforms a model may stand on (module docstring).
PLATFORMS = ("disk", "board")
#: Fields that only the disk reads, and those that only the board reads.
DISK_FIELDS = ("radius", "c_phi", "j0", "j_per_metronome", "inertia", "escapement_reaction",
               "disk_dry_friction")  # fmt: skip
BOARD_FIELDS = ("board_mass", "box_mass", "roller_mass", "board_damping", "board_dry_friction")


@dataclass(frozen=True)
class PlatformTerms:
    """What the equations of motion need of a platform carrying ``n`` metronomes: the
    lever ℓ (m; the pivot's displacement per unit of the coordinate), the platform's own
    inertia J_p (kg m² or kg; ``inf`` holds it still), its viscous damping and dry
    friction (per unit of the coordinate's velocity and as a generalized force), the
    applied force's amplitude and whether the escapement's reaction acts on it."""

    lever: float
    own_inertia: float
    damping: float
    dry_friction: float
    forcing_amplitude: float
    escapement_reaction: bool


@documented
@dataclass(frozen=True)
class Platform:
    """Platform parameters, SI units (each declared on its field and listed below).

    platform : ``"disk"`` (the paper's, the default) or ``"board"`` (module docstring).
        A parameter of the other platform set away from its default is an error, not
        ignored.

    The disk's:

    radius : R, distance of the pivots from the axis.
    c_phi : viscous friction of the disk's bearing.
    j0, j_per_metronome : the law J(N) = j0 + N·j_per_metronome.
    inertia : if set, a fixed J that ignores the law; ``math.inf`` pins the disk.
    forcing_amplitude : A of the external torque τ(t) = A sin(Ω t) on the disk;
        0 (the default) switches it off.
    forcing_bpm : the forcing's frequency in the metronomes' BPM, Ω = π·BPM/60 rad/s;
        needed (> 0) when ``forcing_amplitude`` is not 0.
    escapement_reaction : whether the escapement's torque reacts on the disk, the
        −Σ𝕄_i term of eq. (metron2a) (True, as the paper writes it). False keeps the
        kicks on the pendulums but takes their reaction off the disk, as if the
        escapement were driven from outside the platform. Accepts 0 or 1.
    disk_dry_friction : the disk's Coulomb friction torque: the largest torque that
        holds the disk at rest, and the torque against a slipping disk; 0 for none.

    The board's (defaults: Pantaleone's board, 58 g, and the cases of his 94 g
    metronomes, the pendulum's mass taken off; the cans' mass neglected as in his Eq. 2):

    board_mass : the board alone.
    box_mass : each metronome's case (everything but its pendulum), carried by the board.
    roller_mass : the rollers' effective mass, Σ (m_c + I_c/a²)/4 (module docstring).
    board_damping : viscous damping of the board's motion (a wet table damps it strongly).
    board_dry_friction : the board's Coulomb friction force; 0 for none.

    Both: ``forcing_amplitude`` is the applied torque on the disk (N m) or the applied
    force on the board (N).
    """

    platform: str = quantity("disk", choices=PLATFORMS)

    radius: float = quantity(0.27, unit="m", bounds=POSITIVE)
    c_phi: float = quantity(1e-5, unit="kg m²/s", bounds=NON_NEGATIVE)
    j0: float = quantity(PAPER_J_MIN, unit="kg m²", bounds=NON_NEGATIVE)
    j_per_metronome: float = quantity(
        (PAPER_J_MAX - PAPER_J_MIN) / PAPER_N_MAX, unit="kg m²", bounds=NON_NEGATIVE
    )
    #: None (the law) or, checked in `__post_init__`, within its bounds or ``math.inf``.
    inertia: float | None = quantity(None, unit="kg m²", bounds=POSITIVE)
    forcing_amplitude: float = quantity(0.0, unit="N m", bounds=NON_NEGATIVE)
    forcing_bpm: float = quantity(0.0, unit="BPM", bounds=NON_NEGATIVE)
    escapement_reaction: bool = True
    disk_dry_friction: float = quantity(0.0, unit="N m", bounds=NON_NEGATIVE)
    board_mass: float = quantity(0.058, unit="kg", bounds=POSITIVE)
    box_mass: float = quantity(0.0705, unit="kg", bounds=NON_NEGATIVE)
    roller_mass: float = quantity(0.0, unit="kg", bounds=NON_NEGATIVE)
    board_damping: float = quantity(0.0, unit="kg/s", bounds=NON_NEGATIVE)
    board_dry_friction: float = quantity(0.0, unit="N", bounds=NON_NEGATIVE)

    def __post_init__(self) -> None:
        if not isinstance(self.platform, str) or self.platform not in PLATFORMS:
            raise ParameterError(
                f"unknown `platform` {self.platform!r}; choose one of {list(PLATFORMS)}."
            )
        # In the order they have always been checked: the first wrong value is named.
        check_quantities(self, "radius", "c_phi", "j0", "j_per_metronome", "disk_dry_friction")
        inertia, bounds = self.inertia, declared(self, "inertia", "bounds")
        if inertia is not None and not (inertia == math.inf or bounds.admits(inertia)):
            raise ParameterError(
                f"`inertia` must {bounds} {declared(self, 'inertia')} (or math.inf for a rigid "
                f"support), got {inertia!r}."
            )
        check_quantities(self, "forcing_amplitude", "forcing_bpm")
        if self.forcing_amplitude > 0 and self.forcing_bpm == 0:
            raise ParameterError(
                f"`forcing_amplitude` = {self.forcing_amplitude!r} "
                f"{declared(self, 'forcing_amplitude')} needs a frequency: set `forcing_bpm` > 0 "
                f"(Ω = π·BPM/60, e.g. the metronomes' BPM for resonance)."
            )
        reaction = self.escapement_reaction
        if not (isinstance(reaction, bool | np.bool_) or reaction in (0, 1)):
            raise ParameterError(
                f"`escapement_reaction` must be true or false (1 or 0), got {reaction!r}."
            )
        object.__setattr__(self, "escapement_reaction", bool(reaction))
        check_quantities(self, *BOARD_FIELDS)
        self._check_other_platform_unset()

    def _check_other_platform_unset(self) -> None:
        """A parameter of the platform not chosen must keep its default: set, it would
        be ignored, and the run would be another model than the one asked for."""
        other = BOARD_FIELDS if self.platform == "disk" else DISK_FIELDS
        for name in other:
            value, default = getattr(self, name), self.__dataclass_fields__[name].default
            if value != default:
                needs = "board" if name in BOARD_FIELDS else "disk"
                raise ParameterError(
                    f"`{name}` = {value!r} is a parameter of the {needs}, but `platform` is "
                    f"{self.platform!r}: set platform={needs}, or leave `{name}` at its "
                    f"default {default!r}."
                )

    @property
    def lever(self) -> float:
        """ℓ, m: how far a pivot moves per unit of the platform's coordinate."""
        return self.radius if self.platform == "disk" else 1.0

    @property
    def damping_parameter(self) -> str:
        """The field that damps this platform viscously: ``c_phi`` or ``board_damping``."""
        return "c_phi" if self.platform == "disk" else "board_damping"

    @property
    def dry_friction_parameter(self) -> str:
        """The field of this platform's Coulomb friction: ``disk_dry_friction`` or
        ``board_dry_friction``."""
        return f"{self.platform}_dry_friction"

    @property
    def inertia_per_metronome(self) -> float:
        """What each metronome's case adds to J_p: ``j_per_metronome`` (kg m²) on the
        disk's law, ``box_mass`` (kg) on the board."""
        return self.j_per_metronome if self.platform == "disk" else self.box_mass

    def own_inertia(self, n: int) -> float:
        """J_p for ``n`` metronomes: the disk's J (`disk_inertia`), or the board's mass
        with the rollers' and the ``n`` cases', kg."""
        if self.platform == "disk":
            return self.disk_inertia(n)
        if n < 1:
            raise ParameterError(f"`n` must be >= 1 metronome, got {n!r}.")
        return self.board_mass + self.roller_mass + n * self.box_mass

    def terms(self, n: int) -> PlatformTerms:
        """The constants the equations of motion read, for ``n`` metronomes."""
        disk = self.platform == "disk"
        return PlatformTerms(
            lever=self.lever,
            own_inertia=self.own_inertia(n),
            damping=getattr(self, self.damping_parameter),
            dry_friction=getattr(self, self.dry_friction_parameter),
            forcing_amplitude=self.forcing_amplitude,
            escapement_reaction=self.escapement_reaction if disk else False,
        )

    def units(self) -> dict[str, str]:
        """Each field's unit as file attributes write it; the applied drive is a force,
        N, on the board."""
        out = units(Platform)
        if self.platform == "board":
            out["forcing_amplitude"] = "N"
        return out

    def chosen_fields(self) -> dict:
        """The fields of this platform (the other platform's are left out)."""
        skip = BOARD_FIELDS if self.platform == "disk" else DISK_FIELDS
        return {k: v for k, v in vars(self).items() if k not in skip}

    def disk_inertia(self, n: int) -> float:
        """J for ``n`` metronomes on the disk, kg m²."""
        if self.inertia is not None:
            return float(self.inertia)
        if n < 1:
            raise ParameterError(f"`n` must be >= 1 metronome, got {n!r}.")
        return self.j0 + n * self.j_per_metronome

    @property
    def rigid(self) -> bool:
        return self.platform == "disk" and self.inertia == math.inf

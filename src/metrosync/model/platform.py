"""The freely rotating disk that carries the metronomes (paper §4–5).

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .quantity import NON_NEGATIVE, POSITIVE, check_quantities, declared, documented, quantity

PAPER_J_MIN = 0.0729
PAPER_J_MAX = 0.25515
PAPER_N_MAX = 7


@documented
@dataclass(frozen=True)
class Platform:
    """Disk parameters, SI units (each declared on its field and listed below).

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
    """

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

    def __post_init__(self) -> None:
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

    def disk_inertia(self, n: int) -> float:
        """J for ``n`` metronomes on the disk, kg m²."""
        if self.inertia is not None:
            return float(self.inertia)
        if n < 1:
            raise ParameterError(f"`n` must be >= 1 metronome, got {n!r}.")
        return self.j0 + n * self.j_per_metronome

    @property
    def rigid(self) -> bool:
        return self.inertia == math.inf

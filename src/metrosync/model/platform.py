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

from ..errors import ParameterError, require_positive

PAPER_J_MIN = 0.0729
PAPER_J_MAX = 0.25515
PAPER_N_MAX = 7


@dataclass(frozen=True)
class Platform:
    """Disk parameters, SI units.

    radius : R, distance of the pivots from the axis, m.
    c_phi : viscous friction of the disk's bearing, kg m²/s.
    j0, j_per_metronome : the law J(N) = j0 + N·j_per_metronome, kg m².
    inertia : if set, a fixed J that ignores the law; ``math.inf`` pins the disk.
    forcing_amplitude : A of the external torque τ(t) = A sin(Ω t) on the disk, N m;
        0 (the default) switches it off.
    forcing_bpm : the forcing's frequency in the metronomes' BPM, Ω = π·BPM/60 rad/s;
        needed (> 0) when ``forcing_amplitude`` is not 0.
    escapement_reaction : whether the escapement's torque reacts on the disk, the
        −Σ𝕄_i term of eq. (metron2a) (True, as the paper writes it). False keeps the
        kicks on the pendulums but takes their reaction off the disk, as if the
        escapement were driven from outside the platform. Accepts 0 or 1.
    disk_dry_friction : the disk's Coulomb friction torque, N m: the largest torque
        that holds the disk at rest, and the torque against a slipping disk; 0 for none.
    """

    radius: float = 0.27
    c_phi: float = 1e-5
    j0: float = PAPER_J_MIN
    j_per_metronome: float = (PAPER_J_MAX - PAPER_J_MIN) / PAPER_N_MAX
    inertia: float | None = None
    forcing_amplitude: float = 0.0
    forcing_bpm: float = 0.0
    escapement_reaction: bool = True
    disk_dry_friction: float = 0.0

    def __post_init__(self) -> None:
        require_positive("radius", self.radius, unit="m")
        require_positive("c_phi", self.c_phi, allow_zero=True, unit="kg m²/s")
        require_positive("j0", self.j0, allow_zero=True, unit="kg m²")
        require_positive("j_per_metronome", self.j_per_metronome, allow_zero=True, unit="kg m²")
        require_positive("disk_dry_friction", self.disk_dry_friction, allow_zero=True, unit="N m")
        if self.inertia is not None and not (self.inertia == math.inf or self.inertia > 0):
            raise ParameterError(
                f"`inertia` must be > 0 kg m² (or math.inf for a rigid support), "
                f"got {self.inertia!r}."
            )
        require_positive("forcing_amplitude", self.forcing_amplitude, allow_zero=True, unit="N m")
        require_positive("forcing_bpm", self.forcing_bpm, allow_zero=True, unit="BPM")
        if self.forcing_amplitude > 0 and self.forcing_bpm == 0:
            raise ParameterError(
                f"`forcing_amplitude` = {self.forcing_amplitude!r} N m needs a frequency: set "
                f"`forcing_bpm` > 0 (Ω = π·BPM/60, e.g. the metronomes' BPM for resonance)."
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

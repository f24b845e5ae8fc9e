"""What the measured and the estimated coupling share: the `Coupling` they return, the
disk's N/D₀(N) scale (`disk_scale`) and the metronome tuned to a marking.

`metrosync.theory.coupling` measures K e^{−iα}; `metrosync.theory.estimate` estimates it
and gives the measurements their first guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import ParameterError
from ..model import ModelParameters, get_preset
from ..model.steady_swing import steady_swing
from ..model.tuning import l2_for_bpm


@dataclass(frozen=True)
class Coupling:
    """K e^{−iα} of the reduced model for ``n`` metronomes at nominal ``bpm``.

    k_cos, k_sin : K cos α and K sin α, rad/s, with their uncertainties (1 σ).
    scale : N/D₀(N) of the disk it was measured on, 1/(kg m²).
    free_bpm : tick rate of a free metronome at the steady swing, BPM.
    """

    bpm: float
    n: int
    k_cos: float
    k_sin: float
    k_cos_err: float
    k_sin_err: float
    method: str
    scale: float
    free_bpm: float

    @property
    def k(self) -> float:
        return math.hypot(self.k_cos, self.k_sin)

    @property
    def alpha(self) -> float:
        """Phase lag α, rad (negative: the locked frequency lies above the free one)."""
        return math.atan2(self.k_sin, self.k_cos)

    @property
    def k_err(self) -> float:
        return math.hypot(self.k_cos * self.k_cos_err, self.k_sin * self.k_sin_err) / self.k

    @property
    def alpha_err(self) -> float:
        return math.hypot(self.k_sin * self.k_cos_err, self.k_cos * self.k_sin_err) / self.k**2

    @property
    def kappa(self) -> float:
        """K/(N/D₀), the disk-independent strength, rad/s · kg m²."""
        return self.k / self.scale

    def for_n(self, n: int | float, params: ModelParameters | str = "default") -> Coupling:
        """The same coupling for ``n`` metronomes (``math.inf`` for the N → ∞ limit)."""
        factor = disk_scale(n, params) / self.scale
        return replace(
            self,
            n=n,
            k_cos=self.k_cos * factor,
            k_sin=self.k_sin * factor,
            k_cos_err=self.k_cos_err * factor,
            k_sin_err=self.k_sin_err * factor,
            scale=self.scale * factor,
        )


def disk_scale(n: int | float, params: ModelParameters | str = "default") -> float:
    """N/D₀(N) with D₀ = J_p(N) + N m ℓ² (J_p the platform's own inertia, ℓ its lever:
    J(N) and R on the disk, the board's mass and 1 m on the board); its N → ∞ limit
    for ``n = math.inf``."""
    params = get_preset(params, warn=False)
    p, mass = params.platform, params.metronome.mass
    if n == math.inf:
        if p.platform == "disk" and p.inertia is not None:
            raise ParameterError(
                "`n` = inf needs the J(N) law, but this platform has a fixed `inertia`; with a "
                "fixed J the coupling per metronome vanishes as N grows. Give a finite `n`."
            )
        return 1.0 / (p.inertia_per_metronome + mass * p.lever**2)
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ParameterError(f"`n` must be a whole number >= 1 of metronomes, got {n!r}.")
    return n / (p.own_inertia(int(n)) + n * mass * p.lever**2)


def tuned_metronome(bpm: float, params: ModelParameters):
    """The metronome of ``params`` tuned to tick at ``bpm``, and its steady swing."""
    design = params.metronome
    metronome = design.with_l2(float(l2_for_bpm(design, bpm, tuning=design.tuning)))
    return metronome, steady_swing(metronome)

"""Named parameter sets (docs/model.md §4 and §6.5).

``boda2013``  exactly as published: M = 6×10⁻⁴ N m s. Its energy-balance amplitude,
              2M/(π c_θ) ≈ 7.6 rad, means the pendulums go over the top; loading it warns.
``default``   the published set with M = 6×10⁻⁵ (the paper's own z-study value), which
              swings at ≈ 0.76 rad like a real metronome.
``pantaleone2002``  two Wittner Super-Mini-Taktell metronomes on a 58 g board on two
              cans (J. Pantaleone, Am. J. Phys. 70, 992 (2002); docs/model.md §9.3):
              each 94 g, ticking 208 a minute at a ±45° swing (his θ₀ = 0.39 rad is
              half the van der Pol amplitude), with his base-motion scale
              x₀ = m r_cm/(M + 2m) ≈ 0.088 cm. The pendulum (w1, w2, l1) is our
              estimate, chosen so that m h = 2.22×10⁻⁴ kg m at 208 BPM (x₀ = 0.090 cm,
              β = x₀ω²/g = 0.0109 against his 0.011); c_θ gives his van der Pol
              relaxation rate μω (μ = 0.010): c_θ = 2 I μ ω; the drive M gives the ±45°
              steady swing; tuned at the steady swing, as a real metronome is marked.
              The cans' mass is neglected and the board undamped, as in his Eq. 2.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

from ..errors import OverturnWarning, ParameterError
from .metronome import MetronomeDesign, balance_amplitude
from .platform import Platform


@dataclass(frozen=True)
class ModelParameters:
    """A metronome design and a platform: every fixed parameter of the model."""

    metronome: MetronomeDesign = field(default_factory=MetronomeDesign)
    platform: Platform = field(default_factory=Platform)
    name: str = "custom"
    description: str = ""

    @property
    def balance_amplitude(self) -> float:
        """Energy-balance amplitude 2M/(π c_θ) of the design, rad (`balance_amplitude`)."""
        return balance_amplitude(self.metronome.drive, self.metronome.c_theta)

    @property
    def overturns(self) -> bool:
        """True when the energy-balance amplitude passes the horizontal (π/2)."""
        return self.balance_amplitude > math.pi / 2

    def on_rigid_support(self) -> ModelParameters:
        """The same metronomes on a support that does not move (a pinned disk, whatever
        the platform was): each swings alone."""
        return replace(self, platform=Platform(inertia=math.inf), name=f"{self.name}+rigid")

    def with_changes(self, **changes) -> ModelParameters:
        """Copy with fields of the metronome design or the platform replaced by name.

        ``with_changes(drive=1e-4, c_phi=0)`` routes each name to where it lives.
        """
        design_fields = MetronomeDesign.__dataclass_fields__
        platform_fields = Platform.__dataclass_fields__
        design_changes = {k: v for k, v in changes.items() if k in design_fields}
        platform_changes = {k: v for k, v in changes.items() if k in platform_fields}
        unknown = set(changes) - set(design_changes) - set(platform_changes)
        if unknown:
            valid = sorted(set(design_fields) | set(platform_fields))
            raise ParameterError(
                f"unknown model parameter(s) {sorted(unknown)}; valid names: {valid}."
            )
        return replace(
            self,
            metronome=replace(self.metronome, **design_changes),
            platform=replace(self.platform, **platform_changes),
            name=self.name if not changes else f"{self.name}+changes",
        )

    def as_dict(self) -> dict[str, float | str]:
        """Flat dict of every parameter, for file attributes."""
        out: dict[str, float | str] = {"preset": self.name}
        for key, value in vars(self.metronome).items():
            out[key] = list(value) if isinstance(value, tuple) else value
        for key, value in self.platform.chosen_fields().items():
            out[key] = "law J0+N*j" if value is None else value
        # NetCDF has no booleans: a switch is stored as 0 or 1.
        return {k: int(v) if isinstance(v, bool) else v for k, v in out.items()}


PRESETS: dict[str, ModelParameters] = {
    "default": ModelParameters(
        metronome=MetronomeDesign(drive=6e-5),
        name="default",
        description="published parameters with M = 6e-5 N m s (steady swing ≈ 0.76 rad)",
    ),
    "boda2013": ModelParameters(
        metronome=MetronomeDesign(drive=6e-4),
        name="boda2013",
        description="exactly as published, M = 6e-4 N m s (overturns: amplitude ≈ 7.6 rad)",
    ),
    "pantaleone2002": ModelParameters(
        metronome=MetronomeDesign(
            w1=0.0195,
            w2=0.004,
            l1=0.020,
            c_theta=3.84e-6,
            drive=4.71e-6,
            l2_bounds=(0.0, 0.08),
            tuning="steady-swing",
        ),
        platform=Platform(
            platform="board", board_mass=0.058, box_mass=0.0705, roller_mass=0.0, board_damping=0.0
        ),
        name="pantaleone2002",
        description="Pantaleone's two metronomes on a 58 g board on cans, 208 BPM, ±45° swing",
    ),
}


def get_preset(name: str | ModelParameters, *, warn: bool = True) -> ModelParameters:
    """Look up a preset by name; warns with `OverturnWarning` if its pendulums overturn."""
    if isinstance(name, ModelParameters):
        params = name
    else:
        try:
            params = PRESETS[name]
        except KeyError:
            raise ParameterError(
                f"unknown preset {name!r}; choose one of {sorted(PRESETS)}."
            ) from None
    if warn and params.overturns:
        warnings.warn(
            f"preset {params.name!r}: the energy-balance amplitude 2M/(pi c_theta) = "
            f"{params.balance_amplitude:.2f} rad exceeds pi/2, so the pendulums overturn "
            f"(swing past the horizontal). Runs that do are flagged in `status`.",
            OverturnWarning,
            stacklevel=2,
        )
    return params

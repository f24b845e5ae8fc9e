"""Named parameter sets (docs/model.md §4 and §6.5).

``boda2013``  exactly as published: M = 6×10⁻⁴ N m s. Its energy-balance amplitude,
              2M/(π c_θ) ≈ 7.6 rad, means the pendulums go over the top; loading it warns.
``default``   the published set with M = 6×10⁻⁵ (the paper's own z-study value), which
              swings at ≈ 0.76 rad like a real metronome.
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
        for key, value in vars(self.platform).items():
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

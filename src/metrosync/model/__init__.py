"""Model parameters: metronomes, the platform, and named presets."""

from .metronome import (
    Metronome,
    MetronomeDesign,
    bpm_to_omega,
    omega_to_bpm,
    steady_amplitude,
)
from .platform import Platform
from .presets import PRESETS, ModelParameters, get_preset

__all__ = [
    "PRESETS",
    "Metronome",
    "MetronomeDesign",
    "ModelParameters",
    "Platform",
    "bpm_to_omega",
    "get_preset",
    "omega_to_bpm",
    "steady_amplitude",
]

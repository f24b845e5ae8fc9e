"""Model parameters: metronomes, the platform, and named presets."""

from .metronome import (
    TUNINGS,
    Metronome,
    MetronomeDesign,
    bpm_to_omega,
    centre_of_mass,
    natural_omega,
    omega_to_bpm,
    pendulum_inertia,
    pivot_moment,
    steady_amplitude,
)
from .platform import Platform
from .presets import PRESETS, ModelParameters, get_preset
from .system import SystemArrays, system_arrays

__all__ = [
    "PRESETS",
    "TUNINGS",
    "Metronome",
    "MetronomeDesign",
    "ModelParameters",
    "Platform",
    "SystemArrays",
    "bpm_to_omega",
    "centre_of_mass",
    "get_preset",
    "natural_omega",
    "omega_to_bpm",
    "pendulum_inertia",
    "pivot_moment",
    "steady_amplitude",
    "system_arrays",
]

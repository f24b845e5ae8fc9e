"""Model parameters: metronomes, the platform, named presets, and the tunings (`tuning`,
with the single-pendulum mechanics of the steady swing in `steady_swing`)."""

from .metronome import (
    Metronome,
    MetronomeDesign,
    balance_amplitude,
    bpm_to_omega,
    centre_of_mass,
    natural_omega,
    omega_to_bpm,
    pendulum_inertia,
    pivot_moment,
)
from .platform import Platform
from .presets import PRESETS, ModelParameters, get_preset
from .system import SystemArrays, system_arrays
from .tuning import TUNINGS, l2_for_bpm

__all__ = [
    "PRESETS",
    "TUNINGS",
    "Metronome",
    "MetronomeDesign",
    "ModelParameters",
    "Platform",
    "SystemArrays",
    "balance_amplitude",
    "bpm_to_omega",
    "centre_of_mass",
    "get_preset",
    "l2_for_bpm",
    "natural_omega",
    "omega_to_bpm",
    "pendulum_inertia",
    "pivot_moment",
    "system_arrays",
]

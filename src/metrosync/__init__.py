"""metrosync: spontaneous synchronization of metronomes on a freely rotating disk.

A model, integrators, observables and analysis tools for the system of Boda, Néda,
Tyukodi and Tunyagi, "The rhythm of coupled metronomes" (2013).
"""

__version__ = "0.1.0"

from .ensemble import Ensemble, build_ensemble  # noqa: E402
from .errors import MetrosyncError, OverturnWarning, ParameterError  # noqa: E402
from .model import (  # noqa: E402
    PRESETS,
    Metronome,
    MetronomeDesign,
    ModelParameters,
    Platform,
    bpm_to_omega,
    get_preset,
    omega_to_bpm,
)
from .simulate import simulate  # noqa: E402

__all__ = [
    "PRESETS",
    "Ensemble",
    "Metronome",
    "MetronomeDesign",
    "MetrosyncError",
    "ModelParameters",
    "OverturnWarning",
    "ParameterError",
    "Platform",
    "__version__",
    "bpm_to_omega",
    "build_ensemble",
    "get_preset",
    "omega_to_bpm",
    "simulate",
]

from .reproduce import reproduce  # noqa: E402

__all__ += ["reproduce"]

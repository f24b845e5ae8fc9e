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
    "animate",
    "plot_run",
    "write_page",
    "write_wav",
]

from .lightgate import analyze  # noqa: E402

__all__ += ["analyze"]
from .sweeps import sweep  # noqa: E402

__all__ += ["sweep"]

#: Names served lazily from `metrosync.show`, so that importing metrosync does not
#: import matplotlib.
_SHOW = ("animate", "plot_run", "write_page", "write_wav")


def __getattr__(name: str):
    if name in _SHOW:
        from . import show

        return getattr(show, name)
    raise AttributeError(f"module 'metrosync' has no attribute {name!r}")

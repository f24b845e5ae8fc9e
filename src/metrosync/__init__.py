"""metrosync: spontaneous synchronization of metronomes on a freely rotating disk.

A model, integrators, observables and analysis tools for the system of Boda, Néda,
Tyukodi and Tunyagi, "The rhythm of coupled metronomes" (2013).

One entry point per job: `simulate` (an ensemble), `analyze` (light-gate logs),
`analyze_audio` (a sound recording of metronomes), `track` (a video of them),
`sweep` (parameter grids), `reproduce` (the paper's studies), `animate`, `write_wav`,
`write_page`, `plot_run` (seeing and hearing a run), `write_playground` (the model
live in a browser), and `reduced_theory`, `simulate_reduced` (the phase-model
reduction, `metrosync.theory`). Those that need matplotlib, dask, an audio or a video
library are imported on first use, so that ``import metrosync`` stays quick.
"""

from ._version import __version__
from .ensemble import Ensemble, build_ensemble  # noqa: E402
from .errors import MetrosyncError, OverturnWarning, ParameterError  # noqa: E402
from .lightgate import analyze  # noqa: E402
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

#: Names served on first use from the modules that need matplotlib, dask, soundfile or av.
_LAZY = {
    "animate": "show",
    "plot_run": "show",
    "write_page": "show",
    "write_playground": "show",
    "write_wav": "show",
    "sweep": "sweeps",
    "reproduce": "paper",
    "analyze_audio": "audio",
    "track": "video",
    "reduced_theory": "theory",
    "simulate_reduced": "theory",
}

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
    "analyze",
    "bpm_to_omega",
    "build_ensemble",
    "get_preset",
    "omega_to_bpm",
    "simulate",
    *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'metrosync' has no attribute {name!r}")

"""metrosync: spontaneous synchronization of metronomes on a freely rotating disk.

A model, integrators, observables and analysis tools for the system of Boda, Néda,
Tyukodi and Tunyagi, "The rhythm of coupled metronomes" (2013).

One entry point per job: `simulate` (an ensemble), `analyze` (light-gate logs),
`analyze_audio` (a sound recording of metronomes), `analyze_angles` (an encoder's or
Tracker's table of a pendulum's angle), `track` (a video of them),
`sweep` (parameter grids), `reproduce` (the paper's studies), `animate`, `write_wav`,
`write_page`, `plot_run` (seeing and hearing a run), `write_playground` (the model
live in a browser), and `reduced_theory`, `simulate_reduced` (the phase-model
reduction, `metrosync.theory`). Each is imported on first use, so that
``import metrosync`` is quick and loads no numerical library: the command line sets
up its Ctrl-C handling before those load.
"""

import importlib
import sys
import types

from ._kernel_cache_dir import use_user_cache

use_user_cache()  # before numba is imported: the compiled kernels outlive a reinstall

from ._version import __version__  # noqa: E402

#: Every public name, and the module that defines it: imported on first use, so that
#: ``import metrosync`` (and the ``metrosync`` command, until it has set up its Ctrl-C
#: handling) loads no numerical library.
_LAZY = {
    "Ensemble": "ensemble",
    "build_ensemble": "ensemble",
    "MetrosyncError": "errors",
    "OverturnWarning": "errors",
    "ParameterError": "errors",
    "analyze": "lightgate",
    "PRESETS": "model",
    "Metronome": "model",
    "MetronomeDesign": "model",
    "ModelParameters": "model",
    "Platform": "model",
    "bpm_to_omega": "model",
    "get_preset": "model",
    "omega_to_bpm": "model",
    "simulate": "simulate",
    "animate": "show",
    "plot_run": "show",
    "write_page": "show",
    "write_playground": "show",
    "write_wav": "show",
    "sweep": "sweeps",
    "reproduce": "paper",
    "analyze_audio": "audio",
    "analyze_angles": "angles",
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
    "animate",
    "plot_run",
    "write_page",
    "write_playground",
    "write_wav",
    "sweep",
    "reproduce",
    "analyze_audio",
    "analyze_angles",
    "track",
    "reduced_theory",
    "simulate_reduced",
]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    try:  # a subpackage used as an attribute, as when every module was loaded up front
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as error:
        if error.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module 'metrosync' has no attribute {name!r}")


class _Package(types.ModuleType):
    """Keeps `metrosync.simulate` the function once the module of the same name is
    imported (the import system then sets the package's attribute to the module)."""

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and _LAZY.get(name) == name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

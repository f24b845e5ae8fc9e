"""Reproduce the paper's simulation figures and claims, with an honest report.

``runner``      the engine: runs a study's `metrosync.simulate` calls on the sweep
                machinery (`metrosync.sweeps`: one point store, resumable, any
                executor); it knows no kind of study, only what `runner.Study` asks
``studies``     the kinds of study, declared as data (grids, statistics per mode),
                each with its points, labels and assembly, and the paper's figures
``sigma_map``   the σ map;  ``readings``, ``claims_map``: the claims map
``catalogue``   which studies the paper has (`STUDIES`)
``assemble``    joins a study's stored points into its dataset
``figures``     one plotting function per figure (PNG + PDF)
``claims``      verdicts on the paper's claims from the study data
``consistency`` the parameter-consistency table
``experiment``  Fig. 9 from light-gate logs (optional)
``report``      REPORT.md
``pipeline``    `reproduce`, the entry point tying them together
"""

from .catalogue import STUDIES
from .studies import paper_sigma_to_bpm

__all__ = ["STUDIES", "Reproduction", "paper_sigma_to_bpm", "reproduce"]


def __getattr__(name: str):
    # The pipeline pulls in the simulator, calibration and scipy; the CLI's parser only
    # needs the study names, so it is loaded on first use.
    if name in ("Reproduction", "reproduce"):
        from . import pipeline

        return getattr(pipeline, name)
    raise AttributeError(f"module 'metrosync.paper' has no attribute {name!r}")

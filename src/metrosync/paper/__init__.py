"""Reproduce the paper's simulation figures and claims, with an honest report.

``studies``     the studies, declared as data (grids, statistics per mode)
``runner``      runs a study's `metrosync.simulate` calls on the sweep machinery
                (`metrosync.sweeps`: one point store, resumable, any executor)
``assemble``    joins a study's stored points into its dataset
``figures``     one plotting function per figure (PNG + PDF)
``claims``      verdicts on the paper's claims from the study data
``consistency`` the parameter-consistency table
``experiment``  Fig. 9 from light-gate logs (optional)
``report``      REPORT.md
``pipeline``    `reproduce`, the entry point tying them together
"""

from .studies import STUDIES, paper_sigma_to_bpm

__all__ = ["STUDIES", "Reproduction", "paper_sigma_to_bpm", "reproduce"]


def __getattr__(name: str):
    # The pipeline pulls in the simulator, calibration and scipy; the CLI's parser only
    # needs the study names, so it is loaded on first use.
    if name in ("Reproduction", "reproduce"):
        from . import pipeline

        return getattr(pipeline, name)
    raise AttributeError(f"module 'metrosync.paper' has no attribute {name!r}")

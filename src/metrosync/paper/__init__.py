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

__all__ = ["STUDIES", "Reproduction", "paper_sigma_to_bpm", "reproduce"]

# Each of these pulls in scipy, xarray or the simulator; the command line's parser, which
# every command builds, needs only `names`: each is loaded on first use (PEP 562).
_HOMES = {"STUDIES": "catalogue", "paper_sigma_to_bpm": "studies",
          "Reproduction": "pipeline", "reproduce": "pipeline"}  # fmt: skip


def __getattr__(name: str):
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(f".{_HOMES[name]}", __name__), name)
    raise AttributeError(f"module 'metrosync.paper' has no attribute {name!r}")

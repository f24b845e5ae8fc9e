"""A point: one `metrosync.simulate` call, what is kept of it, and its content key.

Contract: `make_point(kwargs, keep=...)` returns a `PointSpec` whose ``key`` is a
SHA-256 over everything that decides the stored result:

- the `simulate` keyword arguments, with ``preset`` and ``changes`` replaced by the
  fully resolved model parameters (every field of the metronome design and of the
  platform), so a preset whose values change gives new keys, and two names for the
  same values give the same key;
- what is kept of the result (``keep``, see `metrosync.sweeps.keep`);
- the package version;
- a digest of the sources that compute the result (`source_digest`): every module of
  the ``integrators``, ``model``, ``observables`` and ``simulation`` packages, found by
  walking the folders (a renamed or added module is covered), plus ``equations.py``,
  ``ensemble.py``, ``groups.py``, ``simulate.py`` and the reductions in ``sweeps/keep.py``.

A stored point is therefore reused only when recomputing it would give the same file.
Every entry point that stores points (`metrosync.sweep`, `metrosync.reproduce`) builds
its points here, so there is one key for all of them.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._version import __version__
from ..errors import ParameterError
from ..model import get_preset

#: What a point keeps of its `simulate` result (see `metrosync.sweeps.keep`).
KEEPS = ("r_eq", "r_eq+r", "run_mean_r", "z")
#: Packages (folders) and modules, relative to the metrosync package, whose source
#: decides a point's result.
SOURCE_PACKAGES = ("integrators", "model", "observables", "simulation")
SOURCE_MODULES = ("equations.py", "ensemble.py", "groups.py", "simulate.py", "sweeps/keep.py")


@dataclass(frozen=True)
class PointSpec:
    """One point: where it sits, what it runs and keeps, and its content key.

    index : position along each axis of its grid.   coords : swept name -> value.
    kwargs : the complete keyword arguments of `metrosync.simulate`.
    keep : what is stored of the result, one of `KEEPS`.
    key : content hash (hex).   work : oscillator-steps (runs × N × steps).
    """

    index: tuple[int, ...]
    coords: dict[str, Any]
    kwargs: dict[str, Any]
    keep: str
    key: str
    work: int

    @property
    def keep_r(self) -> bool:
        """True when r(t) of every run is kept."""
        return self.keep == "r_eq+r"


def make_point(
    kwargs: Mapping[str, Any],
    *,
    keep: str = "r_eq",
    index: tuple[int, ...] = (),
    coords: Mapping[str, Any] | None = None,
) -> PointSpec:
    """The `PointSpec` of one `simulate` call with keyword arguments ``kwargs``."""
    if keep not in KEEPS:
        raise ParameterError(f"unknown `keep` {keep!r}; choose one of {list(KEEPS)}.")
    kwargs = dict(kwargs)
    steps = round(kwargs["duration"] / kwargs.get("dt", 0.01))
    groups = kwargs.get("groups")  # (n, bpm[, sigma]) each, in place of n
    n = sum(int(g[0]) for g in groups) if groups else int(kwargs["n"])
    work = int(kwargs.get("runs", 1)) * n * int(steps)
    return PointSpec(tuple(index), dict(coords or {}), kwargs, keep, point_key(kwargs, keep), work)


def point_key(kwargs: Mapping[str, Any], keep: str) -> str:
    """The content key of a point (see the module docstring)."""
    simulate_args = {k: v for k, v in kwargs.items() if k not in ("preset", "changes", "progress")}
    key_input = {
        "simulate": simulate_args,
        "model": resolved_model(kwargs),
        "keep": keep,
        "metrosync_version": __version__,
        "sources": source_digest(),
    }
    return hashlib.sha256(canonical_json(key_input).encode()).hexdigest()


def resolved_model(kwargs: Mapping[str, Any]) -> dict[str, Any]:
    """Every model parameter the point runs with, by name (the preset's name left out)."""
    params = get_preset(kwargs.get("preset", "default"), warn=False)
    changes = kwargs.get("changes") or {}
    if changes:
        params = params.with_changes(**changes)
    resolved = params.as_dict()
    resolved.pop("preset")  # a name; the values are what count
    return resolved


def source_digest(root: str | Path | None = None) -> str:
    """SHA-256 of the sources that compute a point (paths and contents, sorted).

    ``root`` : the metrosync package folder (default: this installation's). A module
    listed in `SOURCE_MODULES` that is missing is an error, never silently skipped.
    """
    return _installed_digest() if root is None else _digest(Path(root))


@functools.cache
def _installed_digest() -> str:
    # Once per process: the sources do not change under a running computation.
    return _digest(Path(__file__).resolve().parent.parent)


def _digest(root: Path) -> str:
    files = [root / name for name in SOURCE_MODULES]
    for package in SOURCE_PACKAGES:
        if not (root / package).is_dir():
            raise FileNotFoundError(f"metrosync source package {root / package} is missing")
        files += (root / package).rglob("*.py")
    digest = hashlib.sha256()
    for path in sorted(set(files)):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def canonical_json(obj: Any) -> str:
    """JSON with sorted keys; arrays and dataclasses written out in full."""
    return json.dumps(obj, sort_keys=True, default=_plain, allow_nan=True)


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()  # repr() would elide the middle of a large array
    if isinstance(value, np.generic):
        return value.item()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"type": type(value).__name__, **dataclasses.asdict(value)}
    return repr(value)

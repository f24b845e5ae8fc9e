"""Point keys: resolved parameters (not preset names), version and simulation sources."""

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

import metrosync
from metrosync import ParameterError
from metrosync.model import presets as presets_module
from metrosync.sweeps import points as points_module
from metrosync.sweeps.points import (
    SOURCE_MODULES,
    SOURCE_PACKAGES,
    make_point,
    point_key,
    source_digest,
)

KWARGS = {"n": 3, "bpm": 190.0, "runs": 2, "duration": 5.0, "seed": 1}


def test_key_follows_the_values_of_a_preset_not_its_name(monkeypatch):
    before = point_key({**KWARGS, "preset": "default"}, "r_eq")
    # The same values under another name (or spelled as changes) give the same key.
    renamed = dataclasses.replace(presets_module.PRESETS["default"], name="other")
    monkeypatch.setitem(presets_module.PRESETS, "other", renamed)
    assert point_key({**KWARGS, "preset": "other"}, "r_eq") == before
    assert point_key({**KWARGS, "changes": {"drive": 6e-5}}, "r_eq") == before
    # A preset whose meaning changes gives a new key under the same name.
    changed = presets_module.PRESETS["default"].with_changes(c_phi=2e-5)
    monkeypatch.setitem(presets_module.PRESETS, "default", changed)
    assert point_key({**KWARGS, "preset": "default"}, "r_eq") != before


def test_key_covers_what_is_kept_the_version_and_the_sources(monkeypatch):
    base = point_key(KWARGS, "r_eq")
    assert point_key(KWARGS, "run_mean_r") != base
    monkeypatch.setattr(points_module, "__version__", "999.0")
    assert point_key(KWARGS, "r_eq") != base
    monkeypatch.undo()
    monkeypatch.setattr(points_module, "source_digest", lambda root=None: "0" * 64)
    assert point_key(KWARGS, "r_eq") != base


def test_large_arrays_are_hashed_in_full():
    theta0 = np.zeros((3000, 2))
    other = theta0.copy()
    other[1500, 1] = 1e-9  # repr() would elide the middle of the array
    a = point_key({**KWARGS, "theta0": theta0}, "z")
    assert a != point_key({**KWARGS, "theta0": other}, "z")


def copy_sources(to: Path) -> Path:
    root = Path(metrosync.__file__).parent
    for package in SOURCE_PACKAGES:
        shutil.copytree(root / package, to / package, ignore=shutil.ignore_patterns("__pycache__"))
    for module in SOURCE_MODULES:
        (to / module).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(root / module, to / module)
    return to


def test_source_digest_covers_every_module_of_the_packages(tmp_path):
    root = copy_sources(tmp_path / "metrosync")
    base = source_digest(root)
    assert base == source_digest(root) == source_digest()  # a copy hashes like the original
    kernel = next((root / "integrators").glob("kernel_*.py"))
    kernel.write_text(kernel.read_text() + "\n# changed\n")
    edited = source_digest(root)
    assert edited != base
    kernel.rename(kernel.with_name("renamed_kernel.py"))  # a renamed module stays covered
    assert source_digest(root) not in (base, edited)
    (root / "model" / "new_part.py").write_text("X = 1\n")  # so does a new one
    with_new = source_digest(root)
    (root / "equations.py").write_text("")
    assert len({base, edited, with_new, source_digest(root)}) == 4
    shutil.rmtree(root / "observables")
    with pytest.raises(FileNotFoundError, match="observables"):
        source_digest(root)


def test_work_and_unknown_keep():
    point = make_point(KWARGS)
    assert point.work == 2 * 3 * 500 and point.keep == "r_eq" and not point.keep_r
    with pytest.raises(ParameterError, match="`keep`"):
        make_point(KWARGS, keep="everything")

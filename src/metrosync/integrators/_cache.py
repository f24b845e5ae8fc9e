"""Guard numba's on-disk compile cache: a damaged or stale file is deleted (and the
kernel recompiled), never loaded.

numba invalidates a cached function only when its own source file changes, not when
a function it inlines from another file does (`_physics`, `_kernel_parts`,
`trig.sincos`), nor when a global it froze at compile time changes (the bits of
`metrosync.status`). A stamp holding the hash of every module of this package, and of
the modules outside it that the kernels depend on (`STAMPED_OUTSIDE`), sits beside
the cache; when it does not match, every cached function of this package is removed.

numba raises on a truncated or corrupt cache file instead of recompiling. Before the
first kernel call, `heal_compile_cache` reads each of this package's cache files the
way numba does (an index: a pickled version, then a pickled payload; a data file: one
pickle) and removes the ones that fail, together with their index.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from pathlib import Path

import numba

_checked = False
STAMP_NAME = "metrosync-kernels.stamp"
HERE = Path(__file__).resolve().parent
#: Modules outside this package whose source the compiled kernels depend on: the
#: status bits they freeze, and the system constants their argument list is made of
#: (`SystemArrays`, in model/system.py, re-exported by equations.py).
STAMPED_OUTSIDE = ("status.py", "equations.py", "model/system.py")


def stamped_sources() -> list[Path]:
    """Every source file the stamp covers."""
    return sorted(HERE.glob("*.py")) + [HERE.parent / name for name in STAMPED_OUTSIDE]


def source_stamp() -> str:
    digest = hashlib.sha256()
    for path in stamped_sources():
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def cache_dirs() -> list[Path]:
    dirs = [HERE / "__pycache__"]
    override = numba.config.CACHE_DIR or os.environ.get("NUMBA_CACHE_DIR")
    if override:
        dirs.append(Path(override))
    for folder in dirs:  # so that the stamp is written before numba's first file
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            pass
    return [d for d in dirs if d.is_dir()]


def _readable(path: Path) -> bool:
    try:
        with open(path, "rb") as f:
            if path.suffix == ".nbi":
                pickle.load(f)
                pickle.loads(f.read())
            else:
                pickle.loads(f.read())
    except Exception:  # any failure to read means numba would fail too
        return False
    return True


def heal_compile_cache() -> list[Path]:
    """Delete unreadable cache files of this package's kernels; return what was removed."""
    global _checked
    if _checked:
        return []
    _checked = True
    removed = []
    stamp = source_stamp()
    for folder in cache_dirs():
        stamp_file = folder / STAMP_NAME
        stale = not stamp_file.exists() or stamp_file.read_text() != stamp
        for path in folder.rglob("*.nb[ic]"):
            if not _ours(path):
                continue
            if stale:
                path.unlink(missing_ok=True)
                removed.append(path)
            elif not _readable(path):
                index = path if path.suffix == ".nbi" else _index_of(path)
                for victim in {path, index}:
                    if victim is not None and victim.exists():
                        victim.unlink()
                        removed.append(victim)
        try:
            stamp_file.write_text(stamp)
        except OSError:  # a read-only install: numba cannot cache there either
            pass
    return removed


def _ours(path: Path) -> bool:
    # numba names the folder after the source folder ("integrators_<hash>" under
    # NUMBA_CACHE_DIR) and each file after the module and function: any module of
    # this package may hold compiled functions, today or after a rename.
    in_our_folder = path.parent.name == "__pycache__" or path.parent.name.startswith("integrators")
    return in_our_folder and path.name.startswith(_our_prefixes())


def _our_prefixes() -> tuple[str, ...]:
    return tuple(path.stem + "." for path in HERE.glob("*.py"))


def _index_of(data_file: Path) -> Path | None:
    # name-lineno.pyXY.K.nbc belongs to name-lineno.pyXY.nbi
    stem = data_file.name.rsplit(".", 2)[0]
    candidate = data_file.with_name(stem + ".nbi")
    return candidate if candidate.exists() else None

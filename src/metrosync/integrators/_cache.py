"""Where numba keeps the compiled kernels, what compiling them costs, and a guard
that never lets a damaged or stale cache file be loaded.

Place. The kernels are compiled on first use (tens of seconds each) and kept on disk.
numba's default place is the package's own ``__pycache__``, which a reinstall
deletes; `use_user_cache` (called when metrosync is imported) points numba at
``$XDG_CACHE_HOME/metrosync/numba`` (``~/.cache/metrosync/numba``) instead, unless
``NUMBA_CACHE_DIR`` is set already, which is then honoured. numba files each source
folder's functions under a subfolder named after that folder's path
(`kernel_cache_dir`), so installs in several environments do not meet.

Cost. `compile_kernel` compiles a kernel for the arguments it is about to get,
before it runs, and says so on stderr, once, when the cache holds nothing for it
("compiling kernels, once: about N s"); the seconds spent are added to
`compile_seconds`, which timings subtract so that throughputs (a sweep point's
``compute_seconds``, the printed oscillator-steps/s, REPORT.md's ``--full``
estimate) measure the simulation, not its first compilation.

Guard. numba invalidates a cached function only when its own source file changes,
not when a function it inlines from another file does (`_physics`, `_kernel_parts`,
`trig.sincos`), nor when a global it froze at compile time changes (the bits of
`metrosync.status`). A stamp holding the hash of every module of this package, and
of the modules outside it that the kernels depend on (`STAMPED_OUTSIDE`), sits in the
cache folder; when it does not match, every cached function of this package is
removed. numba raises on a truncated or corrupt cache file instead of recompiling.
Before the first kernel call, `heal_compile_cache` reads each of this package's
cache files the way numba does (an index: a pickled version, then a pickled payload;
a data file: one pickle) and removes the ones that fail, together with their index.
"""

from __future__ import annotations

import hashlib
import pickle
import sys
import time
from pathlib import Path

from .._kernel_cache_dir import use_user_cache, user_cache_dir  # noqa: F401  (re-exported)

_checked = False
STAMP_NAME = "metrosync-kernels.stamp"
HERE = Path(__file__).resolve().parent
#: Modules outside this package whose source the compiled kernels depend on: the
#: status bits they freeze, and the system constants their argument list is made of
#: (`SystemArrays`, in model/system.py, re-exported by equations.py).
STAMPED_OUTSIDE = ("status.py", "equations.py", "model/system.py")
#: Seconds to compile each kernel (with and without trajectories it has one
#: signature), by `kernel_name`, measured with an empty cache on the 2-core x86-64
#: development machine (numba 0.68.1, 2026-11-25).
COMPILE_SECONDS = {
    "verlet.advance_runs": 20.0,
    "verlet.advance_metronomes": 12.0,
    "located.advance_runs": 26.0,
    "located.advance_metronomes": 17.0,
    "reduced._advance_runs": 6.0,
    "reduced._advance_serial": 3.0,
    "reduced._advance_threads": 3.0,
}
#: Seconds spent compiling kernels in this process (loading them from the cache
#: included); timings of simulation work subtract what accrued meanwhile.
_compile_seconds = 0.0


def compile_seconds() -> float:
    """Seconds this process has spent compiling kernels so far (loading them from the
    cache is not counted: on a loaded machine it can take seconds, and a summary would
    call that compiling)."""
    return _compile_seconds


def stamped_sources() -> list[Path]:
    """Every source file the stamp covers."""
    return sorted(HERE.glob("*.py")) + [HERE.parent / name for name in STAMPED_OUTSIDE]


def source_stamp() -> str:
    digest = hashlib.sha256()
    for path in stamped_sources():
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def _cache_folder(source: Path) -> Path:
    """The folder numba caches the compiled functions of source file ``source`` in."""
    import numba
    from numba.core.caching import _CacheLocator

    if not numba.config.CACHE_DIR:
        return source.parent / "__pycache__"
    # numba's own naming of a source folder's place under NUMBA_CACHE_DIR
    return Path(numba.config.CACHE_DIR) / _CacheLocator.get_suitable_cache_subpath(str(source))


def kernel_cache_dir() -> Path:
    """The folder numba keeps this package's compiled kernels in."""
    return _cache_folder(HERE / "verlet.py")


def cache_dirs() -> list[Path]:
    """The folders to guard: this package's kernel folder, created if missing so that
    the stamp is written before numba's first file."""
    folder = kernel_cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        pass
    return [folder] if folder.is_dir() else []


def _folder_of(function) -> Path:
    """The folder numba caches ``function`` (a dispatcher) in."""
    return _cache_folder(Path(function.py_func.__code__.co_filename).resolve())


def kernel_name(function) -> str:
    """``module.function``, as numba begins the names of its cache files."""
    return f"{function.py_func.__module__.rsplit('.', 1)[-1]}.{function.py_func.__qualname__}"


def is_cached(function) -> bool:
    """Whether the cache holds a compiled ``function`` (a dispatcher) for some arguments."""
    prefix = kernel_name(function) + "-"
    return any(path.name.startswith(prefix) for path in _folder_of(function).glob("*.nbi"))


def compile_kernel(function, *args) -> None:
    """Compile ``function`` (a numba dispatcher) for ``args`` unless done in this process
    already: announced on stderr when the cache holds nothing for it, and timed into
    `compile_seconds`."""
    global _compile_seconds
    signature = tuple(function.typeof_pyval(arg) for arg in args)
    if signature in function.overloads:
        return
    cached = is_cached(function)
    if not cached:
        seconds = COMPILE_SECONDS.get(kernel_name(function), 10.0)
        print(
            f"metrosync: compiling kernels, once: about {seconds:.0f} s "
            f"(kept in {_folder_of(function).parent} for later runs)",
            file=sys.stderr,
            flush=True,
        )
    started = time.perf_counter()
    try:
        function.compile(signature)
    finally:
        if not cached:
            _compile_seconds += time.perf_counter() - started


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

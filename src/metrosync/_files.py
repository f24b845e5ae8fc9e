"""Output files that appear whole or not at all.

Contract: every file metrosync writes (NetCDF datasets, figures, light-gate logs,
audio, pages, animations) goes through `atomic_path`: it is written to a hidden
temporary file in the target's directory, then moved into place with `os.replace`,
which is atomic within one file system. An error or a crash while writing leaves
whatever was at the path before untouched, and the temporary file is removed on
any error, so a path never holds half a result. Missing parent directories are
created.

The temporary name is hidden and ends in ``.partial`` (``.run.nc.<hex>.partial``), so
that no glob for the real files (``*.nc``) ever picks up one in flight. Writers that
pick the format from the file name (Pillow, ffmpeg) ask for ``keep_suffix=True``.

Inside `recording_writes`, every path put in place is also noted, so that a command
stopped by Ctrl-C can say exactly which files it kept.
"""

from __future__ import annotations

import contextlib
import os
import uuid
from collections.abc import Iterator
from pathlib import Path

_written: list[Path] | None = None


@contextlib.contextmanager
def recording_writes() -> Iterator[list[Path]]:
    """Yield a list that collects the path of every file written completely inside."""
    global _written
    outer, _written = _written, []
    try:
        yield _written
    finally:
        _written = outer


@contextlib.contextmanager
def atomic_path(path: str | Path, *, keep_suffix: bool = False) -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces ``path``.

    keep_suffix : end the temporary name in ``path``'s suffix (``...partial.gif``).

    Examples
    --------
    >>> with atomic_path("out.txt") as tmp:  # doctest: +SKIP
    ...     tmp.write_text("all or nothing")
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    suffix = path.suffix if keep_suffix else ""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:12]}.partial{suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
        if _written is not None:
            _written.append(path)
    finally:
        tmp.unlink(missing_ok=True)


def write_netcdf(ds, path: str | Path) -> Path:
    """Write an `xarray.Dataset` to NetCDF-4 (h5netcdf) atomically; returns the path."""
    path = Path(path)
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return path


def write_text(text: str, path: str | Path) -> Path:
    """Write UTF-8 text atomically; returns the path."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def save_figure(fig, path: str | Path, *, dpi: float = 120) -> Path:
    """Save a matplotlib figure atomically, in the format its suffix names.

    A path without a suffix gets matplotlib's default format (``savefig.format``).
    """
    import matplotlib

    path = Path(path)
    fmt = path.suffix[1:].lower() or matplotlib.rcParams["savefig.format"]
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=fmt)
    return path

"""Input and output files at the command line's edge.

Contract: a subcommand checks every output path with `check_output` *before* it
starts working, so that a long simulation is never lost to a typo in ``--plot`` or
an unwritable directory; it reads datasets with `read_dataset`, which turns a
missing or unreadable file into a `ParameterError` naming the file; and it writes
its results with `write_outputs` (atomically, see `metrosync._files`), printing
each path written.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from .._files import write_netcdf
from .._input_files import check_input_file
from ..errors import ParameterError

#: Suffixes of a NetCDF-4 (HDF5) dataset.
NETCDF = (".nc", ".nc4", ".cdf", ".h5")
#: Stands for the suffixes of `figure_suffixes` (resolved only when a figure is asked).
FIGURE = "figure"


def figure_suffixes() -> tuple[str, ...]:
    """File suffixes matplotlib can write (``.png``, ``.pdf``, ``.svg``, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    common = (".png", ".pdf", ".svg")
    names = (f".{name}" for name in FigureCanvasBase.get_supported_filetypes())
    return common + tuple(name for name in names if name not in common)


def check_output(
    path: Path | None,
    option: str,
    *,
    suffixes: Sequence[str] | str | None = None,
    folder: bool = False,
) -> None:
    """Refuse an output path that cannot be written, before any work is done.

    Every output option does this one thing with folders: missing ones are created
    when the output is written; a folder that can be neither created nor written in
    is refused here, before anything runs.

    path : the file to write (None: nothing asked, nothing checked).
    option : the option that gave it, for the message (``"--plot"``).
    suffixes : the suffixes accepted (lower case, with the dot), `NETCDF`, `FIGURE`;
        None accepts any.
    folder : ``path`` is a folder the command writes files into (``--store``).
    """
    if path is None:
        return
    path = Path(path)
    if folder:
        if path.exists() and not path.is_dir():
            raise ParameterError(f"`{option}` {str(path)!r} is a file; give a folder.")
        _check_folder(path / "x", option, path)  # a file in it: the folder is its parent
        return
    if path.is_dir():
        raise ParameterError(f"`{option}` {str(path)!r} is a directory; give a file name.")
    if suffixes == FIGURE:
        suffixes = figure_suffixes()
    if suffixes is not None and path.suffix.lower() not in suffixes:
        shown = ", ".join(suffixes[:8]) + (", ..." if len(suffixes) > 8 else "")
        raise ParameterError(f"`{option}` {str(path)!r} must end in {shown}, the format it writes.")
    _check_folder(path, option, path)


def _check_folder(path: Path, option: str, shown: Path) -> None:
    """Refuse ``path`` when its folder can be neither created nor written in."""
    folder = path.parent
    while not folder.exists():  # the missing folders will be created
        folder = folder.parent
    problem = None
    if not folder.is_dir():
        problem = f"{str(folder)!r} is not a directory"
    else:
        try:
            with tempfile.TemporaryFile(dir=folder):
                pass
        except OSError as error:
            problem = f"cannot create files in {str(folder)!r} ({error.strerror})"
    if problem:
        raise ParameterError(f"`{option}` {str(shown)!r}: {problem}; choose another path.")


def read_dataset(path: Path, what: str = "input file"):
    """Load a NetCDF file written by metrosync into memory."""
    import xarray as xr

    path = check_input_file(path, what)
    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            return ds.load()
    except (OSError, ValueError) as error:
        raise ParameterError(
            f"cannot read {what} {str(path)!r} as a metrosync NetCDF file: {error}"
        ) from None


def write_outputs(
    ds, *, out: Path | None = None, plot: Path | None = None, plotter: Callable | None = None
) -> None:
    """Write ``ds`` to NetCDF at ``out`` and ``plotter(ds, plot)`` at ``plot``, when asked."""
    if out is not None:
        write_netcdf(ds, out)
        print(f"wrote {out}")
    if plot is not None:
        plotter(ds, plot)
        print(f"wrote {plot}")

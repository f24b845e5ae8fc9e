"""Input files, checked the same way by every reader.

Contract: a reader calls `check_input_file` before it opens a path the user gave, so
that a missing file, a folder, an unreadable or an empty file gets the same message
whichever command read it (a light-gate log, a recording, a video, a sweep, a grid, a
regions file, an angle table). The message names what was being read and says what to
give instead; the error's class is the reader's own (`ParameterError` by default), so
each reader's callers keep catching what they caught before.
"""

from __future__ import annotations

import os
from pathlib import Path

from .errors import ParameterError

#: How many of a folder's files a message shows, when a folder was given for a file.
SHOWN_FILES = 4


def check_input_file(
    path: str | Path,
    what: str,
    *,
    error: type[Exception] = ParameterError,
    allow_empty: bool = False,
) -> Path:
    """Return ``path`` as a `Path` when it is a readable file, or raise ``error``.

    path : the file the user gave.
    what : what it should hold, for the message (``"video"``, ``"light-gate log"``).
    error : the exception class to raise (a reader's own, such as `VideoFileError`).
    allow_empty : accept a file of 0 bytes (a log that is still being written).
    """
    path = Path(path)
    shown = repr(str(path))
    if path.is_dir():
        raise error(f"{what} {shown} is a directory; give a file{_inside(path)}.")
    if not path.exists():
        hint = "" if path.parent.is_dir() else f" (nor does the folder {str(path.parent)!r})"
        raise error(f"cannot read {what} {shown}: the file does not exist{hint}.")
    if not path.is_file():
        raise error(f"cannot read {what} {shown}: it is not a regular file.")
    if not os.access(path, os.R_OK):
        raise error(f"cannot read {what} {shown}: permission denied.")
    if not allow_empty and path.stat().st_size == 0:
        raise error(f"cannot read {what} {shown}: the file is empty (0 bytes).")
    return path


def _inside(folder: Path) -> str:
    """`` inside it, such as 'a.wav', 'b.wav'`` (the folder's first files), or nothing."""
    try:
        names = sorted(p.name for p in folder.iterdir() if p.is_file() and p.name[0] != ".")
    except OSError:
        return ""
    if not names:
        return ""
    shown = ", ".join(repr(name) for name in names[:SHOWN_FILES])
    more = f" and {len(names) - SHOWN_FILES} more" if len(names) > SHOWN_FILES else ""
    return f" inside it, such as {shown}{more}"

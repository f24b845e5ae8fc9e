"""Ctrl-C that always lands, promptly, wherever the process is.

Python turns SIGINT into `KeyboardInterrupt` in the main thread at the next bytecode.
Two things can defeat that. A compiled kernel runs no bytecode until it returns: the
drivers bound each call's duration (`metrosync.pacing`). And the exception can be
raised inside code whose exceptions Python discards, such as a garbage-collector
callback (dask installs some): the interrupt is then printed as "Exception ignored"
and lost, and the work goes on.

Inside `sigint_checked` (entered by the command line, and by the work that waits on
other processes), SIGINT still raises `KeyboardInterrupt` at once, and also sets a
flag; `check`, called by every long loop between two pieces of work, raises it again
when it was lost. Lost interrupts are not printed, nor, once SIGINT arrived, the
complaints of finalizers of what it abandoned; `release` lets go of the rest before the
command's last line.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator

_requested = threading.Event()


def _on_sigint(signum, frame) -> None:
    _requested.set()
    raise KeyboardInterrupt


def _discard_lost_interrupts(unraisable) -> None:
    if _requested.is_set():
        # A lost interrupt: `check` raises it again where it can be handled. Any other
        # error comes from the finalizer of something the interrupt abandoned half-made
        # (an h5netcdf file interrupted while it opened): noise after the work was stopped.
        return
    _previous_hook(unraisable)


_previous_hook = sys.unraisablehook


def requested() -> bool:
    """Whether SIGINT arrived inside the current `sigint_checked` block."""
    return _requested.is_set()


def check() -> None:
    """Raise `KeyboardInterrupt` if SIGINT arrived and was lost since it was raised."""
    if _requested.is_set():
        raise KeyboardInterrupt


@contextlib.contextmanager
def sigint_checked() -> Iterator[None]:
    """Make SIGINT set the flag that `check` reads, as well as raise.

    Does nothing outside the main thread, or where someone else handles SIGINT.
    """
    global _previous_hook
    mine = (
        threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    )
    if not mine:
        yield
        return
    _requested.clear()
    _previous_hook = sys.unraisablehook
    signal.signal(signal.SIGINT, _on_sigint)
    sys.unraisablehook = _discard_lost_interrupts
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        sys.unraisablehook = _previous_hook
        _requested.clear()


def release(interrupt: BaseException) -> None:
    """Let go, now, of what the interrupted work held open, so that nothing is printed
    after the command's last line.

    The frames of an interrupt's traceback keep the objects the work was using alive,
    a file half-opened by h5netcdf among them; left to the interpreter's exit, their
    finalizers complain ("Exception ignored in: <function File.close ...>") after the
    one line that says what was kept. Here the frames are cleared, xarray's cache of
    open files is closed, and what that frees is collected with its finalizers'
    complaints discarded: the work they belonged to was abandoned, and every output is
    written atomically, so no file that counts is left behind.
    """
    import gc
    import traceback

    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        seen: set[int] = set()
        error: BaseException | None = interrupt
        while error is not None and id(error) not in seen:
            seen.add(id(error))
            if error.__traceback__ is not None:
                traceback.clear_frames(error.__traceback__)
                error.__traceback__ = None
            error = error.__context__ or error.__cause__
        file_manager = sys.modules.get("xarray.backends.file_manager")
        if file_manager is not None:
            for opened in list(file_manager.FILE_CACHE.values()):
                with contextlib.suppress(Exception):
                    opened.close()
        gc.collect()
    finally:
        sys.unraisablehook = hook

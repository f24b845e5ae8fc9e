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
when it was lost. Lost interrupts are not printed.
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
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and _requested.is_set():
        return  # `check` raises it again where it can be handled
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

"""The ``metrosync`` command (``python -m metrosync``, and the installed script).

This module is the entry point because it imports nothing heavy before `main` runs:
a Ctrl-C while the command line's own modules load (argparse, the error types) ends
with the same one line and status 130 as one during the work, never a traceback.
From `metrosync.cli.main` on, `metrosync.interrupts` takes over.
"""

import signal
import sys


def main(argv: list[str] | None = None) -> int:
    """Run the command line (`metrosync.cli.main`); returns the exit code."""
    try:
        from .cli import main as run
    except KeyboardInterrupt:
        return _interrupted(argv, "nothing was written")
    try:
        code = run(argv)
    except KeyboardInterrupt:  # in the instant after `run` restored Python's handler
        return _interrupted(argv, "its work had ended")
    # The work is over and its outputs are whole: a Ctrl-C while the interpreter shuts
    # down would only turn a finished command into one killed by SIGINT.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if code == 130:
        _end_interrupted()
    return code


def _interrupted(argv: list[str] | None, what: str) -> int:
    """Say, in the command's one line, that Ctrl-C ended it and ``what`` was kept; then
    exit 130 (`_end_interrupted`: an interrupt that escaped an import's C code would
    otherwise kill the interpreter by SIGINT at exit, after the line)."""
    command = " ".join((sys.argv[1:] if argv is None else argv)[:1])
    print(f"metrosync {command}: interrupted: {what}", file=sys.stderr)
    if argv is None:  # the command itself, not a caller in this process
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        _end_interrupted()
    return 130


def _end_interrupted() -> None:
    """Exit with status 130 now, the interrupt handled and its line printed.

    CPython remembers a KeyboardInterrupt that escaped code it ran through its C API
    (as some extensions do), and at a normal exit kills itself with SIGINT, so the
    status would read as killed although the interrupt was handled. The exit handlers
    run and the standard streams are flushed first; every output was written and
    closed before the line was printed.
    """
    import atexit
    import os

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(130)


if __name__ == "__main__":
    sys.exit(main())

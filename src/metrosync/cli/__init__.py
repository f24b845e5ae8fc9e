"""The ``metrosync`` command line: one module per subcommand.

Each subcommand module exposes ``register(subparsers)``, which adds its parser and
sets ``func`` to a handler taking the parsed arguments and returning an exit code.

Exit codes: 0 success; 1 the work ran but did not fully succeed (a sweep with
failed or missing points), a file could not be written, or the reader of the output
went away; 2 bad input, reported in one line that names the option, the value and
what to do (a `MetrosyncError`); 130 stopped by Ctrl-C (SIGINT), whatever the command,
reported in one line that says what was kept and how to resume (`record` keeps its
capture and `analyze --follow` writes its analysis first: for them Ctrl-C is the usual
end, and still exits 130). Warnings print as one line each.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import re
import sys
import warnings

from .. import interrupts
from .._files import recording_writes
from .._version import __version__
from ..errors import MetrosyncError

#: Subcommand modules, in the order ``--help`` lists them.
SUBCOMMANDS = (
    "simulate", "presets", "reproduce", "analyze", "calibrate", "sweep",
    "critical", "theory", "pantaleone", "animate", "listen", "page", "playground", "record",
    "track",
)  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    """The ``metrosync`` parser with every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="metrosync",
        description="Simulate and measure the synchronization of metronomes on a rotating disk.",
        epilog="`metrosync COMMAND --help` describes each command.",
    )
    parser.add_argument("--version", action="version", version=f"metrosync {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(subparsers)
    return parser


def name_options(message: str, aliases: dict[str, str]) -> str:
    """Add the command-line option to each library argument a message names.

    >>> name_options("`sigma_bpm` must be >= 0", {"sigma_bpm": "--sigma"})
    '`sigma_bpm` (--sigma) must be >= 0'
    """

    def named(match: re.Match) -> str:
        option = aliases.get(match[1])
        return f"{match[0]} ({option})" if option else match[0]

    return re.sub(r"`(\w+)`", named, message)


def main(argv: list[str] | None = None) -> int:
    """Run ``metrosync`` with ``argv`` (default: the process's); returns the exit code."""
    written: list = []
    try:
        with recording_writes() as written, interrupts.sigint_checked():
            try:
                code = _run(argv)
            except Exception:
                # An interrupt raised inside a library can leave it broken, so that it
                # fails next with an error of its own (matplotlib: "Invalid affine
                # transformation matrix"). After Ctrl-C, that error is the interrupt.
                if interrupts.requested():
                    raise KeyboardInterrupt from None
                raise
            if interrupts.requested():
                # The work took the interrupt and finished what it was doing (a write
                # that completed): Ctrl-C still ends with its line and status 130.
                raise KeyboardInterrupt
            return code
    except KeyboardInterrupt as interrupt:
        # The one handler for Ctrl-C: every subcommand's outputs are atomic, so what
        # exists is whole; say what that is, and how to go on.
        command = " ".join(sys.argv[1:2] if argv is None else argv[:1])
        kept = _kept(interrupt, written)
        interrupts.release(interrupt)
        print(f"metrosync {command}: interrupted: {kept}", file=sys.stderr)
        return 130


def _kept(interrupt: KeyboardInterrupt, written: list) -> str:
    kept = getattr(interrupt, "kept", None)
    if kept:
        return kept
    if not written:
        return "nothing was written"
    names = ", ".join(str(path) for path in written[:3])
    more = f" and {len(written) - 3} more" if len(written) > 3 else ""
    return f"kept {names}{more} (complete); the rest was not written"


def _run(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)

    shown: set[str] = set()

    def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
        # A check may run once before the work and again inside it (animate's size
        # check): the user hears each warning once, wherever it was raised.
        text = name_options(str(message), getattr(args, "_aliases", None) or {})
        if text not in shown:
            shown.add(text)
            print(f"metrosync {args.command}: warning: {text}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            # An unclosed file is a note for developers (an import cut short by Ctrl-C
            # leaves one), never a line for the user.
            warnings.simplefilter("ignore", ResourceWarning)
            warnings.showwarning = show_warning
            code = int(args.func(args) or 0)
            # Flush here, not at exit: a reader that went away must meet the handler below
            # whether or not the output outgrew the pipe's buffer.
            sys.stdout.flush()
            return code
    except MetrosyncError as error:
        message = name_options(str(error), getattr(args, "_aliases", None) or {})
        print(f"metrosync {args.command}: error: {message}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (`metrosync analyze ... | head`): stop quietly, and keep
        # the interpreter from complaining when it flushes stdout at exit.
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:
        # Disk full, permissions, a file vanishing: the environment, not a bug to trace.
        where = f" {error.filename!r}" if error.filename else ""
        print(f"metrosync {args.command}: error:{where} {error.strerror or error}",
              file=sys.stderr)  # fmt: skip
        return 1

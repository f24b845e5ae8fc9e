"""The ``metrosync`` command line: one module per subcommand.

Each subcommand module exposes ``register(subparsers)``, which adds its parser and
sets ``func`` to a handler taking the parsed arguments and returning an exit code.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import warnings

from ..errors import MetrosyncError

#: Subcommand modules, in the order ``--help`` lists them.
SUBCOMMANDS = (
    "simulate", "presets", "reproduce", "analyze", "calibrate", "sweep",
    "critical", "animate", "listen", "page",
)  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="metrosync",
        description="Simulate and measure the synchronization of metronomes on a rotating disk.",
    )
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    warnings.simplefilter("default")
    try:
        return int(args.func(args) or 0)
    except MetrosyncError as error:
        print(f"metrosync {args.command}: error: {error}", file=sys.stderr)
        return 2

"""``metrosync record``: the logger's serial stream → a capture file, with a live panel."""

from __future__ import annotations

import sys
import warnings

from .._words import plural
from ..errors import Interrupted, ParameterError
from ._options import HelpFormatter, add_aliases, int_list, path_option


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "record",
        help="record a light-gate logger's serial stream, with a live r(t)",
        description="Read the gate-logger's lines from a serial port and write them, line "
        "for line, to a capture file that `metrosync analyze` reads (flushed at once, synced "
        "to disk every second). A board that did not reset when the port opened is asked "
        "for its header after 2 s; a note in the capture says when none came. Shows a live "
        "panel: passes and BPM per gate, silent gates and gates that never changed (left "
        "out of r), and r(t). Ctrl-C ends the recording: the capture is kept, complete, and "
        "the exit status is 130 as for every command stopped by Ctrl-C.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument("port", metavar="PORT", help="serial port, e.g. /dev/ttyACM0 or COM3")
    parser.add_argument("--out", type=path_option, required=True, help="capture file to write")
    parser.add_argument("--baud", type=int, default=115200, help="serial rate (the firmware's)")
    parser.add_argument("--duration", type=float, default=None, metavar="S",
                        help="stop after S seconds (default: at Ctrl-C)")  # fmt: skip
    parser.add_argument(
        "--channels",
        type=int_list,
        default=None,
        metavar="I,J,...",
        help="gates to show and use for the live r, 0-based (default: all); refused, with "
        "the valid range, as soon as the logger's header or first lines give its gate count",
    )
    parser.add_argument("--reconnect", action="store_true",
                        help="when the port vanishes, wait for it and mark the gap")  # fmt: skip
    parser.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    parser.add_argument(
        "--plain",
        action="store_true",
        help="plain status lines instead of the panel, even on a terminal",
    )
    add_aliases(parser, duration="--duration", baud="--baud", port="PORT", channels="--channels")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..lightgate.channels import check_channels, never_changed_text
    from ..lightgate.follow import LogFollower
    from ..lightgate.recorder import record
    from ._io import check_output
    from ._live import LIVE_LINES, LivePanel

    check_output(args.out, "--out")
    if args.out.exists() and not args.overwrite:
        raise ParameterError(
            f"`--out` {str(args.out)!r} exists; choose another name, or give --overwrite."
        )
    if args.channels is not None:
        check_channels(args.channels, 8, where=" (a logger has at most 8 gates)")
    follower = LogFollower(keep=LIVE_LINES)  # the live view only: the file keeps it all
    title = f"recording {args.port} -> {args.out}"
    try:
        with LivePanel(follower, title, channels=args.channels, plain=args.plain or None,
                       logger=f"the logger on {args.port}") as panel:  # fmt: skip
            summary = record(args.port, args.out, baud=args.baud, duration=args.duration,
                             reconnect=args.reconnect, overwrite=args.overwrite,
                             on_line=follower.feed, on_tick=panel.tick)  # fmt: skip
            panel.tick(force=True)
    except ParameterError as error:
        if not follower.n_lines:
            raise
        # Refused once the logger had spoken (`--channels` it does not have).
        raise ParameterError(
            f"{error} The {plural(follower.n_lines, 'line')} recorded so far "
            f"{'is' if follower.n_lines == 1 else 'are'} in "
            f"{str(args.out)!r}; give --overwrite to record again under that name."
        ) from None
    changes = follower.changes[: follower.gates or 0]
    dead = [k for k, n in enumerate(changes) if n == 0 and k in (args.channels or range(8))]
    if dead and len(dead) < len(changes):
        warnings.warn(f"{never_changed_text(dead)}; `metrosync analyze` leaves it out.",
                      UserWarning, stacklevel=1)  # fmt: skip
    print(f"metrosync record: {summary}", flush=True)
    if summary.ended == "port vanished":
        print(
            f"metrosync record: error: the port {args.port} vanished (cable pulled?); the "
            f"capture {args.out} is kept. Give --reconnect to wait for it.",
            file=sys.stderr,
        )
        return 1
    if summary.ended == "interrupted":
        raise Interrupted(
            f"the capture {args.out} is kept, complete ({plural(summary.lines, 'line')})"
        )
    return 0

"""``metrosync analyze --follow``: a growing capture, live, then its dataset at Ctrl-C."""

from __future__ import annotations

import time

from ..errors import Interrupted, ParameterError

#: Seconds between two looks at the followed file.
POLL_EVERY = 0.1


def follow(args, analyze_options: dict) -> int:
    """Follow ``args.logs[0]`` with the live panel until Ctrl-C, then analyse it whole
    and end as an interrupted command does (`Interrupted`: exit status 130).

    analyze_options : the keyword arguments `analyze` gets, reading options included.
    """
    from ..lightgate.analyze import analyze_logs
    from ..lightgate.follow import LogFollower
    from ..lightgate.plots import plot_analysis
    from ..lightgate.summary import summary_text
    from ._io import write_outputs
    from ._live import LivePanel

    if len(args.logs) != 1:
        raise ParameterError(
            f"`--follow` follows one LOG, got {len(args.logs)}; analyse finished runs "
            f"together without --follow."
        )
    path = args.logs[0]
    reading = {k: analyze_options.pop(k) for k in ("tick", "counter_bits", "polarity", "strict")}
    follower = LogFollower(path, **reading)
    last = time.monotonic()
    title = f"following {path} (Ctrl-C: analyse and stop)"
    with LivePanel(follower, title, channels=analyze_options.get("channels"),
                   logger=str(path)) as panel:  # fmt: skip
        try:
            while True:
                if follower.poll():
                    last = time.monotonic()
                panel.tick(time.monotonic() - last)
                time.sleep(POLL_EVERY)
        except KeyboardInterrupt:
            pass
        follower.poll(final=True)
        panel.tick(time.monotonic() - last, force=True)
    if not path.exists():
        raise ParameterError(f"{str(path)!r} does not exist: nothing was written to it while "
                             f"it was followed, so there is nothing to analyse.")  # fmt: skip
    ds = analyze_logs([follower.log()], counter_bits=reading["counter_bits"],
                      polarity=reading["polarity"], **analyze_options)  # fmt: skip
    print(summary_text(ds))
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_analysis)
    # Ctrl-C is how a follow ends, but it is still Ctrl-C: exit status 130, as for every
    # command, with what it wrote.
    written = [str(path) for path in (args.out, args.plot) if path is not None]
    raise Interrupted(
        f"analysed {path} as it stood"
        + (f"; wrote {' and '.join(written)} (complete)" if written else "")
    )

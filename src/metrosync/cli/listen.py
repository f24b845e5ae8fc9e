"""``metrosync listen``: a stereo WAV with one click per metronome at each tick."""

from __future__ import annotations

from pathlib import Path

from .._words import plural
from ._io import check_output
from ._options import HelpFormatter, add_aliases, path_option
from ._show_source import add_source_options, load_or_simulate

#: The choices of ``--tick-sound`` (`metrosync.show.sound.TICK_SOUNDS`, not imported
#: here so that the parser stays light).
TICK_SOUNDS = ("click", "realistic")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "listen",
        help="write the ticks of a run as a WAV file",
        description="Write a stereo WAV with a click for every zero crossing of every "
        "pendulum (the instant a metronome ticks; for a metronome out of beat, "
        "--set escapement_offset=RAD, where θ crosses that angle), panned by its place "
        "on the disk. "
        "Simulating here records every step, so clicks fall on the simulated crossings. "
        "--tick-sound realistic makes each tick sound like a real metronome's: several "
        "impacts ringing through resonances of its own, tick and tock different.",
        formatter_class=HelpFormatter,
    )
    add_source_options(parser, record_seconds=None)
    out = parser.add_argument_group("sound")
    out.add_argument("--out", type=path_option, default=Path("metrosync.wav"), help="FILE.wav")
    out.add_argument("--speedup", type=float, default=1.0, help="play faster than real time")
    out.add_argument("--sample-rate", type=int, default=44100, help="samples per second")
    out.add_argument(
        "--tick-sound",
        choices=TICK_SOUNDS,
        default="click",
        help="a short click, or a real metronome's tick (impacts and ring, one sound "
        "per metronome, tick and tock different)",
    )
    add_aliases(parser, speedup="--speedup", sample_rate="--sample-rate")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..show.sound import check_length, check_sound, write_wav

    check_output(args.out, "--out", suffixes=(".wav",))
    check_sound(args.speedup, args.sample_rate)

    def check(start: float, end: float) -> None:
        # The nominal BPM stands for the metronomes; the drawn frequencies are checked
        # again once simulated.
        if args.bpm > 0:
            check_length(args.speedup, start, end, fastest_bpm=args.bpm, slowest_bpm=args.bpm)

    ds = load_or_simulate(args, check)
    track = write_wav(
        ds, args.out, run=args.run, speedup=args.speedup, start=args.start, end=args.end,
        sample_rate=args.sample_rate, tick_sound=args.tick_sound,
    )  # fmt: skip
    clicks = sum(len(t) for t in track.click_times)
    clicks = plural(clicks, "click")
    print(f"wrote {args.out} ({track.duration:.1f} s, {clicks}, {track.sample_rate} Hz)")
    return 0

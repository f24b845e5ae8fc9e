"""``metrosync analyze recording.wav``: the options and the run for sound recordings.

`metrosync.cli.analyze` adds these options to its parser and hands a recording (a
file with an audio or video suffix, see `metrosync.audio.reader`: a video's sound
track is analysed) to `run_audio`; light-gate logs go on as before. An option that
only one kind of input uses draws a warning when given with the other.
"""

from __future__ import annotations

import argparse
import sys
import warnings

from ..errors import ParameterError
from ._io import FIGURE, NETCDF, check_output, write_outputs
from ._options import add_aliases

#: Options of the light-gate analysis, which a recording ignores.
LIGHTGATE_OPTIONS = {
    "tick": "--tick", "counter_bits": "--counter-bits", "polarity": "--polarity",
    "strict": "--strict", "channels": "--channels", "glitch": "--glitch",
    "min_asymmetry": "--min-asymmetry", "grid_dt": "--grid-dt", "window": "--window",
    "follow": "--follow",
}  # fmt: skip
#: Options of the audio analysis, which light-gate logs ignore.
AUDIO_OPTIONS = {
    "bpm": "--bpm", "metronomes": "--metronomes", "band": "--band",
    "sensitivity": "--sensitivity", "refractory": "--refractory",
    "order_window": "--order-window", "cluster_gap": "--cluster-gap",
    "together": "--together",
}  # fmt: skip


def band_arg(text: str) -> tuple[float, float]:
    """``--band``: two frequencies in Hz, ``LOW,HIGH``."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 2:
        raise argparse.ArgumentTypeError(
            f"expected LOW,HIGH in Hz such as 1000,10000, got {text!r}"
        )
    return values


def add_audio_options(parser: argparse.ArgumentParser) -> None:
    """Add the options for recordings; call after the light-gate options."""
    from ..audio.settings import CLUSTER_GAP, DEFAULT_BAND, DEFAULT_SENSITIVITY

    parser.set_defaults(
        _lightgate_defaults={dest: parser.get_default(dest) for dest in LIGHTGATE_OPTIONS}
    )
    g = parser.add_argument_group(
        "sound recordings (.wav, .flac, .ogg, .mp3, a phone's .m4a, a video's sound: one "
        "file, or several with --together)",
        "Tick times, tempo, beat (tick/tock), and how together the ticks fall.",
    )
    g.add_argument(
        "--bpm",
        type=float,
        default=None,
        help="the metronomes' setting, BPM (default: found from the ticks)",
    )
    g.add_argument(
        "--metronomes",
        type=int,
        default=None,
        metavar="N",
        help="how many metronomes sound (default: the most ticks per beat heard, rounded)",
    )
    g.add_argument(
        "--band",
        type=band_arg,
        default=None,
        metavar="LOW,HIGH",
        help=f"band-pass of the tick detector, Hz, HIGH below half the sample rate (default: "
        f"{DEFAULT_BAND[0]:g},{DEFAULT_BAND[1]:g}, its top lowered for a low sample rate)",
    )
    g.add_argument(
        "--sensitivity",
        type=float,
        metavar="K",
        default=DEFAULT_SENSITIVITY,
        help="threshold in robust spreads of the detection curve (lower finds "
        "softer ticks, and more false ones)",
    )
    g.add_argument(
        "--refractory",
        type=float,
        default=None,
        metavar="S",
        help="shortest time between ticks, s (default: 1/32 beat, 3-30 ms)",
    )
    g.add_argument(
        "--order-window",
        type=float,
        default=None,
        metavar="S",
        help="window of the acoustic order parameter, s (default: 16 beats)",
    )
    g.add_argument("--cluster-gap", type=float, default=CLUSTER_GAP, metavar="F",
                   help="ticks closer than this fraction of a beat sound as one")  # fmt: skip
    # gone with the stages it chose between; refused by name, not as an unknown option
    g.add_argument("--analysis", default=None, help=argparse.SUPPRESS)
    g.add_argument("--together", action="store_true",
                   help="the recordings were made at the same time by several microphones "
                   "(one file each): align them and tell the metronomes apart by their "
                   "level at each")  # fmt: skip
    parser.set_defaults(_audio_defaults={dest: parser.get_default(dest) for dest in AUDIO_OPTIONS})
    add_aliases(parser, **AUDIO_OPTIONS)


def _changed(args, defaults: dict, names: dict) -> list[str]:
    return [names[d] for d, v in defaults.items() if getattr(args, d, v) != v]


def audio_requested(args, *, others: str = "light-gate logs") -> bool:
    """True when the inputs are recordings; refuses a mix of recordings and logs, and
    warns about audio options given with logs (or what ``others`` names instead)."""
    from ..audio.reader import is_audio_path

    if getattr(args, "analysis", None) is not None:
        raise ParameterError(
            f"--analysis {args.analysis} is no longer an option: the timing model is the "
            f"one sound analysis now (docs/sound.md, \"How it works\"); leave it out."
        )
    audio = [is_audio_path(p) for p in args.logs]
    if any(audio) and not all(audio):
        raise ParameterError(
            "give either sound recordings or light-gate logs, not both: "
            f"{', '.join(str(p) for p in args.logs)}."
        )
    if not any(audio):
        ignored = _changed(args, args._audio_defaults, AUDIO_OPTIONS)
        if ignored:
            warnings.warn(f"{others} ignore {', '.join(ignored)} (options for sound "
                          f"recordings).", UserWarning, stacklevel=2)  # fmt: skip
        return False
    return True


def run_audio(args) -> int:
    """Analyse one recording (or several made together), print the summary, write --out
    and --plot."""
    together = getattr(args, "together", False)
    if len(args.logs) != 1 and not together:
        raise ParameterError(
            f"analyse one recording at a time; got {len(args.logs)}: "
            f"{', '.join(str(p) for p in args.logs)}. Recorded at the same time by "
            f"several microphones? Add --together."
        )
    if together and len(args.logs) == 1:
        warnings.warn("--together with one recording: nothing to align.", UserWarning,
                      stacklevel=2)  # fmt: skip
    ignored = _changed(args, args._lightgate_defaults, LIGHTGATE_OPTIONS)
    if ignored:
        warnings.warn(f"a recording ignores {', '.join(ignored)} (options for light-gate "
                      f"logs).", UserWarning, stacklevel=2)  # fmt: skip
    check_output(args.out, "--out", suffixes=NETCDF)
    check_output(args.plot, "--plot", suffixes=FIGURE)
    from ..audio.analysis import analyze_audio
    from ..audio.plots import plot_audio

    ds = analyze_audio(
        list(args.logs) if together else args.logs[0],
        bpm=args.bpm,
        metronomes=args.metronomes,
        band=args.band,
        sensitivity=args.sensitivity,
        refractory=args.refractory,
        order_window=args.order_window,
        cluster_gap=args.cluster_gap,
        progress=sys.stderr.isatty(),
    )
    print(ds.attrs["summary"])
    write_outputs(ds, out=args.out, plot=args.plot, plotter=plot_audio)
    return 0

"""``metrosync presets``: list the parameter presets with their values."""

from __future__ import annotations


def register(subparsers) -> None:
    parser = subparsers.add_parser("presets", help="list parameter presets and their values")
    parser.set_defaults(func=run)


def run(args) -> int:
    del args
    from ..model import PRESETS

    for name, params in PRESETS.items():
        print(f"{name}: {params.description}")
        for key, value in params.as_dict().items():
            if key != "preset":
                print(f"    {key:16s} {value}")
        low, high = params.metronome.bpm_range()
        print(f"    {'steady amp.':16s} {params.steady_amplitude:.3f} rad"
              + ("  (OVERTURNS: > pi/2)" if params.overturns else ""))  # fmt: skip
        print(f"    {'tunable BPM':16s} {low:.1f} .. {high:.1f}")
    return 0

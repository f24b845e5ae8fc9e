"""``metrosync presets``: list the parameter presets with their values and units."""

from __future__ import annotations

from ._options import HelpFormatter


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "presets",
        help="list parameter presets and their values",
        description="List the model parameter presets (SI units), each one's steady swing "
        "and the BPM range its metronomes can be tuned to. Pick one with --preset and "
        "change single values with --set NAME=VALUE.",
        formatter_class=HelpFormatter,
    )
    parser.set_defaults(func=run)


def run(args) -> int:
    del args
    from ..model import PRESETS
    from ..sweeps.grid import UNITS

    units = {**UNITS, "l2_bounds": "m"}
    width = max(16, *(len(key) for params in PRESETS.values() for key in params.as_dict()))
    for name, params in PRESETS.items():
        print(f"{name}: {params.description}")
        for key, value in params.as_dict().items():
            if key != "preset":
                print(f"    {key:{width}s} {value} {units.get(key, '')}".rstrip())
        low, high = params.metronome.bpm_range()
        print(f"    {'steady amp.':{width}s} {params.steady_amplitude:.3f} rad"
              + ("  (OVERTURNS: > pi/2)" if params.overturns else ""))  # fmt: skip
        print(f"    {'tunable BPM':{width}s} {low:.1f} .. {high:.1f}")
    return 0

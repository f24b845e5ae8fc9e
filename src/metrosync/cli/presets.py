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
    from ..model import PRESETS, MetronomeDesign
    from ..model.quantity import units

    design_units = units(MetronomeDesign)
    width = max(16, *(len(key) for params in PRESETS.values() for key in params.as_dict()))
    for name, params in PRESETS.items():
        print(f"{name}: {params.description}")
        unit = {**design_units, **params.platform.units()}
        for key, value in params.as_dict().items():
            if key != "preset":
                print(f"    {key:{width}s} {value} {unit.get(key, '')}".rstrip())
        low, high = params.metronome.bpm_range()
        overturns = "  (OVERTURNS: > pi/2)" if params.overturns else ""
        print(f"    {'steady amp.':{width}s} {params.balance_amplitude:.3f} rad{overturns}")
        print(f"    {'tunable BPM':{width}s} {low:.1f} .. {high:.1f} ({params.metronome.tuning})")
        print(f"    {'tick at 192':{width}s} {_tick_at(params.metronome, 192.0)}")
    print(
        "tuning: 'small-amplitude' puts the small-swing frequency on the nominal BPM, "
        "'steady-swing' the tick rate at the steady swing (--set tuning=steady-swing)."
    )
    return 0


def _tick_at(design, bpm: float) -> str:
    """What a metronome marked ``bpm`` ticks at under each tuning (rigid support)."""
    from dataclasses import replace

    from ..errors import ParameterError
    from ..model.steady_swing import steady_swing

    rows = []
    for tuning in ("small-amplitude", "steady-swing"):
        try:
            one = replace(design, tuning=tuning)
            tick = steady_swing(one.with_l2(one.l2_for_bpm(bpm))).tick_bpm
            rows.append(f"{tick:.1f} BPM ({tuning})")
        except ParameterError:
            rows.append(f"no steady swing ({tuning})")
    return ", ".join(rows)

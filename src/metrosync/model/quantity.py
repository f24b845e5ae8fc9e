"""Each model parameter's unit and bounds, declared once, as field metadata.

A parameter dataclass (`MetronomeDesign`, `Metronome`, `Platform`) declares a field
with `quantity`: its default, its unit as a person writes it (``"kg m²/s"``) and the
`Bounds` of its values. Everything that needs them reads them there: the checks of
``__post_init__`` (`check_quantities`), the ``metrosync presets`` listing and the
units of a sweep's axes (`units`, in the ASCII form that file attributes use,
``"kg m2/s"``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from ..errors import ParameterError, require_finite


@dataclass(frozen=True)
class Bounds:
    """The values a parameter may take: ``value >= at_least``, ``value > above`` and
    ``value < below``, each where given; ``shown`` writes them for a message."""

    at_least: float | None = None
    above: float | None = None
    below: float | None = None
    shown: str = ""

    def admits(self, value: float) -> bool:
        return not (
            (self.at_least is not None and not value >= self.at_least)
            or (self.above is not None and not value > self.above)
            or (self.below is not None and not value < self.below)
        )

    @property
    def text(self) -> str:
        """``>= 0``, ``> 0``, or the interval ``shown``."""
        if self.shown:
            return self.shown
        if self.below is None and (self.at_least is None) != (self.above is None):
            return f">= {self.at_least:g}" if self.above is None else f"> {self.above:g}"
        raise ValueError(f"{self!r} has no words: give `shown`")

    def __str__(self) -> str:
        """What a value must do, for a message: ``be >= 0``, or ``lie in (a, b)``."""
        return f"lie in {self.text}" if self.shown else f"be {self.text}"


#: Bounds of a quantity that may be zero, of one that must not, and of an angle on the
#: lower half of a swing.
NON_NEGATIVE = Bounds(at_least=0.0)
POSITIVE = Bounds(above=0.0)
LOWER_HALF = Bounds(above=-math.pi / 2, below=math.pi / 2, shown="(-pi/2, pi/2)")


def quantity(
    default: Any = dataclasses.MISSING,
    *,
    unit: str = "",
    bounds: Bounds | None = None,
    why: str = "",
    choices: tuple[str, ...] = (),
) -> Any:
    """A dataclass field with its unit, its bounds (checked by `check_quantities`),
    what to say when a value is out of them (``why``), and, for a field that takes a
    name, its ``choices``."""
    metadata = {"unit": unit, "bounds": bounds, "why": why, "choices": choices}
    return dataclasses.field(default=default, metadata=metadata)


def check_quantities(obj: Any, *names: str) -> None:
    """Raise `ParameterError` unless each field ``names`` of ``obj`` (default: every
    field with bounds, in order) is a finite number within its declared bounds:
    "`w1` must be > 0 kg, got -1.0."."""
    fields = {f.name: f for f in dataclasses.fields(obj)}
    if not names:
        names = tuple(name for name, f in fields.items() if f.metadata.get("bounds"))
    for name in names:
        meta = fields[name].metadata
        value = require_finite(name, getattr(obj, name))
        bounds: Bounds = meta["bounds"]
        if not bounds.admits(value):
            unit = f" {meta['unit']}" if meta["unit"] else ""
            why = f": {meta['why']}" if meta["why"] else ""
            raise ParameterError(f"`{name}` must {bounds}{unit}, got {value!r}{why}.")


def documented(cls: type) -> type:
    """Class decorator: end the docstring of ``cls`` with each field's unit and bounds,
    read from their declarations, so that ``help()`` shows them."""
    fields = [
        f for f in dataclasses.fields(cls) if f.metadata.get("unit") or f.metadata.get("bounds")
    ]
    width = max(len(f.name) for f in fields)
    rows = [
        f"    {f.name:{width}s}  {f.metadata['unit'] or '1':10s} "
        f"{f.metadata['bounds'].text if f.metadata['bounds'] else ''}".rstrip()
        for f in fields
    ]
    title = "Units and bounds (declared on the fields)"
    cls.__doc__ = "\n".join(
        [(cls.__doc__ or "").rstrip(), "", f"    {title}", f"    {'-' * len(title)}", *rows, "    "]
    )
    return cls


def declared(obj: Any, name: str, key: str = "unit") -> Any:
    """What field ``name`` of ``obj`` (a parameter dataclass or one of its instances)
    declares as ``key``: ``"unit"``, ``"bounds"``, ``"why"`` or ``"choices"``."""
    return obj.__dataclass_fields__[name].metadata[key]


def units(*classes: type) -> dict[str, str]:
    """Each field's unit, by name, as file attributes write it (ASCII: ``kg m2/s``);
    fields without a unit (a switch, a name) are left out."""
    return {
        f.name: ascii_unit(f.metadata["unit"])
        for cls in classes
        for f in dataclasses.fields(cls)
        if f.metadata.get("unit")
    }


def named(*classes: type) -> dict[str, tuple[str, ...]]:
    """The fields that take a name rather than a number (``tuning``, ``platform``), with
    their choices, by name."""
    return {
        f.name: f.metadata["choices"]
        for cls in classes
        for f in dataclasses.fields(cls)
        if f.metadata.get("choices")
    }


def ascii_unit(unit: str) -> str:
    """``"kg m²/s"`` -> ``"kg m2/s"``: the unit as UDUNITS and NetCDF attributes read it."""
    return unit.translate(_SUPERSCRIPTS)


_SUPERSCRIPTS = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-")

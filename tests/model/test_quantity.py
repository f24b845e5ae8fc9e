"""Each model parameter's unit and bounds are declared once, on its field, and every
reader (the checks, the presets listing, the sweep axes) takes them from there."""

from __future__ import annotations

import dataclasses

import pytest

from metrosync.errors import ParameterError
from metrosync.groups import Group
from metrosync.model import Metronome, MetronomeDesign, Platform
from metrosync.model.quantity import ascii_unit, declared, units
from metrosync.simulation.request import SimulationRequest
from metrosync.sweeps.grid import MODEL_PARAMETERS, UNITS

#: Fields that are a name or a switch: no unit.
UNITLESS = {"tuning", "platform", "escapement_reaction"}


@pytest.mark.parametrize("cls", [MetronomeDesign, Metronome, Platform])
def test_every_quantity_of_the_model_declares_its_unit(cls):
    for field in dataclasses.fields(cls):
        if field.name not in UNITLESS | {"design"}:
            assert field.metadata.get("unit"), f"{cls.__name__}.{field.name} declares no unit"


def test_the_sweep_axes_read_the_declared_units():
    for name in MODEL_PARAMETERS:
        if name not in UNITLESS:
            owner = MetronomeDesign if name in MetronomeDesign.__dataclass_fields__ else Platform
            assert UNITS[name] == ascii_unit(declared(owner, name))
    assert UNITS["c_theta"] == "kg m2/s" and UNITS["g"] == "m/s2"
    assert UNITS["duration"] == units(SimulationRequest)["duration"] == "s"
    assert units(Group)["sigma_bpm"] == "BPM"


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: MetronomeDesign(w1=-1.0), r"^`w1` must be > 0 kg, got -1\.0\.$"),
        (lambda: MetronomeDesign(c_theta=-1.0), r"^`c_theta` must be >= 0 kg m²/s, got -1\.0\.$"),
        (lambda: MetronomeDesign(escapement_offset=2.0), r"must lie in \(-pi/2, pi/2\) rad"),
        (lambda: Metronome(l2=-0.01), r"^`l2` must be >= 0 m, got -0\.01\.$"),
        (lambda: Platform(disk_dry_friction=-1.0), r"^`disk_dry_friction` must be >= 0 N m"),
        (lambda: Platform(inertia=-1.0), r"^`inertia` must be > 0 kg m² \(or math\.inf"),
    ],
)
def test_a_value_out_of_its_declared_bounds_is_named_with_its_unit(make, message):
    with pytest.raises(ParameterError, match=message):
        make()


def test_the_docstrings_list_the_declarations():
    assert "c_theta            kg m²/s    >= 0" in MetronomeDesign.__doc__
    assert "inertia             kg m²      > 0" in Platform.__doc__

"""What runs where: the one table of model features and the consumers that run them.

The paper's model is the baseline every consumer runs. Beyond it, the model has terms
that are off by default (docs/model.md, "Beyond the paper") and a run has options that
not every backend records. Each is a `Feature`: its name, the parameters that switch
it on, a one-line summary, and how to tell whether it is on, from `ModelParameters`,
from the per-run `SystemArrays` (per-metronome values given one by one can switch a
term on there), or from a request's options (``trajectories``, ``groups``).

Each *consumer* (an integrator on one backend, ``"verlet/numba"``, or the browser
``"playground"``) declares the features it runs, in `CONSUMERS`. Everything that
decides what runs where reads this table: `simulate` (`require`, once before it runs),
the integrators' registry (which backends record trajectories), the kernels that
refuse a term (``located``, the GPU backend), the command line's choices and help,
the budget's cost model (`Consumer.cost`), the playground, and the tests' parameter
lists, so that a new feature is asked of every consumer at once.

`require(consumer, *sources)` raises `UnsupportedFeature`, a `ParameterError` that
names the feature's parameter and value, the consumer, and the consumers that run it:

    `disk_dry_friction` = 0.005 N m: integrator 'located' has no dry friction on the
    disk; use integrator='verlet' (or 'exact').

The module imports nothing heavy (no numba, scipy or xarray), so that every consumer,
the command line's parser included, can read it cheaply.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ParameterError

#: What a detector returns when a feature is on: (parameter, value shown, unit).
Found = tuple[str, Any, str]


class UnsupportedFeature(ParameterError):
    """A consumer was asked to run a model feature it does not have.

    ``feature`` and ``consumer`` are the names in `FEATURES` and `CONSUMERS`."""

    def __init__(self, message: str, *, feature: str, consumer: str) -> None:
        super().__init__(message)
        self.feature = feature
        self.consumer = consumer


@dataclass(frozen=True)
class Feature:
    """A model term or run option beyond the paper's baseline.

    name : the feature's name (a key of `FEATURES`).
    parameters : the model parameters (or `simulate` options) that switch it on.
    summary : one line for help texts and messages.
    lacks : how a message says that a consumer does not have it ("no dry friction on
        the disk"); "has {lacks}" must read as a sentence.
    example : for a model feature, the parameter changes (``with_changes``) that
        switch it on; for a run option, `simulate`'s keyword arguments that ask for it
        (for two metronomes); tests ask every consumer with it.
    kind : ``"model"`` (a term of the equations, or the tuning), ``"run"`` (a run
        option or record of `simulate`), ``"system"`` (a form of the per-run arrays
        that no parameter makes yet; tests build the arrays by hand).
    from_params : (ModelParameters) → `Found` when it is on, else None.
    from_system : (SystemArrays) → `Found` when it is on, else None; None when the
        arrays cannot tell (the tuning only sets the slider positions).
    from_request : (mapping of `simulate` options) → `Found` when it is on, else None.
    """

    name: str
    parameters: tuple[str, ...]
    summary: str
    lacks: str
    example: Mapping[str, Any] = field(repr=False)
    kind: str = "model"
    from_params: Callable[[Any], Found | None] | None = field(default=None, repr=False)
    from_system: Callable[[Any], Found | None] | None = field(default=None, repr=False)
    from_request: Callable[[Mapping[str, Any]], Found | None] | None = field(
        default=None, repr=False
    )

    def found(self, source: Any) -> Found | None:
        """(parameter, value, unit) when this feature is on in ``source`` (model
        parameters, system arrays or a mapping of request options), else None."""
        if isinstance(source, Mapping):
            return self.from_request(source) if self.from_request else None
        if hasattr(source, "metronome") and hasattr(source, "platform"):
            return self.from_params(source) if self.from_params else None
        if hasattr(source, "total_inertia"):
            return self.from_system(source) if self.from_system else None
        raise TypeError(f"cannot read features from {type(source).__name__}")


def _largest(values, *, absolute: bool = False) -> float:
    values = np.abs(values) if absolute else np.asarray(values)
    return float(np.max(values))


def _offset(values) -> float:
    """The offset furthest from 0, with its sign."""
    flat = np.ravel(np.asarray(values, dtype=float))
    return float(flat[np.argmax(np.abs(flat))])


def _platform_coordinates(system) -> Found | None:
    """A platform the one-coordinate kernels cannot take: several coordinates, or one
    whose metronomes sit at different levers (`SystemArrays.one_coordinate`)."""
    if system.coordinates > 1:
        return ("platform", f"{system.coordinates} coordinates", "")
    if system.one_coordinate() is None:
        return ("platform", "metronomes at different levers", "")
    return None


def _platform_dry_friction(platform) -> Found | None:
    """The platform's Coulomb friction, named by its own parameter, when it is on."""
    name = platform.dry_friction_parameter
    value = getattr(platform, name)
    return (name, value, platform.units()[name]) if value > 0 else None


FEATURES: dict[str, Feature] = {
    f.name: f
    for f in (
        Feature(
            name="forcing",
            parameters=("forcing_amplitude", "forcing_bpm"),
            summary="an external torque A sin(Ω t) on the disk",
            lacks="no external forcing torque on the disk",
            example={"forcing_amplitude": 0.02, "forcing_bpm": 189.0},
            from_params=lambda p: (
                (
                    "forcing_amplitude",
                    p.platform.forcing_amplitude,
                    p.platform.units()["forcing_amplitude"],
                )
                if p.platform.forcing_amplitude != 0
                else None
            ),
            from_system=lambda s: (
                ("forcing_amplitude", _largest(s.forcing_amplitude, absolute=True), "N m")
                if np.any(s.forcing_amplitude != 0)
                else None
            ),
        ),
        Feature(
            name="escapement-offset",
            parameters=("escapement_offset",),
            summary="the escapement acts where θ crosses δ ≠ 0 (a metronome out of beat)",
            lacks="no escapement offset",
            example={"escapement_offset": 0.07},
            from_params=lambda p: (
                ("escapement_offset", p.metronome.escapement_offset, "rad")
                if p.metronome.escapement_offset != 0
                else None
            ),
            from_system=lambda s: (
                ("escapement_offset", _offset(s.escapement_offset), "rad")
                if np.any(s.escapement_offset != 0)
                else None
            ),
        ),
        Feature(
            name="no-escapement-reaction",
            parameters=("escapement_reaction",),
            summary="the escapement's reaction −Σ𝕄 taken off the disk",
            lacks="no switch for the escapement's reaction on the disk",
            example={"escapement_reaction": False},
            from_params=lambda p: (
                ("escapement_reaction", False, "") if not p.platform.escapement_reaction else None
            ),
            # Off in a run whose platform takes the reaction on none of its coordinates
            # (a second coordinate, a translation, need not take it).
            from_system=lambda s: (
                ("escapement_reaction", False, "")
                if np.any(np.all(s.escapement_reaction != 1, axis=-1))
                else None
            ),
        ),
        Feature(
            name="dry-friction",
            parameters=("disk_dry_friction", "board_dry_friction"),
            summary="Coulomb (dry) friction on the platform: it sticks and slips",
            lacks="no dry friction on the platform",
            example={"disk_dry_friction": 5e-3},
            from_params=lambda p: _platform_dry_friction(p.platform),
            from_system=lambda s: (
                ("disk_dry_friction", _largest(s.dry_friction), "N m")
                if np.any(s.dry_friction > 0)
                else None
            ),
        ),
        Feature(
            name="board",
            parameters=("platform",),
            summary="the metronomes on a board on rollers instead of the disk",
            lacks="no board on rollers (only the disk)",
            example={"platform": "board"},
            from_params=lambda p: (
                ("platform", "board", "") if p.platform.platform == "board" else None
            ),
        ),
        Feature(
            name="platform-coordinates",
            parameters=("platform",),
            summary="a platform of several generalized coordinates (equations, P > 1)",
            lacks="no platform of several coordinates (only the disk, the board)",
            # No parameter builds one yet: a new platform term would (docs/model.md §9.1).
            example={},
            kind="system",
            from_system=_platform_coordinates,
        ),
        Feature(
            name="steady-swing",
            parameters=("tuning",),
            summary="L2 tuned so that a metronome ticks at its BPM at its steady swing",
            lacks="no steady-swing tuning (it tunes by the small-amplitude frequency)",
            example={"tuning": "steady-swing"},
            from_params=lambda p: (
                ("tuning", p.metronome.tuning, "") if p.metronome.tuning == "steady-swing" else None
            ),
        ),
        Feature(
            name="groups",
            parameters=("groups",),
            summary="groups of metronomes at their own frequencies, each with its order",
            lacks="no groups",
            example={"groups": [(1, 186.0), (2, 198.0)]},
            kind="run",
            from_request=lambda r: (
                ("groups", len(r["groups"]), "") if r.get("groups") is not None else None
            ),
        ),
        Feature(
            name="trajectories",
            parameters=("trajectories",),
            summary="θ, θ̇, φ, φ̇ recorded at every record",
            lacks="no trajectories yet (it does not record them)",
            example={"trajectories": True},
            kind="run",
            from_request=lambda r: ("trajectories", True, "") if r.get("trajectories") else None,
        ),
        Feature(
            name="death",
            parameters=("escapement_stopped",),
            summary="each escapement's last kick, which flags a metronome that stopped",
            lacks="no record of each escapement's last kick",
            example={"changes": {"escapement_offset": 0.45}, "theta0": [0.3, 0.6]},
            kind="run",
            # `simulate` records it always, and says so in its request.
            from_request=lambda r: (
                ("escapement_stopped", True, "") if r.get("escapement_stopped") else None
            ),
        ),
    )
}


@dataclass(frozen=True)
class Consumer:
    """Something that runs the model: an integrator on one backend, or the playground.

    name : ``"integrator/backend"``, or ``"playground"``.
    runs : the names of the `FEATURES` it runs.
    described : how a message names it ("integrator 'located'").
    cost : how the budget estimates its time: ``"compiled"`` (per run-step and
        oscillator-step), ``"numpy"`` (per step, vectorised over runs) or
        ``"whole-run"`` (per run and simulated second).
    """

    name: str
    runs: frozenset[str]
    described: str
    cost: str = "compiled"

    @property
    def integrator(self) -> str | None:
        return self.name.split("/")[0] if "/" in self.name else None

    @property
    def backend(self) -> str | None:
        return self.name.split("/")[1] if "/" in self.name else None


#: The integrators share one set of force functions (`equations`, `integrators._physics`),
#: so each runs every feature but those it names; a feature added to the table is then
#: compared between every layout and its NumPy twin (tests/integrators/test_kernels.py).
_ALL = frozenset(FEATURES)
#: The compiled kernels hold the platform as one coordinate per run, and located's
#: impulse is written for one: a platform of several runs on the NumPy twin's verlet
#: and on exact.
_ONE_COORDINATE = frozenset({"platform-coordinates"})
#: The playground's JavaScript (`metrosync.show.playground`): every term of the model
#: (the forcing, the escapement's offset and reaction switch, dry friction on the
#: platform, the board on rollers) and the steady-swing tuning; ``run(params, steps)``
#: returns trajectories; no groups' orders, no kick records.
PLAYGROUND_RUNS = frozenset(
    {
        "forcing",
        "escapement-offset",
        "no-escapement-reaction",
        "dry-friction",
        "board",
        "steady-swing",
        "trajectories",
    }
)

CONSUMERS: dict[str, Consumer] = {
    c.name: c
    for c in (
        Consumer("verlet/numba", _ALL - _ONE_COORDINATE, "integrator 'verlet'"),
        Consumer("verlet/numpy", _ALL, "integrator 'verlet'", cost="numpy"),
        Consumer(
            "verlet/gpu",
            _ALL - {"dry-friction", "trajectories"} - _ONE_COORDINATE,
            "the GPU backend",
        ),
        Consumer(
            "located/numba", _ALL - {"dry-friction"} - _ONE_COORDINATE, "integrator 'located'"
        ),
        Consumer(
            "located/numpy",
            _ALL - {"dry-friction"} - _ONE_COORDINATE,
            "integrator 'located'",
            cost="numpy",
        ),
        Consumer(
            "located/gpu",
            _ALL - {"dry-friction", "trajectories"} - _ONE_COORDINATE,
            "integrator 'located' on the GPU",
        ),
        Consumer("exact/scipy", _ALL, "integrator 'exact'", cost="whole-run"),
        Consumer("playground", PLAYGROUND_RUNS, "the playground"),
    )
}


def consumer(name: str) -> Consumer:
    """The consumer called ``name``; `ParameterError` listing the valid names if none."""
    try:
        return CONSUMERS[name]
    except (KeyError, TypeError):
        raise ParameterError(
            f"unknown consumer {name!r}; choose one of {list(CONSUMERS)}."
        ) from None


def consumer_of(integrator: str, backend: str) -> Consumer:
    """The consumer of ``integrator`` on ``backend`` (a whole-run integrator has one
    backend, which any ``backend`` names)."""
    name = f"{integrator}/{backend}"
    if name in CONSUMERS:
        return CONSUMERS[name]
    own = [c for c in CONSUMERS.values() if c.integrator == integrator]
    if len(own) == 1:
        return own[0]
    return consumer(name)


def runs(name: str, feature: str) -> bool:
    """Whether consumer ``name`` runs ``feature``."""
    if feature not in FEATURES:
        raise ParameterError(f"unknown feature {feature!r}; choose one of {list(FEATURES)}.")
    return feature in consumer(name).runs


def backends_running(integrator: str, feature: str) -> tuple[str, ...]:
    """The backends of ``integrator`` that run ``feature``, in the table's order."""
    return tuple(
        c.backend for c in CONSUMERS.values() if c.integrator == integrator and feature in c.runs
    )


def features_on(source: Any) -> list[tuple[Feature, Found]]:
    """The features that ``source`` (model parameters, system arrays or request
    options) switches on, with what switches each on."""
    out = []
    for f in FEATURES.values():
        found = f.found(source)
        if found is not None:
            out.append((f, found))
    return out


def require(name: str, *sources: Any) -> None:
    """`UnsupportedFeature` for the first feature on in ``sources`` (model parameters,
    system arrays, or a mapping of `simulate`'s options) that consumer ``name`` lacks."""
    who = consumer(name)
    for source in sources:
        for f, found in features_on(source):
            if f.name not in who.runs:
                raise UnsupportedFeature(refusal(who, f, found), feature=f.name, consumer=who.name)


def refusal(who: Consumer, f: Feature, found: Found) -> str:
    """The message of `require`: the parameter and value, who lacks it, what runs it."""
    parameter, value, unit = found
    return (
        f"`{parameter}` = {value!r}{' ' + unit if unit else ''}: {who.described} has {f.lacks}; "
        f"use {instead(who, f)}."
    )


def instead(who: Consumer, f: Feature) -> str:
    """What to use instead of ``who`` for feature ``f``: another backend of the same
    integrator when one runs it, else the integrators that do."""
    if who.integrator is not None:
        others = [b for b in backends_running(who.integrator, f.name) if b != who.backend]
        if others:
            return _alternatives("backend", others)
    integrators, seen = [], set()
    for c in CONSUMERS.values():  # offered only when the integrator's default backend runs it
        if c.integrator and c.integrator not in seen:
            seen.add(c.integrator)
            if f.name in c.runs:
                integrators.append(c.integrator)
    integrators = [i for i in integrators if i != who.integrator]
    if who.integrator is None:  # the playground
        return "`metrosync.simulate` with " + _alternatives("integrator", integrators)
    return _alternatives("integrator", integrators)


def _alternatives(option: str, names: list[str]) -> str:
    first, *rest = names
    text = f"{option}={first!r}"
    if rest:
        text += " (or " + ", ".join(repr(r) for r in rest) + ")"
    return text


def describe_lacks(integrator: str) -> str:
    """For help texts: what ``integrator``'s backends do not run of what an option can
    ask for, e.g. ``"no dry-friction"`` or ``"on gpu no dry-friction, trajectories"``;
    "" when they run all."""
    own = [c for c in CONSUMERS.values() if c.integrator == integrator]
    askable = [name for name, f in FEATURES.items() if f.kind != "system"]  # by an option
    lacking = {c.backend: [f for f in askable if f not in c.runs] for c in own}
    if len({tuple(v) for v in lacking.values()}) == 1:
        missing = next(iter(lacking.values()))
        return f"no {', '.join(missing)}" if missing else ""
    return "; ".join(f"on {b} no {', '.join(m)}" for b, m in lacking.items() if m)

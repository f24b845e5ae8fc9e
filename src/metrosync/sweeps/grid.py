"""Sweep grids: which parameters vary, over which values, and what every point runs.

Contract: a `Grid` holds the swept axes (name -> tuple of values, in order) and the
fixed settings. Every point of the Cartesian product becomes a `PointSpec`: the full
keyword arguments of one `metrosync.simulate` call plus a content key
(`metrosync.sweeps.points`). The key covers every input that can change the result
(all ensemble settings, the fully resolved model parameters, the point's seed, what
is kept, the package version and the simulation's sources), so a stored point is
reused only when it would be recomputed bit for bit.

Values come from TOML (`Grid.from_toml`) or from text (`parse_values`):
``150:220:2.5`` is an inclusive range with a step, ``7,16,32`` a list, ``192`` a
single value. Each point's seed is drawn from the sweep seed and the point's own
parameter values (not its position in the grid), so enlarging a grid leaves the
points already computed valid, and any executor reproduces the same draws.
"""

from __future__ import annotations

import hashlib
import itertools
import math
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._input_files import check_input_file
from .._version import __version__
from ..errors import ParameterError, describe
from ..groups import as_groups, describe_groups, shifted
from ..model import MetronomeDesign, Platform, get_preset
from ..model.quantity import named, units
from ..simulation.request import SimulationRequest
from .points import PointSpec, canonical_json, make_point

#: Ensemble settings of `simulate`, with their type and default in a sweep.
ENSEMBLE_SETTINGS: dict[str, tuple[type, Any]] = {
    "n": (int, 7),
    "bpm": (float, 192.0),
    "sigma_bpm": (float, 0.75),
    "runs": (int, 20),
    "duration": (float, 600.0),
    "dt": (float, 0.01),
    "seed": (int, 0),
    # None: the steady swing 2M/(π c_θ); needed where that is 0 or infinite.
    "amplitude": (float, None),
}
#: Settings that exist only with ``groups``: the BPM added to every group after the first.
GROUP_SETTINGS = ("group_offset_bpm",)
#: Model parameters that can be swept or fixed (routed through ``simulate(changes=)``).
MODEL_PARAMETERS = tuple(
    sorted(
        name
        for name in (*MetronomeDesign.__dataclass_fields__, *Platform.__dataclass_fields__)
        if name != "l2_bounds"
    )
)
#: Model parameters that take a name rather than a number, and their choices.
CHOICES = named(MetronomeDesign, Platform)
#: Other names people use for the same parameter.
ALIASES = {
    "N": "n",
    "omega0": "bpm",
    "sigma": "sigma_bpm",
    "M": "drive",
    "J": "inertia",
    "seeds": "seed",
}
#: Units of the settings and parameters a sweep can vary, as file attributes write them:
#: each declared once, on the field that defines it (`metrosync.model.quantity`).
UNITS = {
    name: unit
    for name, unit in {
        **units(SimulationRequest),
        "group_offset_bpm": "BPM",
        **units(MetronomeDesign, Platform),
    }.items()
    if name in ENSEMBLE_SETTINGS or name in GROUP_SETTINGS or name in MODEL_PARAMETERS
}
#: Model switches: true/false in TOML, 0 or 1 on the command line.
SWITCHES = ("escapement_reaction",)
#: Grid size above which a typo (e.g. a step of 0.0025 for 2.5) is more likely than intent.
MAX_POINTS_PER_AXIS = 100_000
#: Sweep-level options (TOML top level) and their defaults.
OPTIONS: dict[str, Any] = {
    "preset": "default",
    "keep_r": False,
    "equilibrium_window": None,
    "record_every": None,
    "integrator": "verlet",
    "backend": "numba",
    "groups": None,
    "target_error": None,
    "max_runs": None,
}
#: Batches of `runs` a point may grow to when ``max_runs`` is not given.
DEFAULT_MAX_BATCHES = 8


def canonical_name(name: str) -> str:
    """The parameter's canonical name, or a `ParameterError` listing the valid ones."""
    name = ALIASES.get(name, name).replace("-", "_")
    if name not in ENSEMBLE_SETTINGS and name not in MODEL_PARAMETERS + GROUP_SETTINGS:
        valid = sorted({*ENSEMBLE_SETTINGS, *MODEL_PARAMETERS, *GROUP_SETTINGS, *ALIASES})
        raise ParameterError(f"unknown sweep parameter {name!r}; valid names: {valid}.")
    return name


def _kind(name: str) -> type:
    return ENSEMBLE_SETTINGS[name][0] if name in ENSEMBLE_SETTINGS else float


def _convert(name: str, value: Any) -> int | float | str:
    """One checked value of parameter ``name``."""
    if name in SWITCHES:
        words = {"0": 0, "1": 1, "false": 0, "true": 1}
        if isinstance(value, str) and value.strip().lower() in words:
            return words[value.strip().lower()]
        number = isinstance(value, bool | int | float | np.integer | np.floating)
        if not number or value not in (0, 1):
            raise ParameterError(
                f"`{name}` is a switch: give true or false (1 or 0), got {describe(value)}."
            )
        return int(value)
    if name in CHOICES:
        if not isinstance(value, str) or value.strip() not in CHOICES[name]:
            raise ParameterError(
                f"`{name}` takes one of {list(CHOICES[name])}, got {describe(value)}."
            )
        return value.strip()
    if isinstance(value, bool) or not isinstance(
        value, int | float | np.integer | np.floating | str
    ):
        raise ParameterError(f"`{name}` values must be numbers, got {describe(value)}.")
    try:
        number = float(value)
    except ValueError:
        raise ParameterError(f"`{name}`: {value!r} is not a number.") from None
    if not math.isfinite(number) and not (name == "inertia" and number == math.inf):
        raise ParameterError(f"`{name}` values must be finite, got {value!r}.")
    if _kind(name) is int:
        if number != int(number):
            raise ParameterError(f"`{name}` takes whole numbers, got {value!r}.")
        number = int(number)
        lowest = 0 if name == "seed" else 1
        if number < lowest:
            raise ParameterError(f"`{name}` must be >= {lowest}, got {value!r}.")
        return number
    if name in ("duration", "dt") and number <= 0:
        raise ParameterError(f"`{name}` must be > 0 s, got {value!r}.")
    if name == "sigma_bpm" and number < 0:
        raise ParameterError(f"`sigma_bpm` must be >= 0 BPM, got {value!r}.")
    if name == "amplitude" and number < 0:
        raise ParameterError(f"`amplitude` must be >= 0 rad, got {value!r}.")
    # 12 significant digits undo float drift of ranges (0.1*3 -> 0.3) so values hash stably.
    return float(f"{number:.12g}")


def parse_values(name: str, spec: Any) -> tuple:
    """Values of one parameter from a range ``"a:b:step"``, a list, or a single value.

    Ranges include ``b`` when it lies on the grid (within 1e-9 of a step).

    Examples
    --------
    >>> parse_values("bpm", "180:190:2.5")
    (180.0, 182.5, 185.0, 187.5, 190.0)
    >>> parse_values("n", "7,16,32")
    (7, 16, 32)
    """
    if isinstance(spec, list | tuple):
        items = list(spec)
    elif isinstance(spec, str) and ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise ParameterError(
                f"`{name}` range {spec!r} must read START:STOP:STEP, e.g. 150:220:2.5."
            )
        try:
            start, stop, step = (float(p) for p in parts)
        except ValueError:
            raise ParameterError(
                f"`{name}` range {spec!r}: START, STOP, STEP must be numbers."
            ) from None
        if not all(math.isfinite(v) for v in (start, stop, step)) or step <= 0 or stop < start:
            raise ParameterError(
                f"`{name}` range {spec!r} needs finite START <= STOP and STEP > 0."
            )
        count = math.floor((stop - start) / step + 1e-9) + 1
        if count > MAX_POINTS_PER_AXIS:
            raise ParameterError(
                f"`{name}` range {spec!r} has {count} values (more than {MAX_POINTS_PER_AXIS}); "
                f"check STEP."
            )
        items = [start + k * step for k in range(count)]
    elif isinstance(spec, str):
        items = [item for item in spec.split(",") if item.strip()]
    else:
        items = [spec]
    if not items:
        raise ParameterError(f"`{name}` has no values, got {spec!r}.")
    values = tuple(_convert(name, item) for item in items)
    if len(set(values)) != len(values):
        raise ParameterError(f"`{name}` lists a value twice: {values!r}.")
    return values


@dataclass(frozen=True)
class Grid:
    """Swept axes and fixed settings of a sweep.

    Parameters
    ----------
    axes : swept parameter -> values (each a list, a tuple or a text spec, see
        `parse_values`); the order of the axes is the order of the dimensions.
    fixed : parameters held fixed (ensemble settings or model parameters by name).
    seed : the sweep seed; each point's seed derives from it and the point's values.
        Sweeping ``seed`` instead gives independent replicas of the whole grid.
    preset : the model preset the changes apply to.
    keep_r : keep r(t) of every run (large: points × runs × records).
    equilibrium_window, record_every, integrator, backend : passed to `simulate`.
    groups : groups of metronomes (`metrosync.groups`; tuples or ``"N@BPM[:SIGMA]"``)
        in place of ``n`` and ``bpm``; then ``group_offset_bpm`` (swept or fixed) adds
        to the BPM of every group after the first, and ``sigma_bpm`` is the spread of
        the groups that give none.
    target_error : run each point until the standard error of its mean r_eq is at
        most this (`metrosync.sweeps.adaptive`): ``runs`` is then the batch that a
        point starts with and grows by, up to ``max_runs`` (default
        `DEFAULT_MAX_BATCHES` batches). None: ``runs`` runs a point.
    """

    axes: Mapping[str, Any]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    seed: int = 0
    preset: str = "default"
    keep_r: bool = False
    equilibrium_window: float | None = None
    record_every: int | None = None
    integrator: str = "verlet"
    backend: str = "numba"
    groups: Any = None
    target_error: float | None = None
    max_runs: int | None = None

    def __post_init__(self) -> None:
        axes: dict[str, tuple] = {}
        for raw, spec in dict(self.axes).items():
            name = canonical_name(raw)
            if name in axes:
                raise ParameterError(f"`{raw}` is swept twice (as {name!r}).")
            axes[name] = parse_values(name, spec)
        if not axes:
            raise ParameterError("a sweep needs at least one swept parameter in `axes`.")
        fixed: dict[str, Any] = {}
        for raw, value in dict(self.fixed).items():
            name = canonical_name(raw)
            if name in axes:
                raise ParameterError(f"`{name}` is both swept and fixed; keep one.")
            (fixed[name],) = parse_values(name, value)
        self._check_groups(axes, fixed)
        replaced = ("n", "bpm") if self.groups else ()
        for name, (_, default) in ENSEMBLE_SETTINGS.items():
            if name in axes or name in fixed or name in replaced:
                continue
            if default is not None or name == "seed":
                fixed[name] = self.seed if name == "seed" else default
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "fixed", fixed)
        get_preset(self.preset, warn=False)  # an unknown preset fails here, not per point
        self._check_model()
        self._check_target()

    def _check_target(self) -> None:
        """Check ``target_error`` and ``max_runs``, and complete ``max_runs``."""
        target, cap = self.target_error, self.max_runs
        if target is None:
            if cap is not None:
                raise ParameterError(
                    f"`max_runs` = {cap!r} caps the runs added to reach `target_error`: give "
                    f"`target_error` too (e.g. 0.01), or set `runs` instead."
                )
            return
        if (
            isinstance(target, bool)
            or not isinstance(target, int | float)
            or not (math.isfinite(target) and target > 0)
        ):
            raise ParameterError(
                f"`target_error` is the standard error of a point's mean r_eq to reach, a "
                f"number > 0 such as 0.01; got {describe(target)}."
            )
        if "runs" in self.axes:
            raise ParameterError(
                "with `target_error` each point chooses its own number of runs: fix `runs` "
                "(the batch it starts with and grows by) instead of sweeping it."
            )
        batch = self.fixed["runs"]
        if batch < 2:
            raise ParameterError(
                f"with `target_error`, `runs` is the first batch of each point and needs at "
                f"least 2 runs to estimate the spread, got {batch}."
            )
        if cap is None:
            cap = DEFAULT_MAX_BATCHES * batch
        if isinstance(cap, bool) or not isinstance(cap, int | np.integer) or cap < batch:
            raise ParameterError(
                f"`max_runs` must be a whole number >= `runs` ({batch}), got {describe(cap)}."
            )
        object.__setattr__(self, "target_error", float(target))
        object.__setattr__(self, "max_runs", int(cap))

    def _check_groups(self, axes, fixed) -> None:
        if self.groups is None:
            if "group_offset_bpm" in {*axes, *fixed}:
                raise ParameterError(
                    "`group_offset_bpm` shifts the groups after the first: give `groups` too."
                )
            return
        object.__setattr__(self, "groups", as_groups(self.groups, None))
        given = [name for name in ("n", "bpm") if name in axes or name in fixed]
        if given:
            raise ParameterError(
                f"`groups` sets the number and BPM of each group's metronomes; drop `{given[0]}`."
            )

    def _check_model(self) -> None:
        """Build every distinct parameter set once, so bad values fail before any work."""
        swept_model = [name for name in self.axes if name in MODEL_PARAMETERS]
        bpms = self.axes["bpm"] if "bpm" in self.axes else (self.fixed.get("bpm"),)
        if self.groups:
            offsets = self.axes.get("group_offset_bpm", (self.fixed.get("group_offset_bpm", 0),))
            bpms = [g.bpm for o in offsets for g in shifted(self.groups, o)]
        axis = "group_offset_bpm" if self.groups else "bpm"
        started = "amplitude" in self.axes or "amplitude" in self.fixed
        for values in itertools.product(*(self.axes[name] for name in swept_model)):
            where = dict(zip(swept_model, values, strict=True))
            params = self.model_parameters(where)
            swing = params.balance_amplitude
            if not started and not (math.isfinite(swing) and swing > 0):
                at = f" at {where}" if where else ""
                raise ParameterError(
                    f"the default start amplitude is the steady swing 2M/(pi c_theta) = {swing:g} "
                    f"rad{at} (`drive` = {params.metronome.drive:g}, `c_theta` = "
                    f"{params.metronome.c_theta:g}), so no run could start there. Give a start "
                    f"amplitude: `amplitude` (--amplitude 0.5, or amplitude = 0.5 under [fixed] "
                    f"in the grid file)."
                )
            params.metronome.check_tunable(bpms, fix=f"Narrow the `{axis}` axis.")

    @classmethod
    def from_toml(cls, path: str | Path, **overrides) -> Grid:
        """Read a grid from TOML: ``[grid]`` swept values, ``[fixed]`` fixed ones, and
        top-level ``seed``, ``preset``, ``keep_r``, ``equilibrium_window``,
        ``record_every``, ``integrator``, ``backend``, ``groups`` (e.g.
        ``["7@184", "7@184:0.5"]``). ``overrides`` replace or extend (``axes``/``fixed``
        are merged by name)."""
        path = check_input_file(path, "grid file")
        try:
            data = tomllib.loads(path.read_text())
        except OSError as error:
            raise ParameterError(f"cannot read grid file {str(path)!r}: {error}") from None
        except tomllib.TOMLDecodeError as error:
            raise ParameterError(f"grid file {str(path)!r} is not valid TOML: {error}") from None
        unknown = set(data) - {"grid", "fixed", "seed", *OPTIONS}
        if unknown:
            raise ParameterError(
                f"grid file {str(path)!r}: unknown key(s) {sorted(unknown)}; expected [grid], "
                f"[fixed], seed, {', '.join(OPTIONS)}."
            )
        axes = dict(data.get("grid", {}))
        fixed = dict(data.get("fixed", {}))
        # A parameter given on the command line replaces the file's, swept or fixed.
        new_axes = dict(overrides.pop("axes", None) or {})
        new_fixed = dict(overrides.pop("fixed", None) or {})
        for name in new_axes:
            fixed.pop(name, None)
        for name in new_fixed:
            axes.pop(name, None)
        axes.update(new_axes)
        fixed.update(new_fixed)
        options = {k: data[k] for k in ("seed", *OPTIONS) if k in data}
        options.update(overrides)
        return cls(axes=axes, fixed=fixed, **options)

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values along each swept axis, in axis order."""
        return tuple(len(values) for values in self.axes.values())

    @property
    def size(self) -> int:
        """Number of grid points."""
        return math.prod(self.shape)

    def model_parameters(self, swept: Mapping[str, Any] | None = None):
        """The resolved `ModelParameters` for the fixed changes plus ``swept`` ones."""
        changes = {k: v for k, v in self.fixed.items() if k in MODEL_PARAMETERS}
        changes.update({k: v for k, v in (swept or {}).items() if k in MODEL_PARAMETERS})
        params = get_preset(self.preset, warn=False)
        return params.with_changes(**changes) if changes else params

    def points(self) -> Iterator[PointSpec]:
        """Every grid point, in C order of the axes."""
        names = list(self.axes)
        for index in itertools.product(*(range(n) for n in self.shape)):
            coords = {name: self.axes[name][i] for name, i in zip(names, index, strict=True)}
            yield self._point(index, coords)

    def batch(self, point: PointSpec, number: int) -> PointSpec:
        """Batch ``number`` of ``point``: its runs again with new frequency draws (a seed
        of its own). Batch 0 is the point itself, so a sweep with `target_error`
        reuses the points of the same sweep without it."""
        return point if number == 0 else self._point(point.index, point.coords, number)

    def _point(self, index: tuple[int, ...], coords: dict[str, Any], batch: int = 0) -> PointSpec:
        values = {**self.fixed, **coords}
        changes = {k: v for k, v in values.items() if k in MODEL_PARAMETERS}
        if self.groups:
            groups = shifted(self.groups, values.get("group_offset_bpm", 0.0))
            values["groups"] = describe_groups(groups)  # for the seed
        kwargs = {
            "n": values.get("n"),
            "bpm": values.get("bpm"),
            "sigma_bpm": values["sigma_bpm"],
            "runs": values["runs"],
            "duration": values["duration"],
            "dt": values["dt"],
            "seed": point_seed(values["seed"], _seeded_values(values, batch)),
            **({"groups": [[g.n, g.bpm, g.sigma_bpm] for g in groups]} if self.groups else {}),
            "preset": self.preset,
            "changes": changes or None,
            "integrator": self.integrator,
            "backend": self.backend,
            "record_every": self.record_every,
            "equilibrium_window": self.equilibrium_window,
        }
        if values.get("amplitude") is not None:  # absent otherwise: earlier keys stay valid
            kwargs["amplitude"] = values["amplitude"]
        keep = "r_eq+r" if self.keep_r else "r_eq"
        return make_point(kwargs, keep=keep, index=index, coords=coords)

    def describe(self) -> dict[str, Any]:
        """Every setting as file attributes (NetCDF-safe types)."""
        attrs: dict[str, Any] = {f"fixed_{k}": _attr(v) for k, v in self.fixed.items()}
        attrs.update(
            swept=" ".join(self.axes),
            sweep_seed=self.fixed.get("seed", self.seed) if "seed" not in self.axes else "swept",
            preset=self.preset,
            keep_r=int(self.keep_r),
            integrator=self.integrator,
            backend=self.backend,
            equilibrium_window=_attr(self.equilibrium_window),
            record_every=_attr(self.record_every),
            target_error=_attr(self.target_error),
            max_runs=_attr(self.max_runs),
            metrosync_version=__version__,
        )
        if self.groups:
            attrs["groups"] = describe_groups(self.groups)
        # Resolved at the first point: parameters checked together (a forcing amplitude
        # with a swept forcing frequency) may not stand without the swept values.
        first = self.model_parameters({name: values[0] for name, values in self.axes.items()})
        unswept = {k: v for k, v in first.as_dict().items() if k not in self.axes}
        attrs.update({f"model_{k}": _attr(v) for k, v in unswept.items()})
        return attrs


def point_seed(sweep_seed: int, values: Mapping[str, Any]) -> int:
    """A 63-bit seed for one point, a pure function of the sweep seed and its values."""
    digest = hashlib.sha256(canonical_json(dict(values)).encode()).digest()
    entropy = [int(sweep_seed), int.from_bytes(digest[:16], "little")]
    return int(np.random.SeedSequence(entropy).generate_state(1, np.uint64)[0] >> np.uint64(1))


def _seeded_values(values: Mapping[str, Any], batch: int) -> dict[str, Any]:
    """What a point's seed is drawn from besides the sweep seed; a batch after the first
    adds its number (absent for batch 0, so the keys of earlier sweeps stay valid)."""
    seeded = {k: v for k, v in values.items() if k != "seed"}
    if batch:
        seeded["batch"] = batch
    return seeded


def _attr(value: Any) -> Any:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return value

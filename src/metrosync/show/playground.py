"""A playground: the model running live in a browser, in one self-contained HTML file.

Unlike `write_page`, which plays back a run computed beforehand, the playground
simulates while it is watched. Its JavaScript (``_playground/*.js``, package data)
follows the integrator's NumPy twin (`integrators.twin`) line by line: the same
equations, eqs. (eqm1)–(eqm2), the same velocity-Verlet-type step with the ±M/dt
escapement, the same tuning of L2 from a BPM (under the steady-swing tuning, with the
package's per-design spline, sent as the constants' ``steady_swing``). It runs exactly
the model terms that `metrosync.capabilities` lists for the playground;
`playground_config` refuses any other by name. Every number of the model (each preset's
metronome design and platform, the tunable BPM range, the time step) comes from this
package as JSON embedded in the page; the JavaScript holds formulas only.
``window.metrosync.run(params, steps)`` returns trajectories, so that tests can compare
the browser's physics with `metrosync.simulate(..., backend="numpy")`.

The page loads nothing: CSS and scripts are inline, the sound is synthesised, and it
opens from the file system with no server and no network. Controls: N, nominal BPM,
σ, two frequency groups, the drive M, the platform (the disk or the board on rollers),
the disk's inertia and friction or the board's mass and damping, holding the platform,
restart, pause and speed (1×–50×). The control ranges are `LIMITS`.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from importlib import resources
from pathlib import Path

from .._files import write_text
from .._version import __version__
from ..capabilities import require
from ..ensemble import MAX_DAMPING_PER_STEP
from ..errors import ParameterError, describe, shown_range
from ..model import PRESETS, ModelParameters, get_preset
from ..model.quantity import declared

#: The page's scripts, in the order they run (each uses those before it).
SCRIPTS = ("physics.js", "session.js", "view.js", "audio.js", "app.js")

#: Ranges of the page's controls: N, σ (BPM), speed (× real time), the second group's
#: offset (BPM), and the log-scale sliders for M (N m s), the disk's c_φ (kg m²/s) and
#: J (kg m²), and the board's mass (kg) and damping (kg/s). M, c_φ and the board's
#: damping also reach 0.
LIMITS = {
    "n": (1, 100),
    "sigma_bpm": (0.0, 10.0),
    "speed": (1, 50),
    "group_offset_bpm": (-20.0, 20.0),
    "drive": (1e-6, 1e-3),
    "c_phi": (1e-7, 1e-1),
    "inertia": (1e-3, 1e2),
    # From a few grams (Pantaleone's board is 58 g) to a heavy table top; a wet
    # table's damping, tens of kg/s, is inside.
    "board_mass": (1e-3, 1e2),
    "board_damping": (1e-4, 1e2),
}
#: The sliders that may also stand at 0.
_ZERO_ALLOWED = ("drive", "c_phi", "board_damping")
#: The finest time step offered: finer ones cannot keep up with 50× real time at N = 100.
MIN_DT = 1e-3
#: A period must span at least this many steps (as `metrosync.ensemble.check_time_step`).
MIN_STEPS_PER_PERIOD = 10
#: |θ| beyond which the page reports an overturned pendulum, rad (as `simulate`).
OVERTURN_ANGLE = math.pi / 2


def preset_data(params: ModelParameters) -> dict:
    """A preset as the page uses it: its constants by the package's names (SI units),
    the tunable BPM range, and its description. A pinned disk (J = ∞) is sent as the
    J(N) law plus ``held``, since JSON has no infinity."""
    constants = {**vars(params.metronome), **vars(params.platform)}
    constants["l2_bounds"] = list(constants["l2_bounds"])
    held = params.platform.rigid
    if held:
        constants["inertia"] = None
    if params.metronome.tuning == "steady-swing":
        # The page inverts the tuning as `steady_swing_l2` does, with the same spline.
        from ..model.steady_swing import steady_swing_spline  # needs scipy; loaded on use

        constants["steady_swing"] = steady_swing_spline(params.metronome)
    low, high = params.metronome.bpm_range()
    return {
        "description": params.description,
        "constants": constants,
        "bpm_range": [low, high],
        "held": held,
    }


def playground_config(
    *,
    preset: str | ModelParameters = "default",
    changes: Mapping[str, float] | None = None,
    n: int = 7,
    bpm: float = 192.0,
    sigma_bpm: float = 0.0,
    dt: float = 0.01,
    seed: int = 0,
) -> dict:
    """The JSON-ready configuration the page embeds (see the module docstring).

    Parameters
    ----------
    preset : the preset the page starts with (every named preset is offered as well).
    changes : model parameters changed by name, as in `simulate`.
    n, bpm, sigma_bpm : the start's number of metronomes, nominal BPM and spread.
    dt : the time step, s.
    seed : seed of the first start's random phases and frequencies (Restart draws anew).
    """
    params = get_preset(preset, warn=False)
    if changes:
        params = params.with_changes(**changes)
    # The page runs the model terms the capability table says it has, and no other.
    require("playground", params)
    _check_ranges(params)
    get_preset(params)  # warns if its pendulums overturn, once the values are known to fit
    presets = {name: preset_data(get_preset(name, warn=False)) for name in PRESETS}
    presets[params.name] = preset_data(params)
    start = presets[params.name]
    n = _check_count(n)
    low, high = start["bpm_range"]
    if not (isinstance(bpm, int | float) and math.isfinite(bpm) and low <= bpm <= high):
        finite = isinstance(bpm, int | float) and math.isfinite(bpm)
        _, low_text, high_text = shown_range(low, high, float(bpm) if finite else low)
        raise ParameterError(
            f"`bpm` = {describe(bpm)} is outside the tunable range [{low_text}, {high_text}] BPM "
            f"of preset {params.name!r}; choose a BPM in range."
        )
    lo, hi = LIMITS["sigma_bpm"]
    if not (isinstance(sigma_bpm, int | float) and lo <= sigma_bpm <= hi):
        raise ParameterError(
            f"`sigma_bpm` = {describe(sigma_bpm)} is outside the page's range [{lo:g}, {hi:g}] "
            f"BPM; choose a spread in range."
        )
    # The page lets BPM go up to the top of the tunable range: dt must resolve it there.
    finest = min(60.0 / p["bpm_range"][1] * 2 for p in presets.values()) / MIN_STEPS_PER_PERIOD
    if not (isinstance(dt, int | float) and math.isfinite(dt) and MIN_DT <= dt <= finest):
        raise ParameterError(
            f"`dt` = {describe(dt)} s is outside [{MIN_DT:g}, {finest:.4g}] s: coarser steps do "
            f"not resolve the fastest tunable metronome ({MIN_STEPS_PER_PERIOD} steps a period), "
            f"finer ones cannot run at 50× real time in a browser. The paper uses 0.01 s."
        )
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**32:
        raise ParameterError(f"`seed` must be an integer in [0, 2**32), got {describe(seed)}.")
    _check_damping_step(params, n, float(bpm), float(dt))
    return {
        "version": __version__,
        "dt": float(dt),
        "overturn_angle": OVERTURN_ANGLE,
        "max_damping_per_step": MAX_DAMPING_PER_STEP,
        "presets": presets,
        "start": {
            "preset": params.name,
            "n": n,
            "bpm": float(bpm),
            "sigma_bpm": float(sigma_bpm),
            "seed": seed,
            "hold": start["held"],
        },
        "limits": {k: list(v) for k, v in LIMITS.items()},
    }


def render_playground(**options) -> str:
    """The page's HTML text; ``options`` as for `playground_config`."""
    config = playground_config(**options)
    # "</" inside a script element would end it early; JSON allows "<\/" for it.
    payload = json.dumps(config, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    script = "\n".join(_asset(name) for name in SCRIPTS)
    values = {
        "CONFIG": payload,
        "SCRIPT": script,
        "VERSION": __version__,
        "DT": f"{config['dt']:g}",
    }
    # One pass, so that text in one value is never taken for another placeholder.
    return re.sub(r"@(CONFIG|SCRIPT|VERSION|DT)@", lambda m: values[m[1]], _asset("page.html"))


def write_playground(path: Path | str, **options) -> Path:
    """Write the playground page to ``path`` (atomically) and return the path.

    ``options``: ``preset``, ``changes``, ``n``, ``bpm``, ``sigma_bpm``, ``dt`` and
    ``seed``, the page's starting point (see `playground_config`); every one can be
    changed on the page.
    """
    return write_text(render_playground(**options), path)


def _asset(name: str) -> str:
    return resources.files(__package__).joinpath("_playground", name).read_text(encoding="utf-8")


def _check_count(n) -> int:
    lo, hi = LIMITS["n"]
    if isinstance(n, bool) or not isinstance(n, int) or not lo <= n <= hi:
        raise ParameterError(
            f"`n` must be a whole number of metronomes in [{lo}, {hi}], got {describe(n)}."
        )
    return n


def _check_ranges(params: ModelParameters) -> None:
    """Refuse a parameter the page's sliders could not show (and would silently move)."""
    if params.metronome.w2 == 0:
        raise ParameterError(
            "`w2` = 0: the playground tunes each metronome by its sliding weight, and there "
            "is none; give `w2` > 0 kg."
        )
    platform = params.platform
    values = {"drive": params.metronome.drive}
    if platform.platform == "board":  # the disk's own values are then unused defaults
        values.update(board_mass=platform.board_mass, board_damping=platform.board_damping)
    else:
        values["c_phi"] = platform.c_phi
        if platform.inertia is not None and not platform.rigid:
            values["inertia"] = platform.inertia
    for name, value in values.items():
        lo, hi = LIMITS[name]
        zero = name in _ZERO_ALLOWED
        if not (zero and value == 0) and not lo <= value <= hi:
            raise ParameterError(
                f"`{name}` = {value!r} is outside the playground's slider range "
                f"[{lo:g}, {hi:g}]{' (or 0)' if zero else ''}; choose a value in it."
            )


def damping_rate(params: ModelParameters, n: int, bpm: float) -> float:
    """The platform's viscous damping rate c/D₀, 1/s, for ``n`` metronomes tuned to
    ``bpm`` (D₀ the coefficient of φ̈ in eq. (eqm1) with the pendulums hanging); 0 for a
    held disk. The page computes the same (`Physics.buildSystem`'s ``dampingRate``)."""
    import numpy as np

    from ..ensemble import damping_rate as rate_of
    from ..model.system import system_arrays
    from ..model.tuning import l2_for_bpm

    design = params.metronome
    l2 = np.full((1, n), l2_for_bpm(design, bpm, tuning=design.tuning))
    return rate_of(system_arrays(params, l2)[0])


def _check_damping_step(params: ModelParameters, n: int, bpm: float, dt: float) -> None:
    """Refuse a start whose platform damping the step cannot follow (it would diverge)."""
    rate = damping_rate(params, n, bpm)
    if rate * dt <= MAX_DAMPING_PER_STEP:
        return
    platform = params.platform
    name = platform.damping_parameter
    unit, value = declared(platform, name), getattr(platform, name)
    fixes = f"lower it to at most {value * MAX_DAMPING_PER_STEP / (rate * dt):.3g} {unit}"
    finer = MAX_DAMPING_PER_STEP / rate
    if finer >= MIN_DT:
        fixes += f", or give `dt` <= {finer:.3g} s"
    raise ParameterError(
        f"`{name}` = {value!r} {unit} damps the {platform.platform} at {rate:.3g} /s, "
        f"too fast for the step `dt` = {dt:g} s (the page's step needs rate x dt <= "
        f"{MAX_DAMPING_PER_STEP:g}, or it diverges): {fixes}."
    )

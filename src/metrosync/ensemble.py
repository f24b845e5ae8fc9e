"""Ensembles: B independent runs of N metronomes, their constants and initial state.

Contract: `build_ensemble` turns user-level choices (N, nominal BPM, spread σ in BPM,
or groups of their own N, BPM and σ (`metrosync.groups`), explicit frequencies or
metronomes, initial conditions, seed) into an `Ensemble`:
(B, N) slider positions and the `SystemArrays` every integrator consumes, plus the
initial state. Everything random comes from one seed through independent streams
(frequencies, phases), so changing σ never changes the initial phases.

In the model the metronomes differ only through their slider position L2⁽ⁱ⁾ (paper
§7): a drawn natural frequency is realised by tuning L2 to it. The constants
themselves come from `model.system.system_arrays`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ._words import plural
from .equations import effective_inertia
from .errors import ParameterError, describe
from .groups import Group, as_groups, group_bounds
from .model import (
    Metronome,
    MetronomeDesign,
    ModelParameters,
    SystemArrays,
    omega_to_bpm,
    system_arrays,
)
from .model.system import PER_METRONOME

#: The coarsest step accepted: a period must span at least this many steps.
MIN_STEPS_PER_PERIOD = 10


@dataclass(frozen=True)
class Ensemble:
    """Constants and initial conditions of B runs × N metronomes.

    l2, frequency_bpm, theta0, theta_dot0 : (B, N).   phi0, phi_dot0 : (B,).
    disk_inertia : (B,) the platform's J (without the R²Σm term).
    groups : the groups, with their spreads resolved, when built from groups; else ().
    """

    params: ModelParameters
    system: SystemArrays
    l2: np.ndarray
    frequency_bpm: np.ndarray
    disk_inertia: np.ndarray
    theta0: np.ndarray
    theta_dot0: np.ndarray
    phi0: np.ndarray
    phi_dot0: np.ndarray
    groups: tuple[Group, ...] = ()

    @property
    def runs(self) -> int:
        return self.l2.shape[0]

    @property
    def group_start(self) -> np.ndarray:
        """(G + 1,) bounds of the groups along the metronomes; one group if none."""
        return group_bounds(self.groups) if self.groups else np.array([0, self.n], np.int64)

    @property
    def n(self) -> int:
        return self.l2.shape[1]

    def shortest_period(self) -> float:
        return float(2 * np.pi / np.max(self.system.omega))


def build_ensemble(
    n: int | None = 7,
    bpm: float | None = 192.0,
    *,
    params: ModelParameters,
    sigma_bpm: float = 0.0,
    runs: int = 1,
    seed: int | None = 0,
    frequencies_bpm: Sequence[float] | np.ndarray | None = None,
    metronomes: Sequence[Metronome] | None = None,
    amplitude: float | None = None,
    theta0: Sequence[float] | np.ndarray | None = None,
    theta_dot0: Sequence[float] | np.ndarray | None = None,
    phi_dot0: float = 0.0,
    groups: Sequence[Group | tuple] | None = None,
) -> Ensemble:
    """Build the constants and initial state of an ensemble.

    Parameters
    ----------
    n, bpm : number of metronomes and their nominal beat frequency (BPM).
    params : the model's fixed parameters (a preset, possibly changed).
    sigma_bpm : standard deviation of the natural frequencies, BPM; each run draws its
        own N frequencies from Normal(bpm, sigma_bpm).
    runs : B, the number of independent runs.
    seed : seed of every random choice.
    frequencies_bpm : explicit natural frequencies, shape (N,) or (B, N); replaces the
        draw (``bpm`` is not used; ``n`` must be N or None, ``sigma_bpm`` 0).
    metronomes : explicit, fully specified metronomes (shape (N,)): every parameter
        per metronome, the same in every run (``n`` must be N or None, ``sigma_bpm`` 0).
    amplitude : swing amplitude (rad) of the random-phase start; default the
        energy-balance amplitude 2M/(π c_θ) (docs/model.md §6.5).
    theta0, theta_dot0 : explicit initial angles and angular velocities, (N,) or (B, N).
    phi_dot0 : initial angular velocity of the disk.
    groups : groups of metronomes, each ``(n, bpm)`` or ``(n, bpm, sigma_bpm)``, laid
        out one after the other (see `metrosync.groups`); replaces ``n`` and ``bpm``,
        and ``sigma_bpm`` is the spread of the groups that give none. Each run draws
        group g's frequencies from Normal(bpm_g, sigma_g), from the same stream as an
        ungrouped draw: groups of equal BPM and σ give exactly the ensemble of their
        total N.
    """
    runs = _require_count("runs", runs)
    if seed is not None and (not isinstance(seed, int | np.integer) or seed < 0):
        raise ParameterError(
            f"`seed` must be a non-negative integer or None, got {describe(seed)}."
        )
    freq_rng, phase_rng = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(2))
    if (
        isinstance(sigma_bpm, bool)
        or not isinstance(sigma_bpm, int | float | np.integer | np.floating)
        or not (math.isfinite(sigma_bpm) and sigma_bpm >= 0)
    ):
        raise ParameterError(
            f"`sigma_bpm` must be >= 0 BPM, got {describe(sigma_bpm)}; give a number "
            f"(0 tunes every metronome to the nominal `bpm`)."
        )
    design = params.metronome
    per_metronome = None
    if groups is not None:
        groups, l2 = _grouped(
            design, groups, sigma_bpm, freq_rng, runs, metronomes, frequencies_bpm
        )
    elif metronomes is not None:
        l2, per_metronome = _explicit(metronomes, n, sigma_bpm, runs)
    else:
        freq = _frequencies(design, n, bpm, sigma_bpm, freq_rng, runs, frequencies_bpm)
        l2 = np.asarray(design.l2_for_bpm(freq), dtype=float).reshape(freq.shape)
    system, disk = system_arrays(params, l2, per_metronome)
    phases = phase_rng.uniform(0.0, 2 * np.pi, size=l2.shape)
    th0, thd0 = _start(params, system.omega, phases, amplitude, theta0, theta_dot0)
    if not math.isfinite(phi_dot0):
        raise ParameterError(f"`phi_dot0` must be finite, got {phi_dot0!r}.")
    return Ensemble(
        params=params,
        system=system,
        l2=l2,
        frequency_bpm=omega_to_bpm(system.omega),
        disk_inertia=disk,
        theta0=th0,
        theta_dot0=thd0,
        phi0=np.zeros(runs),
        phi_dot0=np.full(runs, float(phi_dot0)),
        groups=tuple(groups) if groups is not None else (),
    )


def _grouped(
    design: MetronomeDesign, groups, sigma_bpm, freq_rng, runs: int, metronomes, frequencies_bpm
) -> tuple[tuple[Group, ...], np.ndarray]:
    """The groups, their spreads resolved, and the (B, N) slider positions of their
    drawn frequencies."""
    if metronomes is not None or frequencies_bpm is not None:
        given = "`metronomes`" if metronomes is not None else "`frequencies_bpm`"
        raise ParameterError(
            f"give `groups` or {given}, not both: each sets the metronomes' frequencies."
        )
    if not (math.isfinite(sigma_bpm) and sigma_bpm >= 0):
        raise ParameterError(f"`sigma_bpm` must be >= 0 BPM, got {sigma_bpm!r}.")
    groups = as_groups(groups, sigma_bpm)
    for k, g in enumerate(groups):
        design.check_tunable(
            g.bpm,
            what=f"`groups` entry {k} ({g.label()}) has BPM {{value}}, which",
            fix="Move that group's BPM into the range.",
        )
    n = sum(g.n for g in groups)
    loc = np.repeat([g.bpm for g in groups], [g.n for g in groups])
    scale = np.repeat([g.sigma_bpm for g in groups], [g.n for g in groups])
    # One draw over all N, as for a single group, so equal groups are one group.
    freq = freq_rng.normal(loc, scale, size=(runs, n))
    for k, (g, lo) in enumerate(zip(groups, group_bounds(groups), strict=False)):
        design.check_tunable(
            freq[:, lo : lo + g.n],
            what=f"with `groups` entry {k} ({g.label()}), a drawn natural frequency "
            "({value} BPM)",
            fix="Lower that group's sigma or move its BPM inward.",
        )
    return groups, np.asarray(design.l2_for_bpm(freq), dtype=float).reshape(runs, n)


def _explicit(metronomes, n, sigma_bpm, runs: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The (B, N) slider positions of explicit metronomes, and each one's own design
    parameters (`model.system.PER_METRONOME`), the same in every run."""
    metronomes = list(metronomes)
    if not metronomes:
        raise ParameterError("`metronomes` is empty: give at least one Metronome.")
    _require_explicit("metronomes", len(metronomes), n, sigma_bpm)
    n = len(metronomes)
    l2 = np.broadcast_to([m.l2 for m in metronomes], (runs, n)).copy()
    per_metronome = {
        name: np.broadcast_to([getattr(m.design, name) for m in metronomes], (runs, n))
        for name in PER_METRONOME
    }
    return l2, per_metronome


def _frequencies(
    design: MetronomeDesign, n, bpm, sigma_bpm, freq_rng, runs: int, frequencies_bpm
) -> np.ndarray:
    """The (B, N) natural frequencies: ``frequencies_bpm`` as given, or drawn from
    Normal(bpm, sigma_bpm)."""
    if frequencies_bpm is not None:
        freq = _per_metronome("frequencies_bpm", frequencies_bpm, runs, None)
        _require_explicit("frequencies_bpm", freq.shape[1], n, sigma_bpm)
        written = np.asarray(frequencies_bpm, dtype=float)  # so an entry is named as written
        design.check_tunable(written, name="frequencies_bpm", index=True)
        return freq
    n = _require_count("n", n)
    if bpm is None or not math.isfinite(float(bpm)):
        raise ParameterError(f"`bpm` must be a finite number, got {bpm!r}.")
    design.check_tunable(bpm)
    freq = freq_rng.normal(float(bpm), float(sigma_bpm), size=(runs, n))
    design.check_tunable(
        freq,
        what=f"with `sigma_bpm` = {sigma_bpm!r}, a drawn natural frequency ({{value}} BPM)",
        fix="Lower `sigma_bpm` or move `bpm` inward.",
    )
    return freq


def _start(
    params: ModelParameters, omega: np.ndarray, phases: np.ndarray, amplitude, theta0, theta_dot0
) -> tuple[np.ndarray, np.ndarray]:
    """The (B, N) initial angles and angular velocities: ``theta0`` and ``theta_dot0``
    as given, or a swing of ``amplitude`` (default the energy-balance amplitude) at
    the random ``phases``."""
    runs, n = phases.shape
    if theta0 is not None:
        th0 = _per_metronome("theta0", theta0, runs, n)
        thd0 = (
            _per_metronome("theta_dot0", theta_dot0, runs, n)
            if theta_dot0 is not None
            else np.zeros((runs, n))
        )
        return th0, thd0
    if theta_dot0 is not None:
        raise ParameterError("`theta_dot0` was given without `theta0`: give both, or neither.")
    amp = params.balance_amplitude if amplitude is None else amplitude
    if amplitude is None and amp == 0:
        raise ParameterError(
            "the default start amplitude is the energy-balance amplitude 2M/(pi c_theta), "
            "which is 0 without drive (`drive` = 0): every pendulum would start at rest. "
            "Give `amplitude` (--amplitude) or `theta0` (--theta0)."
        )
    if not (math.isfinite(amp) and amp >= 0):
        raise ParameterError(
            f"`amplitude` must be a finite angle >= 0 rad, got {amp!r}"
            + (
                " (no friction: give `amplitude` or `theta0` explicitly)"
                if amplitude is None
                else ""
            )
            + "."
        )
    return amp * np.cos(phases), -amp * omega * np.sin(phases)


def check_time_step(dt: float, ensemble: Ensemble) -> None:
    """Reject a dt too coarse to resolve the fastest metronome's period."""
    period = ensemble.shortest_period()
    if not (math.isfinite(dt) and 0 < dt <= period / MIN_STEPS_PER_PERIOD):
        raise ParameterError(
            f"`dt` = {dt!r} s does not resolve the shortest period {period:.4f} s: it needs "
            f"0 < dt <= period/{MIN_STEPS_PER_PERIOD} = {period / MIN_STEPS_PER_PERIOD:.4g} s."
        )


#: The most a fixed step may be of the platform's damping time: the schemes take the
#: damping force explicitly, and beyond about 1.2 (measured on the board at dt = 0.01 s)
#: they diverge.
MAX_DAMPING_PER_STEP = 1.0


def damping_rate(system) -> float:
    """The fastest viscous damping rate c/D₀ of a platform in ``system`` (`SystemArrays`),
    1/s, D₀ the coefficient of φ̈ in eq. (eqm1) with the pendulums hanging; 0 when
    every platform is held."""
    flat = system.one_coordinate()
    if flat is None:  # several coordinates: each coordinate's damping by its D₀'s diagonal
        d0 = np.diagonal(effective_inertia(system, np.zeros(system.shape)), axis1=1, axis2=2)
        free = ~np.isinf(d0)
        return float(np.max(system.c_phi[free] / d0[free])) if free.any() else 0.0
    free = ~np.isinf(flat.total_inertia)
    if not free.any():
        return 0.0
    d0 = flat.total_inertia - flat.lever**2 * np.sum(system.mh**2 / system.inertia, axis=-1)
    return float(np.max(flat.c_phi[free] / d0[free]))


def check_damping_step(dt: float, ensemble: Ensemble) -> None:
    """Reject a fixed step too long for the platform's viscous damping rate c/D₀ (D₀
    the effective inertia of eq. (eqm1) with the pendulums hanging), which a fixed-step
    scheme would turn into a divergence."""
    rate = damping_rate(ensemble.system)
    if rate * dt > MAX_DAMPING_PER_STEP:
        platform = ensemble.params.platform
        name = platform.damping_parameter
        raise ParameterError(
            f"`{name}` = {getattr(platform, name)!r} damps the {platform.platform} at "
            f"{rate:.3g} /s, too fast for the step `dt` = {dt!r} s (a fixed-step scheme needs "
            f"rate x dt <= {MAX_DAMPING_PER_STEP:g}): use dt <= "
            f"{MAX_DAMPING_PER_STEP / rate:.3g} s, or integrator='exact'."
        )


def _require_count(name: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise ParameterError(f"`{name}` must be an integer >= 1, got {describe(value)}.")
    return int(value)


def _require_explicit(name: str, count: int, n, sigma_bpm) -> None:
    """Explicit metronomes fix N and every frequency: refuse an `n` or a spread that
    says otherwise rather than ignore it."""
    if n is not None and n != count:
        raise ParameterError(
            f"`n` = {n!r} but `{name}` gives {plural(count, 'metronome')}; pass n={count} or "
            f"n=None."
        )
    if sigma_bpm:
        raise ParameterError(
            f"`sigma_bpm` = {sigma_bpm!r} has no effect with `{name}`, which fixes every "
            f"frequency; drop it (or give the spread in the frequencies)."
        )


def _per_metronome(name: str, values, runs: int, n: int | None) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1:
        arr = np.broadcast_to(arr, (runs, arr.shape[0]))
    if arr.ndim != 2 or arr.shape[0] != runs or (n is not None and arr.shape[1] != n):
        want = f"({n},) or ({runs}, {n})" if n is not None else f"(N,) or ({runs}, N)"
        raise ParameterError(f"`{name}` must have shape {want}, got shape {np.shape(values)}.")
    if arr.shape[1] < 1:
        raise ParameterError(f"`{name}` is empty: give one value per metronome.")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"`{name}` must be finite, got {describe(values)}.")
    return np.array(arr)

"""The constants of an ensemble as arrays: `SystemArrays` and its one builder.

Contract: `system_arrays` turns the model's parameters and the (B, N) slider positions
(and, for explicitly given metronomes, per-metronome design values) into the per-run
(B,) and per-metronome (B, N) constants that every integrator consumes. Every
constant of a model term is computed here and nowhere else; the compiled kernels
receive all of `SystemArrays` (`integrators._abi.Constants`), so a new term adds its
field and its line here, its force to `integrators._physics` and to `equations`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .metronome import bpm_to_omega, centre_of_mass, natural_omega, pendulum_inertia
from .presets import ModelParameters

#: The design values that may differ per metronome (`MetronomeDesign` fields).
PER_METRONOME = ("w1", "w2", "l1", "c_theta", "drive", "g", "escapement_offset")


@dataclass(frozen=True)
class SystemArrays:
    """Per-run and per-metronome constants of an ensemble, in SI units.

    Shapes: per-metronome fields (B, N), per-run fields (B,).

    mh : m_i h_i.   mgh : m_i g h_i.   inertia : m_i h_i² + J_i.
    c_theta, drive : friction c_θ and escapement impulse M of each metronome.
    omega : small-amplitude natural frequency on a rigid support, rad/s.
    lever : ℓ, how far a pivot moves per unit of the platform's coordinate φ: the
        disk's radius R, or 1 m for the board (`model.platform`).
    c_phi : the platform's viscous damping (the disk's c_φ, the board's damping).
    total_inertia : J_p + ℓ² Σ m_i (the coefficient of φ̈ in eq. (metron2a)); ``inf``
        pins the platform.

    Beyond the paper (each defaults to "off" when not given, so that a caller that
    builds the arrays by hand need not know them):
    forcing_amplitude, forcing_omega : (B,) A (N m on the disk, N on the board) and
        Ω (rad/s) of the external drive A sin(Ω t) on the platform; A = 0 switches it off.
    escapement_offset : (B, N) angle δ_i at which metronome i's escapement acts, rad.
    escapement_reaction : (B,) 1.0 when the escapement's reaction −Σ𝕄_i acts on the
        disk (the paper), 0.0 when it does not (and always on the board).
    dry_friction : (B,) the platform's Coulomb friction, N m on the disk
        (``disk_dry_friction``), N on the board (``board_dry_friction``); 0 for none.
    """

    mh: np.ndarray
    mgh: np.ndarray
    inertia: np.ndarray
    c_theta: np.ndarray
    drive: np.ndarray
    omega: np.ndarray
    lever: np.ndarray
    c_phi: np.ndarray
    total_inertia: np.ndarray
    forcing_amplitude: np.ndarray | None = None
    forcing_omega: np.ndarray | None = None
    escapement_offset: np.ndarray | None = None
    escapement_reaction: np.ndarray | None = None
    dry_friction: np.ndarray | None = None

    def __post_init__(self) -> None:
        runs = np.shape(self.lever)
        off = {
            "forcing_amplitude": np.zeros(runs),
            "forcing_omega": np.zeros(runs),
            "escapement_offset": np.zeros(np.shape(self.mh)),
            "escapement_reaction": np.ones(runs),
            "dry_friction": np.zeros(runs),
        }
        for name, value in off.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)

    @property
    def shape(self) -> tuple[int, int]:
        return self.mh.shape  # type: ignore[return-value]

    def run(self, b: int) -> SystemArrays:
        """The constants of run ``b`` alone, as a batch of one."""
        return SystemArrays(**{k: v[b : b + 1] for k, v in vars(self).items()})


def system_arrays(
    params: ModelParameters,
    l2: np.ndarray,
    per_metronome: Mapping[str, np.ndarray] | None = None,
) -> tuple[SystemArrays, np.ndarray]:
    """The constants of B runs × N metronomes.

    Parameters
    ----------
    params : the model's parameters (design and platform).
    l2 : (B, N) slider positions, m.
    per_metronome : (B, N) arrays of the `PER_METRONOME` design values, for metronomes
        given one by one; default ``params.metronome``'s values for every metronome.

    Returns
    -------
    The `SystemArrays`, and the platform's own inertia J_p, (B,) (kg m² for the disk,
    kg for the board).
    """
    runs, n = l2.shape
    design = params.metronome
    values = {
        name: np.broadcast_to(
            per_metronome[name] if per_metronome is not None else getattr(design, name),
            (runs, n),
        )
        for name in PER_METRONOME
    }
    w1, w2, l1, g = values["w1"], values["w2"], values["l1"], values["g"]
    h = centre_of_mass(w1, w2, l1, l2)
    if np.any(h <= 0):
        raise ParameterError(
            "a metronome has h <= 0 (its centre of mass is above the pivot, so the pendulum "
            "is inverted); lower its slider `l2` below w1*l1/w2."
        )
    mass = w1 + w2
    terms = params.platform.terms(n)
    own = np.full(runs, terms.own_inertia)
    lever = np.full(runs, terms.lever)
    system = SystemArrays(
        mh=mass * h,
        mgh=mass * g * h,
        inertia=pendulum_inertia(w1, w2, l1, l2),
        c_theta=np.array(values["c_theta"], dtype=float),
        drive=np.array(values["drive"], dtype=float),
        omega=natural_omega(w1, w2, l1, l2, g),
        lever=lever,
        c_phi=np.full(runs, terms.damping),
        total_inertia=own + lever**2 * mass.sum(axis=1),
        forcing_amplitude=np.full(runs, terms.forcing_amplitude),
        forcing_omega=np.full(runs, float(bpm_to_omega(params.platform.forcing_bpm))),
        escapement_offset=np.array(values["escapement_offset"], dtype=float),
        escapement_reaction=np.full(runs, 1.0 if terms.escapement_reaction else 0.0),
        dry_friction=np.full(runs, terms.dry_friction),
    )
    return system, own

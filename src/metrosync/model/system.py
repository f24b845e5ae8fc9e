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
from types import SimpleNamespace

import numpy as np

from ..errors import ParameterError
from .metronome import bpm_to_omega, centre_of_mass, natural_omega, pendulum_inertia
from .presets import ModelParameters

#: The design values that may differ per metronome (`MetronomeDesign` fields).
PER_METRONOME = ("w1", "w2", "l1", "c_theta", "drive", "g", "escapement_offset")


#: The platform's fields with one value per coordinate, (B, P).
PER_COORDINATE = ("c_phi", "forcing_amplitude", "escapement_reaction")


@dataclass(frozen=True)
class SystemArrays:
    """Per-run and per-metronome constants of an ensemble, in SI units.

    Shapes: per-metronome fields (B, N), per-run fields (B,); the platform has P
    generalized coordinates φ (P = 1 for the disk and the board), and its fields carry
    that axis: ``lever`` (B, N, P), ``total_inertia`` (B, P, P), ``c_phi``,
    ``forcing_amplitude`` and ``escapement_reaction`` (B, P). A caller that builds the
    arrays by hand for a one-coordinate platform may give these per run, (B,): they are
    stored with the coordinate axis (`one_coordinate` gives them back per run).

    mh : m_i h_i.   mgh : m_i g h_i.   inertia : m_i h_i² + J_i.
    c_theta, drive : friction c_θ and escapement impulse M of each metronome.
    omega : small-amplitude natural frequency on a rigid support, rad/s.
    lever : ℓ_i, how far metronome i's pivot moves, along its swing, per unit of each
        of the platform's coordinates: the disk's radius R, or 1 m for the board
        (`model.platform`). It is per metronome because on a platform with several
        coordinates each metronome may swing along its own direction; on the disk and
        the board every metronome's is the same.
    c_phi : the platform's viscous damping of each coordinate (the disk's c_φ, the
        board's damping), (B, P).
    total_inertia : M = J_p + Σ_i m_i ℓ_i ℓ_iᵀ (the coefficient of φ̈ in eq.
        (metron2a)), (B, P, P); ``inf`` pins the platform.

    Beyond the paper (each defaults to "off" when not given, so that a caller that
    builds the arrays by hand need not know them):
    forcing_amplitude, forcing_omega : A (B, P) (N m on the disk, N on the board), on
        each coordinate, and Ω (B,) (rad/s) of the external drive A sin(Ω t) on the
        platform; A = 0 switches it off.
    escapement_offset : (B, N) angle δ_i at which metronome i's escapement acts, rad.
    escapement_reaction : (B, P) how much of the escapement's reaction −Σ𝕄_i acts on
        each coordinate: 1.0 on the disk (the paper), 0.0 when switched off (and always
        on the board, whose coordinate does not turn the metronomes' cases).
    dry_friction : (B,) the platform's Coulomb friction, N m on the disk
        (``disk_dry_friction``), N on the board (``board_dry_friction``); 0 for none.
        It is a law of one coordinate: a platform with P > 1 has none.
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
        runs, n = np.shape(self.mh)
        lever = np.asarray(self.lever, dtype=float)
        if lever.ndim == 1:  # one coordinate, given per run
            lever = np.repeat(lever[:, None, None], n, axis=1)
        object.__setattr__(self, "lever", lever)
        p = lever.shape[-1]
        off = {
            "forcing_amplitude": np.zeros((runs, p)),
            "forcing_omega": np.zeros(runs),
            "escapement_offset": np.zeros((runs, n)),
            "escapement_reaction": np.ones((runs, p)),
            "dry_friction": np.zeros(runs),
        }
        for name, value in off.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)
        for name in PER_COORDINATE:
            value = np.asarray(getattr(self, name), dtype=float)
            object.__setattr__(self, name, value[:, None] if value.ndim == 1 else value)
        inertia = np.asarray(self.total_inertia, dtype=float)
        object.__setattr__(
            self, "total_inertia", inertia[:, None, None] if inertia.ndim == 1 else inertia
        )
        if p > 1 and np.any(np.asarray(self.dry_friction) > 0):
            raise ParameterError(
                f"`dry_friction` > 0 on a platform with {p} coordinates: dry friction is a "
                "law of one coordinate; a platform with more than one has none."
            )

    @property
    def coordinates(self) -> int:
        """P, the number of the platform's generalized coordinates."""
        return self.lever.shape[-1]

    def one_coordinate(self):
        """The constants of a one-coordinate platform whose metronomes all have the same
        lever, with the platform's fields per run, (B,), as eqs. (eqm1)–(eqm2) read
        them (a namespace with this class's field names); None for any other platform."""
        if self.coordinates != 1:
            return None
        lever = self.lever[:, 0, 0]
        if not np.all(self.lever[:, :, 0] == lever[:, None]):
            return None
        flat = dict(vars(self))
        flat.update({name: flat[name][:, 0] for name in PER_COORDINATE})
        flat["lever"] = lever
        flat["total_inertia"] = self.total_inertia[:, 0, 0]
        return SimpleNamespace(**flat)

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

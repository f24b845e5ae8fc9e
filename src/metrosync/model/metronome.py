"""One metronome: a physical pendulum with a fixed and a sliding weight (paper §4–5).

The bob is a massless rod with weight ``w1`` at ``L1`` below the pivot and the sliding
weight ``w2`` at ``L2`` above it. Following the paper,

    m = w1 + w2,   h = (w1 L1 - w2 L2) / m,   J_i = w1 L1² + w2 L2²,

and the inertia that multiplies θ̈ in eq. (metron2) is ``m h² + J_i``. The paper calls
``J_i`` the moment "relative to the centre of mass" but computes it about the pivot;
we keep the paper's expression as written (docs/model.md §6.7).

These quantities are computed in one place, by array functions (`centre_of_mass`,
`pivot_moment`, `pendulum_inertia`, `natural_omega`) that take scalars or arrays:
`Metronome`'s properties call them for one metronome, `model.system` for a whole
ensemble. `MetronomeDesign.check_tunable` is the one check (and message) that a BPM
lies in the range the slider can reach.

Tuning (docs/model.md §6.1–6.3): one beat is half a period, so
ω = π·BPM/60. A design's ``tuning`` says how a nominal BPM becomes a slider position:

``"small-amplitude"`` (the default) inverts the model's own small-amplitude frequency on
    a rigid support, ω² = m g h / (m h² + J_i), a quadratic in ``L2`` solved in closed
    form; a metronome tuned to "192 BPM" then ticks about 184.7 times a minute at its
    steady swing of 0.76 rad.
``"steady-swing"`` puts the *tick rate at the steady swing* on the nominal BPM, as a real
    metronome's marking does (`metrosync.model.steady_swing`, solved once per design and
    cached); it needs friction and a drive that does not overturn.

`metrosync.model.tuning` knows the tunings by name (`TUNINGS`, `l2_for_bpm`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ParameterError, describe, require_finite, shown_range
from . import tuning as tunings
from .quantity import (
    LOWER_HALF,
    NON_NEGATIVE,
    POSITIVE,
    check_quantities,
    declared,
    documented,
    quantity,
)
from .tuning import TUNINGS

STANDARD_GRAVITY = 9.81  # m/s², the value used throughout the paper's era of models


def bpm_to_omega(bpm):
    """Angular frequency (rad/s) of a metronome beating ``bpm`` beats per minute.

    A metronome ticks twice per period, so ω = 2π·(BPM/2)/60 = π·BPM/60.
    """
    return np.pi * np.asarray(bpm, dtype=float) / 60.0


def omega_to_bpm(omega):
    """Inverse of `bpm_to_omega`."""
    return 60.0 * np.asarray(omega, dtype=float) / np.pi


def centre_of_mass(w1, w2, l1, l2):
    """h = (w1 L1 − w2 L2) / (w1 + w2): pivot to centre-of-mass distance, m (paper §4).
    Scalars or arrays that broadcast."""
    return (w1 * l1 - w2 * l2) / (w1 + w2)


def pivot_moment(w1, w2, l1, l2):
    """The paper's J_i = w1 L1² + w2 L2², kg m²."""
    return w1 * l1**2 + w2 * l2**2


def pendulum_inertia(w1, w2, l1, l2):
    """m h² + J_i, the coefficient of θ̈ in eq. (metron2), kg m²."""
    return (w1 + w2) * centre_of_mass(w1, w2, l1, l2) ** 2 + pivot_moment(w1, w2, l1, l2)


def natural_omega(w1, w2, l1, l2, g):
    """Small-amplitude angular frequency on a rigid support, ω = √(m g h / (m h² + J_i)),
    rad/s. Needs h > 0."""
    h = centre_of_mass(w1, w2, l1, l2)
    return np.sqrt((w1 + w2) * g * h / pendulum_inertia(w1, w2, l1, l2))


@documented
@dataclass(frozen=True)
class MetronomeDesign:
    """Everything about a metronome except where its sliding weight sits.

    Parameters (SI units, each declared on its field and listed below)
    ------------------------------------------------------------------
    w1, w2 : fixed and sliding weight.
    l1 : distance of ``w1`` below the pivot.
    c_theta : viscous friction of the pivot.
    drive : angular momentum ``M`` given at each zero crossing by the escapement.
    l2_bounds : the slider's reach on the rod (low, high), 0 <= low < high; it bounds
        the tunable BPM range.
    g : gravitational acceleration.
    escapement_offset : the angle δ at which the escapement gives its impulse
        (paper: 0, the vertical). A metronome "out of beat" has δ ≠ 0: it is kicked
        where θ crosses δ, so tick and tock alternate short and long; real metronomes
        are often a few per cent of the swing out.
    tuning : how a nominal BPM becomes ``L2``, one of `TUNINGS` (module docstring).
    """

    w1: float = quantity(0.025, unit="kg", bounds=POSITIVE)
    w2: float = quantity(0.0069, unit="kg", bounds=NON_NEGATIVE)
    l1: float = quantity(0.0358, unit="m", bounds=POSITIVE)
    c_theta: float = quantity(5e-5, unit="kg m²/s", bounds=NON_NEGATIVE)
    drive: float = quantity(6e-5, unit="N m s", bounds=NON_NEGATIVE)
    #: Checked as a pair in `__post_init__`: 0 <= low < high, short of inverting.
    l2_bounds: tuple[float, float] = quantity((0.0, 0.1), unit="m")
    g: float = quantity(STANDARD_GRAVITY, unit="m/s²", bounds=POSITIVE)
    escapement_offset: float = quantity(
        0.0,
        unit="rad",
        bounds=LOWER_HALF,
        why="the escapement acts on the lower half of the swing. A metronome a few per cent "
        "out of beat has an offset of a few hundredths of a radian",
    )
    tuning: str = quantity("small-amplitude", choices=TUNINGS)

    def __post_init__(self) -> None:
        tunings.check_tuning(self.tuning)
        check_quantities(self)  # w1 to escapement_offset, as declared above
        unit = declared(self, "l2_bounds")
        lo, hi = (require_finite("l2_bounds", b) for b in self.l2_bounds)
        if not 0 <= lo < hi:
            raise ParameterError(
                f"`l2_bounds` must satisfy 0 <= low < high, got {self.l2_bounds!r}."
            )
        if self.w2 > 0 and hi >= self.w1 * self.l1 / self.w2:
            limit = self.w1 * self.l1 / self.w2
            raise ParameterError(
                f"`l2_bounds` upper end {hi!r} {unit} reaches the point where h <= 0 "
                f"(L2 >= w1*L1/w2 = {limit:.5f} {unit}): the pendulum would be inverted. "
                f"Use an upper bound below {limit:.5f} {unit}."
            )

    @property
    def mass(self) -> float:
        return self.w1 + self.w2

    def with_l2(self, l2: float) -> Metronome:
        return Metronome(design=self, l2=l2)

    def bpm_range(self) -> tuple[float, float]:
        """Lowest and highest nominal BPM the slider can tune to, under `tuning`."""
        return tunings.bpm_range(self)

    def small_amplitude_range(self) -> tuple[float, float]:
        """Lowest and highest small-amplitude frequency (BPM) the slider reaches."""
        lo, hi = self.l2_bounds
        return (float(self.with_l2(hi).natural_bpm), float(self.with_l2(lo).natural_bpm))

    def out_of_range(self, name: str, bpm: float) -> str:
        """The message for ``bpm`` (given as ``name``) outside `bpm_range`, with a fix
        that works: the `l2_bounds` that reach it, or why no slider position does."""
        low, high = self.bpm_range()
        lo, hi = self.l2_bounds
        shown, low_text, high_text = shown_range(low, high, bpm)
        text = (
            f"`{name}` = {shown} is outside the tunable range [{low_text}, {high_text}] BPM "
            f"of this metronome design (slider L2 in {self.l2_bounds} m). Choose a BPM in range"
        )
        if bpm > high and lo == 0:
            # The slider at the pivot is the fastest setting: no bounds reach further.
            return text + (
                f"; no slider position beats faster than {high_text} BPM (L2 = 0), so a faster "
                f"metronome needs a shorter rod `l1`."
            )
        inverted = self.w1 * self.l1 / self.w2 if self.w2 > 0 else math.inf
        wide = replace(self, l2_bounds=(0.0, min(inverted * (1 - 1e-9), 1e3)))
        wide_low, wide_high = wide.bpm_range()
        if not wide_low <= bpm <= wide_high:
            # Asking `wide` to tune to it would ask this question again, forever.
            return text + (
                f"; no slider position reaches it (L2 from 0 to just short of the inverted "
                f"pendulum, {wide.l2_bounds[1]:.4g} m, tunes {wide_low:.4g} to "
                f"{wide_high:.4g} BPM)."
            )
        try:
            needed = float(wide.l2_for_bpm(bpm))
        except ParameterError:
            return text + "."
        # Round outward to 4 digits, staying short of the inverted pendulum.
        if bpm < low:
            edge = math.ceil(needed * 1e4) / 1e4
            bounds = (lo, edge if edge < inverted else needed)
        else:
            bounds = (math.floor(needed * 1e4) / 1e4, hi)
        return text + f", or widen `l2_bounds` to ({bounds[0]:g}, {bounds[1]:g}) m."

    def check_tunable(
        self,
        bpm,
        *,
        name: str = "bpm",
        index: bool = False,
        what: str | None = None,
        fix: str | None = None,
    ) -> None:
        """Raise `ParameterError` unless every value of ``bpm`` is finite and within
        `bpm_range`.

        ``name`` is the argument as the caller wrote it; with ``index``, an out-of-range
        entry of an array the user wrote is named with its index (`frequencies_bpm[1]`;
        not for a grid the program built). The message offers
        `l2_bounds` that would reach it (`out_of_range`). A caller whose values are not
        the user's own (drawn frequencies, a sweep axis) gives ``what`` (``{value}`` is
        the first value out of range, as text with the range's decimals) and ``fix`` instead.
        """
        bpm_arr = np.asarray(bpm, dtype=float)
        if not np.all(np.isfinite(bpm_arr)):
            raise ParameterError(f"`{name}` must be finite, got {describe(bpm)}.")
        if what is None and fix is None and np.any(bpm_arr <= 0):
            # Checked apart from the range: no slider position (nor any widening of
            # `l2_bounds` that `out_of_range` could offer) reaches a BPM at or below zero.
            # Values the caller drew (``what``) get the caller's message below.
            value = float(bpm_arr[bpm_arr <= 0].flat[0])
            raise ParameterError(f"`{name}` = {value:g} BPM: a tempo must be positive.")
        low, high = self.bpm_range()
        bad = (bpm_arr < low) | (bpm_arr > high)
        if not np.any(bad):
            return
        first = tuple(np.argwhere(bad)[0])
        value = float(bpm_arr[first])
        if what is None and fix is None:
            where = "".join(f"[{int(k)}]" for k in first) if index else ""
            raise ParameterError(self.out_of_range(f"{name}{where}", value))
        shown, low_text, high_text = shown_range(low, high, value)
        subject = what.format(value=shown) if what else f"`{name}` = {shown}"
        raise ParameterError(
            f"{subject} is outside the tunable range [{low_text}, {high_text}] BPM of this "
            f"metronome design (slider L2 in {self.l2_bounds} m). "
            f"{fix or 'Choose a BPM in range.'}"
        )

    def l2_for_bpm(self, bpm):
        """Slider position ``L2`` (m) that tunes the metronome to ``bpm`` under `tuning`.

        Accepts scalars or arrays; raises `ParameterError` for BPM outside `bpm_range`.
        """
        return tunings.l2_for_bpm(self, bpm, tuning=self.tuning)

    def small_amplitude_l2(self, bpm):
        """``L2`` (m) whose small-amplitude frequency is ``bpm``, whatever `tuning` says.

        Solves ω²(m h² + J_i) = m g h, a quadratic in ``L2``, in closed form.
        """
        bpm_arr = np.asarray(bpm, dtype=float)
        if not np.all(np.isfinite(bpm_arr)):
            raise ParameterError(f"`bpm` must be finite, got {describe(bpm)}.")
        low, high = self.small_amplitude_range()
        bad = (bpm_arr < low) | (bpm_arr > high)
        if np.any(bad):
            raise ParameterError(
                f"`bpm` = {float(bpm_arr[bad].flat[0]):.6g} is outside the small-amplitude "
                f"range [{low:.2f}, {high:.2f}] BPM of this metronome design (slider L2 in "
                f"{self.l2_bounds} m)."
            )
        w1, w2, l1, g = self.w1, self.w2, self.l1, self.g
        m = w1 + w2
        a = w1 * l1
        w2_sq = w2 * w2
        omega_sq = bpm_to_omega(bpm_arr) ** 2
        # ω²[(w2²/m + w2) x² - 2 a w2/m x + a²/m + w1 l1²] + g w2 x - g a = 0
        qa = omega_sq * (w2_sq / m + w2)
        qb = -2.0 * omega_sq * a * w2 / m + g * w2
        qc = omega_sq * (a * a / m + w1 * l1 * l1) - g * a
        if w2 == 0:
            raise ParameterError("`w2` is 0: the metronome has no slider and cannot be tuned.")
        disc = np.sqrt(np.maximum(qb * qb - 4.0 * qa * qc, 0.0))
        # The physical branch is the larger root (the smaller one is negative, a slider
        # below the pivot); on it ω falls monotonically as the slider moves up.
        x = (-qb + disc) / (2.0 * qa)
        return x if x.ndim else float(x)


@documented
@dataclass(frozen=True)
class Metronome:
    """A tuned metronome: a design plus the slider position ``l2``."""

    design: MetronomeDesign = field(default_factory=MetronomeDesign)
    l2: float = quantity(0.03, unit="m", bounds=NON_NEGATIVE)

    def __post_init__(self) -> None:
        check_quantities(self)
        if self.h <= 0:
            unit = declared(self, "l2")
            raise ParameterError(
                f"`l2` = {self.l2!r} {unit} gives h = {self.h:.3g} {unit} <= 0: the centre of "
                f"mass is above the pivot and the pendulum is inverted. Use l2 < "
                f"{self.design.w1 * self.design.l1 / max(self.design.w2, 1e-300):.5f} {unit}."
            )

    @property
    def mass(self) -> float:
        return self.design.mass

    @property
    def h(self) -> float:
        """Pivot to centre-of-mass distance, m (paper §4)."""
        d = self.design
        return float(centre_of_mass(d.w1, d.w2, d.l1, self.l2))

    @property
    def j(self) -> float:
        """The paper's J_i = w1 L1² + w2 L2², kg m²."""
        d = self.design
        return float(pivot_moment(d.w1, d.w2, d.l1, self.l2))

    @property
    def inertia(self) -> float:
        """The coefficient of θ̈ in eq. (metron2): m h² + J_i, kg m²."""
        d = self.design
        return float(pendulum_inertia(d.w1, d.w2, d.l1, self.l2))

    @property
    def natural_omega(self) -> float:
        """Small-amplitude angular frequency on a rigid support, rad/s."""
        d = self.design
        return float(natural_omega(d.w1, d.w2, d.l1, self.l2, d.g))

    @property
    def natural_bpm(self) -> float:
        return float(omega_to_bpm(self.natural_omega))

    @property
    def balance_amplitude(self) -> float:
        """Energy-balance amplitude 2M/(π c_θ), rad (small-angle, rigid support)."""
        return balance_amplitude(self.design.drive, self.design.c_theta)


def balance_amplitude(drive: float, c_theta: float) -> float:
    """Amplitude at which the escapement's energy input balances friction, rad: the
    closed-form, small-angle estimate of the steady swing (rigid support).

    Per half period the kick adds ``M·θ̇(0) = M A ω`` and friction removes
    ``c_θ ∫θ̇² dt = π c_θ A² ω / 2``; equating gives ``A = 2M/(π c_θ)``.
    Infinite when there is no friction.
    """
    if c_theta == 0:
        return math.inf if drive > 0 else 0.0
    return 2.0 * drive / (math.pi * c_theta)

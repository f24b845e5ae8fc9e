"""What stands in front of the camera: metronomes on a table before a cluttered wall.

World coordinates in metres: X to the right, Y up, Z away from the viewer; the table
top is the plane Y = 0. Every metronome stands on the table facing −Z, and its rod
swings in the plane Z = z_i (the front face of its body): at angle θ the rod's tip is
at pivot + L·(sin θ, cos θ, 0), so θ > 0 leans the rod to the right, seen from the
front. Metronomes are laid out in a row along X, with depths of their own; a scene
may place neighbours closer than their width, so that one hides part of the other.

`Scene` holds only numbers (frozen dataclasses, SI units); `_scene_render` turns it
into pixels through a `Pinhole`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError

#: Most metronomes a scene holds.
MAX_METRONOMES = 8

#: Body colours (linear-ish sRGB in [0, 1]): wood, black, red, blue, green, ivory, grey.
BODY_COLOURS = (
    (0.45, 0.27, 0.13), (0.30, 0.17, 0.08), (0.08, 0.08, 0.09), (0.62, 0.10, 0.10),
    (0.12, 0.22, 0.55), (0.10, 0.40, 0.22), (0.86, 0.82, 0.70), (0.50, 0.50, 0.52),
    (0.70, 0.55, 0.30), (0.85, 0.45, 0.10),
)  # fmt: skip
#: Rod colours: steel, chrome, black, brass.
ROD_COLOURS = ((0.70, 0.72, 0.75), (0.88, 0.88, 0.90), (0.10, 0.10, 0.10), (0.78, 0.64, 0.30))
#: Bob colours: brass, chrome, black, red.
BOB_COLOURS = ((0.85, 0.70, 0.25), (0.80, 0.80, 0.84), (0.12, 0.12, 0.12), (0.75, 0.15, 0.12))


@dataclass(frozen=True)
class Metronome:
    """One metronome's shape and colours, SI units.

    x, z : position of its base centre on the table (front face at depth z), m.
    body_height, base_width, top_width, body_depth : the trapezoid box, m.
    pivot_height : height of the rod's pivot above the table, m.
    rod_length : pivot to tip, m.   rod_width : m.
    bob_position : pivot to the bob's centre, m (< rod_length).
    bob_length, bob_width : the bob's extent along and across the rod, m.
    body_colour, rod_colour, bob_colour : RGB in [0, 1].
    """

    x: float
    z: float
    body_height: float = 0.22
    base_width: float = 0.11
    top_width: float = 0.045
    body_depth: float = 0.10
    pivot_height: float = 0.035
    rod_length: float = 0.20
    rod_width: float = 0.004
    bob_position: float = 0.12
    bob_length: float = 0.022
    bob_width: float = 0.018
    body_colour: tuple[float, float, float] = BODY_COLOURS[0]
    rod_colour: tuple[float, float, float] = ROD_COLOURS[0]
    bob_colour: tuple[float, float, float] = BOB_COLOURS[0]

    def __post_init__(self) -> None:
        for name in ("x", "z"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"`{name}` must be finite, got {getattr(self, name)!r}.")
        for name in (
            "body_height", "base_width", "top_width", "body_depth", "pivot_height",
            "rod_length", "rod_width", "bob_position", "bob_length", "bob_width",
        ):  # fmt: skip
            value = getattr(self, name)
            if not (math.isfinite(value) and 0 < value < 5):
                raise ParameterError(f"`{name}` must be in (0, 5) m, got {value!r}.")
        if self.bob_position + 0.5 * self.bob_length > self.rod_length:
            raise ParameterError(
                f"`bob_position` + `bob_length`/2 must stay on the rod (`rod_length` = "
                f"{self.rod_length}), got {self.bob_position} + {self.bob_length / 2}."
            )
        if self.pivot_height >= self.body_height:
            raise ParameterError(
                f"`pivot_height` must be below the body's top ({self.body_height} m), "
                f"got {self.pivot_height}."
            )
        for name in ("body_colour", "rod_colour", "bob_colour"):
            colour = getattr(self, name)
            if len(colour) != 3 or not all(0.0 <= c <= 1.0 for c in colour):
                raise ParameterError(f"`{name}` must be 3 numbers in [0, 1], got {colour!r}.")

    @property
    def pivot(self) -> np.ndarray:
        """(3,) the rod's pivot in world coordinates, m."""
        return np.array([self.x, self.pivot_height, self.z])


@dataclass(frozen=True)
class Scene:
    """Metronomes on a table before a wall, and the look of the background.

    metronomes : 1 to `MAX_METRONOMES` `Metronome`.
    wall_colour, table_colour : RGB in [0, 1].
    clutter : number of random shapes on the wall (posters, shelves, cables...).
    texture : amplitude of the wall's and table's blotchy texture, in [0, 1].
    seed : draws the clutter and texture.
    disk : draw the round platform the metronomes stand on.
    """

    metronomes: tuple[Metronome, ...]
    wall_colour: tuple[float, float, float] = (0.78, 0.76, 0.70)
    table_colour: tuple[float, float, float] = (0.55, 0.42, 0.30)
    clutter: int = 25
    texture: float = 0.08
    seed: int = 0
    disk: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "metronomes", tuple(self.metronomes))
        n = len(self.metronomes)
        if not 1 <= n <= MAX_METRONOMES:
            raise ParameterError(
                f"`metronomes` must hold 1 to {MAX_METRONOMES} metronomes, got {n}."
            )
        if not all(isinstance(m, Metronome) for m in self.metronomes):
            raise ParameterError("`metronomes` must be `Metronome` objects.")
        if isinstance(self.clutter, bool) or not (
            isinstance(self.clutter, int | np.integer) and 0 <= self.clutter <= 500
        ):
            raise ParameterError(f"`clutter` must be an integer in [0, 500], got {self.clutter!r}.")
        if not (math.isfinite(self.texture) and 0.0 <= self.texture <= 1.0):
            raise ParameterError(f"`texture` must be in [0, 1], got {self.texture!r}.")

    @property
    def n(self) -> int:
        """Number of metronomes."""
        return len(self.metronomes)

    @classmethod
    def random(
        cls,
        n: int,
        seed: int = 0,
        *,
        overlap: float = 0.3,
        clutter: int | None = None,
        size_spread: float = 0.25,
    ) -> Scene:
        """A random scene of ``n`` metronomes: sizes, colours, spacing and background.

        overlap : probability that a metronome stands closer to its left neighbour than
            their widths, one in front of the other, so that one partly hides the other.
        clutter : shapes on the wall; by default drawn between 5 and 60.
        size_spread : relative spread of the metronomes' sizes (0: all alike).
        """
        if isinstance(n, bool) or not isinstance(n, int | np.integer):
            raise ParameterError(f"`n` must be an integer, got {n!r}.")
        if not 1 <= n <= MAX_METRONOMES:
            raise ParameterError(f"`n` must be in [1, {MAX_METRONOMES}], got {n}.")
        if not (math.isfinite(overlap) and 0.0 <= overlap <= 1.0):
            raise ParameterError(f"`overlap` must be a probability in [0, 1], got {overlap!r}.")
        if not (math.isfinite(size_spread) and 0.0 <= size_spread <= 0.5):
            raise ParameterError(f"`size_spread` must be in [0, 0.5], got {size_spread!r}.")
        rng = np.random.default_rng(seed)
        base_scale = rng.uniform(0.8, 1.2)
        metronomes = []
        x = 0.0
        previous = None
        for _ in range(n):
            scale = base_scale * float(np.exp(rng.normal(0.0, size_spread)))
            scale = float(np.clip(scale, 0.6, 1.6))
            height = 0.22 * scale * rng.uniform(0.9, 1.1)
            base = height * rng.uniform(0.42, 0.6)
            rod = height * rng.uniform(0.85, 1.15)
            bob_len = rod * rng.uniform(0.08, 0.14)
            bob_pos = rod * rng.uniform(0.35, 0.85)
            bob_pos = min(bob_pos, rod - 0.6 * bob_len)
            depth = base * rng.uniform(0.7, 1.0)
            z = rng.normal(0.0, 0.025)
            if previous is not None:
                gap = 0.5 * (previous.base_width + base)
                if rng.random() < overlap:
                    # Closer than their widths: one stands behind the other (their bodies
                    # must not meet), on the side that keeps the row near Z = 0.
                    x += gap * rng.uniform(0.65, 0.95)
                    if previous.z <= 0.0:
                        z = previous.z + previous.body_depth + rng.uniform(0.005, 0.04)
                    else:
                        z = previous.z - depth - rng.uniform(0.005, 0.04)
                else:
                    x += gap * rng.uniform(1.15, 1.9)
            metronome = Metronome(
                x=x,
                z=float(z),
                body_height=height,
                base_width=base,
                top_width=base * rng.uniform(0.3, 0.55),
                body_depth=depth,
                pivot_height=height * rng.uniform(0.1, 0.2),
                rod_length=rod,
                rod_width=rod * rng.uniform(0.012, 0.03),
                bob_position=bob_pos,
                bob_length=bob_len,
                bob_width=rod * rng.uniform(0.07, 0.12),
                body_colour=_jitter(rng, BODY_COLOURS[rng.integers(len(BODY_COLOURS))]),
                rod_colour=_jitter(rng, ROD_COLOURS[rng.integers(len(ROD_COLOURS))]),
                bob_colour=_jitter(rng, BOB_COLOURS[rng.integers(len(BOB_COLOURS))]),
            )
            metronomes.append(metronome)
            previous = metronome
        centre = 0.5 * (metronomes[0].x + metronomes[-1].x)
        metronomes = [_shifted(m, -centre) for m in metronomes]
        wall = tuple(float(c) for c in rng.uniform(0.15, 0.9) * _unit_tint(rng, 0.25))
        table = tuple(float(c) for c in rng.uniform(0.2, 0.75) * _unit_tint(rng, 0.35))
        return cls(
            tuple(metronomes),
            wall_colour=wall,
            table_colour=table,
            clutter=int(rng.integers(5, 61)) if clutter is None else clutter,
            texture=float(rng.uniform(0.02, 0.15)),
            seed=int(rng.integers(2**31)),
            disk=bool(rng.random() < 0.6),
        )


def _jitter(rng, colour) -> tuple[float, float, float]:
    c = np.clip(np.asarray(colour) * rng.uniform(0.85, 1.15, 3), 0.0, 1.0)
    return (float(c[0]), float(c[1]), float(c[2]))


def _unit_tint(rng, spread: float) -> np.ndarray:
    tint = 1.0 + rng.uniform(-spread, spread, 3)
    return np.clip(tint / tint.max(), 0.0, 1.0)


def _shifted(m: Metronome, dx: float) -> Metronome:
    return replace(m, x=m.x + dx)

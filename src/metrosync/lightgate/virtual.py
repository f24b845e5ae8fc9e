"""A virtual light gate: logs in the logger's format from simulated trajectories.

Contract: `gate_edges` finds when a bob enters and leaves a beam; `format_log`
turns the edges of up to 8 metronomes into the text of a capture; `write_logs`
writes one log per run of a `simulate` dataset that holds trajectories, and warns
when a bob never or rarely reaches its beam (fewer passes than half its swings
through the vertical): such a log holds few or no passes, and the analysis of it
bridges missed ones.

Physics of the gate: the beam is interrupted while the bob is inside it,
|θ − offset| < width/2 (angles in rad). Between the recorded samples θ(t) is the
cubic Hermite interpolant through θ and θ̇, so entries and exits are found to well
below a step even though a bob crosses the whole beam within one 10 ms step. The
logger then sees each edge, optionally with Gaussian timing jitter, quantized to
its tick (floor: a counter shows the ticks completed), and prints the counter
modulo 2^counter_bits. It reports the gate levels once when the capture starts
(t = 0), then one line per edge. With an off-centre gate (offset ≠ 0) the intervals
between passes alternate short/long, which is how `cleaning` tells the directions
apart; for offset > 0 the kept passes are those with θ increasing.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import write_text
from .._words import plural
from ..errors import ParameterError
from .counter import COUNTER_BITS_RANGE
from .reader import DEFAULT_TICK, MAX_GATES

_BISECTIONS = 48


@dataclass(frozen=True)
class LightGate:
    """Settings of the virtual gate and logger (SI units, angles in rad).

    offset : angle of the beam's centre from the vertical.
    width : angular width of the beam.
    tick : logger clock tick, s.
    jitter : standard deviation of Gaussian timing noise on each edge, s.
    counter_bits : counter width; the printed value is modulo 2**counter_bits.
        16 bits at 64 µs (a 16 MHz clock / 1024) wraps every 4.19 s.
    start_tick : counter value at the start of the capture.
    interrupted_level : the level (0/1) the logger prints for an interrupted beam.
    seed : seed of the timing jitter.
    """

    offset: float = 0.1
    width: float = 0.05
    tick: float = DEFAULT_TICK
    jitter: float = 0.0
    counter_bits: int = 16
    start_tick: int = 0
    interrupted_level: int = 1
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("offset", "width", "tick", "jitter"):
            if not math.isfinite(getattr(self, name)):
                raise ParameterError(f"`{name}` must be finite, got {getattr(self, name)!r}.")
        if not self.width > 0:
            raise ParameterError(f"`width` must be an angle > 0 rad, got {self.width!r}.")
        if not self.tick > 0:
            raise ParameterError(f"`tick` must be a time > 0 s, got {self.tick!r}.")
        if self.jitter < 0:
            raise ParameterError(f"`jitter` must be >= 0 s, got {self.jitter!r}.")
        lo, hi = COUNTER_BITS_RANGE
        if not (isinstance(self.counter_bits, int) and lo <= self.counter_bits <= hi):
            raise ParameterError(
                f"`counter_bits` must be an integer in [{lo}, {hi}], got {self.counter_bits!r}."
            )
        if not (isinstance(self.start_tick, int) and 0 <= self.start_tick < 1 << self.counter_bits):
            raise ParameterError(
                f"`start_tick` must be in [0, 2**counter_bits), got {self.start_tick!r}."
            )
        if self.interrupted_level not in (0, 1):
            raise ParameterError(
                f"`interrupted_level` must be 0 or 1, got {self.interrupted_level!r}."
            )


def level_crossings(time, theta, theta_dot, level: float):
    """Times where the Hermite interpolant of θ crosses ``level``, and their direction.

    time : (T,) sample times.   theta, theta_dot : (T,).
    Returns (times (C,), upward (C,) bool), sorted by time.
    """
    t = np.asarray(time, dtype=float)
    h = np.diff(t)
    y0, y1 = theta[:-1] - level, theta[1:] - level
    m0, m1 = theta_dot[:-1] * h, theta_dot[1:] * h
    # p(s) = a s³ + b s² + c s + d on s ∈ [0, 1]
    a = 2 * y0 + m0 - 2 * y1 + m1
    b = -3 * y0 - 2 * m0 + 3 * y1 - m1
    c, d = m0, y0
    # Split each step at the interpolant's turning points: each piece is monotone.
    qa, qb, qc = 3 * a, 2 * b, c
    disc = qb * qb - 4 * qa * qc
    with np.errstate(invalid="ignore", divide="ignore"):
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        big = np.abs(qa) > 1e-12 * (np.abs(qb) + np.abs(qc) + 1e-300)
        r1 = np.where(big, (-qb - sq) / (2 * qa), -qc / qb)
        r2 = np.where(big, (-qb + sq) / (2 * qa), np.nan)
    pts = np.stack([np.zeros_like(a), r1, r2, np.ones_like(a)], axis=1)
    pts[~((pts > 0) & (pts < 1))] = np.nan
    pts[:, 0], pts[:, 3] = 0.0, 1.0
    pts = np.sort(pts, axis=1)  # NaN last
    pts = np.where(np.isnan(pts), 1.0, pts)  # pad with the step's end: empty pieces

    def p(k, s):
        return ((a[k] * s + b[k]) * s + c[k]) * s + d[k]

    steps = np.arange(a.size)
    out_t, out_up = [], []
    for j in range(3):
        lo, hi = pts[:, j], pts[:, j + 1]
        plo, phi = p(steps, lo), p(steps, hi)
        # A crossing is a change between "below" (< 0) and "not below" (>= 0).
        hit = (plo < 0) != (phi < 0)
        if j > 0:
            hit &= hi > lo
        k = np.flatnonzero(hit)
        if k.size == 0:
            continue
        up = plo[k] < 0
        lo_k, hi_k = lo[k].copy(), hi[k].copy()
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo_k + hi_k)
            below = p(k, mid) < 0
            go_up = below == up  # still on the start side
            lo_k = np.where(go_up, mid, lo_k)
            hi_k = np.where(go_up, hi_k, mid)
        out_t.append(t[k] + hi_k * h[k])
        out_up.append(up)
    if not out_t:
        return np.empty(0), np.empty(0, dtype=bool)
    times = np.concatenate(out_t)
    ups = np.concatenate(out_up)
    order = np.argsort(times, kind="stable")
    return times[order], ups[order]


def gate_edges(time, theta, theta_dot, *, offset: float, width: float):
    """Edges of one metronome's gate.

    Returns (initial, times (E,), entering (E,) bool): whether the beam is interrupted
    at the first sample, and the times the bob enters (True) or leaves (False) it.
    """
    lower, upper = offset - width / 2, offset + width / 2
    t_lo, up_lo = level_crossings(time, theta, theta_dot, lower)
    t_hi, up_hi = level_crossings(time, theta, theta_dot, upper)
    times = np.concatenate([t_lo, t_hi])
    # In the beam after: rising through the lower edge, or falling through the upper one.
    inside = np.concatenate([up_lo, ~up_hi])
    order = np.argsort(times, kind="stable")
    times, inside = times[order], inside[order]
    initial = bool(abs(theta[0] - offset) < width / 2)
    previous = np.concatenate([[initial], inside[:-1]])
    change = inside != previous
    return initial, times[change], inside[change]


def format_log(time, theta, theta_dot, gate: LightGate = LightGate()) -> str:
    """Text of a capture of one run.

    time : (T,) s, from 0.   theta, theta_dot : (T, N) with N <= 8.
    """
    return _capture(time, theta, theta_dot, gate)[0]


def _capture(time, theta, theta_dot, gate: LightGate) -> tuple[str, np.ndarray]:
    """The capture's text and the number of passes (entries into the beam) per gate."""
    theta = np.asarray(theta, dtype=float)
    theta_dot = np.asarray(theta_dot, dtype=float)
    if theta.ndim != 2 or theta.shape != theta_dot.shape or theta.shape[0] != len(time):
        raise ParameterError(
            f"`theta` and `theta_dot` must both have shape (len(time), N), got "
            f"{theta.shape} and {theta_dot.shape} for {plural(len(time), 'time')}."
        )
    n = theta.shape[1]
    if not 1 <= n <= MAX_GATES:
        raise ParameterError(
            f"the logger follows 1 to {MAX_GATES} gates, but the run has {n} metronomes; "
            f"simulate at most {MAX_GATES}."
        )
    rng = np.random.default_rng(gate.seed)
    state = np.zeros(n, dtype=np.int8)
    all_t, all_ch, all_in = [], [], []
    for i in range(n):
        initial, times, entering = gate_edges(time, theta[:, i], theta_dot[:, i],
                                              offset=gate.offset, width=gate.width)  # fmt: skip
        state[i] = initial
        if gate.jitter > 0:
            times = times + rng.normal(0.0, gate.jitter, times.size)
            times = np.maximum.accumulate(times)  # jitter must not reorder a gate's edges
        all_t.append(times)
        all_ch.append(np.full(times.size, i))
        all_in.append(entering)
    passes = np.array([int(np.count_nonzero(e)) for e in all_in])
    times = np.concatenate(all_t)
    channel = np.concatenate(all_ch)
    entering = np.concatenate(all_in)
    keep = times >= 0
    times, channel, entering = times[keep], channel[keep], entering[keep]
    order = np.argsort(times, kind="stable")
    ticks = np.floor(times[order] / gate.tick).astype(np.int64)
    modulus = 1 << gate.counter_bits
    shown = (gate.start_tick + ticks) % modulus
    flip = gate.interrupted_level == 0
    lines = [_line(state, flip, gate.start_tick % modulus)]
    for ch, ent, value in zip(channel[order], entering[order], shown, strict=True):
        state[ch] = ent
        lines.append(_line(state, flip, int(value)))
    return "\n".join(lines) + "\n", passes


def _line(state: np.ndarray, flip: bool, value: int) -> str:
    levels = (1 - state) if flip else state
    return "-".join(str(int(v)) for v in levels) + f" {value}"


def write_logs(
    ds, directory: str | Path, gate: LightGate = LightGate(), *, prefix: str = "run"
) -> list[Path]:
    """Write one log per run of a `simulate` dataset with trajectories.

    ds : dataset with ``theta`` and ``theta_dot`` (time, run, metronome); a record
        every step gives edges accurate to well below a tick.
    Returns the paths written, ``DIR/{prefix}{run:03d}.log``; files appear atomically.
    """
    if "theta" not in ds or "theta_dot" not in ds:
        raise ParameterError(
            "the dataset has no trajectories; simulate with `trajectories=True` "
            "(ideally `record_every=1`) to feed the virtual light gate."
        )
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    time = ds.time.values
    paths = []
    rare = []
    for b in range(ds.sizes["run"]):
        theta = ds.theta.values[:, b, :]
        text, passes = _capture(time, theta, ds.theta_dot.values[:, b, :],
                                LightGate(**{**vars(gate), "seed": gate.seed + b}))  # fmt: skip
        paths.append(write_text(text, directory / f"{prefix}{b:03d}.log"))
        # A bob that reaches the beam passes it about once per swing through the vertical.
        swings = np.count_nonzero(np.diff(np.signbit(theta), axis=0), axis=0)
        for i in np.flatnonzero(passes < 0.5 * swings):
            rare.append((b, int(i), int(passes[i]), int(swings[i]),
                         float(np.nanmax(np.abs(theta[:, i])))))  # fmt: skip
    if rare:
        _warn_unreached(rare, gate, ds.sizes["run"] * ds.sizes["metronome"])
    return paths


def _warn_unreached(rare: list[tuple[int, int, int, int, float]], gate: LightGate, total: int):
    never = sum(1 for _, _, passes, _, _ in rare if passes == 0)
    b, i, passes, swings, swing = rare[0]
    beam = (gate.offset - gate.width / 2, gate.offset + gate.width / 2)
    warnings.warn(
        f"the light gate at `offset` = {gate.offset:g} rad (beam {beam[0]:.3g} .. "
        f"{beam[1]:.3g} rad) is reached rarely or never in {len(rare)} of {total} metronome "
        f"runs ({never} never): e.g. run {b}, metronome {i} passed it {plural(passes, 'time')} "
        f"in {plural(swings, 'swing')} through the vertical, swinging up to {swing:.3g} rad. "
        f"Those logs hold few or no passes; choose an `offset` well inside the swing (the "
        f"default is 0.1 rad).",
        UserWarning,
        stacklevel=3,
    )

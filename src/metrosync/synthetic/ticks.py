"""A metronome's tick as a real one sounds: several impacts ringing through the
resonances of its case.

The time of a tick is the onset of its loud (main) impact, the most regular of its
impacts: everything else about a tick is placed relative to it.

Measured on real metronomes (44.1 kHz recordings), a tick is a main impact followed
by one to three secondary impacts 15–35 ms later at 40–70 % of its amplitude (the
escapement's pallet bouncing), the whole ringing for about 80 ms through a few
resonances of the case. The tick and the tock of one metronome are struck by different
pallets, so they differ in sound and in loudness; two metronomes of different makes
differ in spectrum more than in loudness.

A `Voice` holds those traits of one metronome, frozen, and is drawn reproducibly from
a seed (`Voice.draw`, or `voices` for several that differ from each other;
`Voice.sibling` for another metronome of the same make, alike but not identical). Its
`Voice.waveform` renders one tick or one tock:

- each impact is a broadband transient (exponentially decaying noise, 0.4 ms) plus
  the voice's resonances, damped sinusoids of frequencies ``resonances`` (Hz) and
  amplitudes ``weights``; the slowest decays 60 dB in ``ring`` seconds, the others
  faster (``decays``, fractions of it);
- impact j ≥ 1 is the same sound, ``sub_gains[j-1]`` times as loud, starting
  ``sub_delays[j-1]`` s after the main impact. As heard, the ring of the earlier
  impacts adds in or out of phase: the waveform's peak at a secondary impact is
  0.39–0.78 of the main one's for 90 % of drawn voices (median 0.57);
- the tock rings at the resonances times ``tock_shift`` (a different pallet excites
  the case differently) and is ``tock_gain`` (< 1) times as loud as the tick, so the
  tick is the louder, as `metrosync.audio.metronome` names them;
- the first sample is the onset of the main impact (it is 0 there and rises within
  0.3 ms);
- makes differ in the structure of their ticks (`metrosync.synthetic.structures`):
  the tock may have later impacts of its own (``tock_sub_delays``, ``tock_sub_gains``),
  and a quieter impact may come before the loud one (``precursor``,
  ``tock_precursor``: a `Precursor`), before most ticks but not all, its lead wandering
  from tick to tick. Its lead varies, so it is no part of the waveform:
  `Voice.precursor_waveform` is its sound, placed by the recording
  (`metrosync.synthetic.recording`) at each tick's drawn lead (`Precursor.leads`);
- loudness is energy: the RMS of the tick over its first `LOUDNESS_WINDOW` (50 ms:
  the impacts) is ``level · REFERENCE_RMS``. Peaks then differ between voices with
  their crest factor (3 to 11 for drawn voices, so a drawn tick's peak stays below 1).

The waveform is a pure function of the voice and the sample rate. The noise of the
transient comes from the voice's own ``seed``, so a voice sounds the same every time.

The simplest tick, `click_waveform`, is no metronome's: a 6 ms decaying cosine burst of
one pitch, which `metrosync listen` plays by default and the detector's tests use.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: Ranges the traits of a drawn voice come from (see `Voice.draw`).
SUB_DELAY_RANGE = (0.015, 0.035)  # s after the main impact
SUB_GAIN_RANGE = (0.4, 0.7)  # fraction of the main impact
RING_RANGE = (0.07, 0.09)  # s for the slowest resonance to fall by 60 dB
RESONANCE_RANGE = (800.0, 4500.0)  # Hz, the main resonance
TOCK_GAIN_RANGE = (0.6, 0.85)
TOCK_SHIFT_RANGE = (0.06, 0.15)  # |tock_shift − 1|
LEVEL_RANGE = (0.85, 1.0)  # 1.4 dB: makes differ in spectrum, hardly in loudness
#: Length of the broadband transient of an impact (decay time), s.
TRANSIENT_DECAY = 0.0004
#: Rise time of an impact, s: the waveform starts at 0.
ATTACK = 0.00008
#: The tick's loudness is its RMS over this first part, s, ...
LOUDNESS_WINDOW = 0.05
#: ... which is ``level`` times this.
REFERENCE_RMS = 0.09
#: Most voices `voices` draws at once.
MAX_VOICES = 10000
#: Highest resonance drawn, Hz.
MAX_RESONANCE = 9000.0
#: A precursor comes this long before the loud impact, s, at least and at most.
PRECURSOR_LEADS = (0.010, 0.045)
#: Length and decay time of `click_waveform`, s.
CLICK_LENGTH = 0.006
CLICK_DECAY = 0.001


@dataclass(frozen=True)
class Precursor:
    """A quieter impact before the loud one, before some of the ticks of one kind.

    lead : how long before the loud impact it comes on average, s, within
        `PRECURSOR_LEADS`.
    spread : the standard deviation of its lead from tick to tick, s, in [0, 0.015].
    gain : its amplitude relative to the loud impact, in (0, 1).
    share : the fraction of the ticks it comes before, in (0, 1].
    """

    lead: float
    spread: float
    gain: float
    share: float

    def __post_init__(self) -> None:
        low, high = PRECURSOR_LEADS
        if not (low <= self.lead <= high):
            raise ParameterError(f"`lead` must be in [{low:g}, {high:g}] s, got {self.lead!r}.")
        if not (0 <= self.spread <= 0.015):
            raise ParameterError(f"`spread` must be in [0, 0.015] s, got {self.spread!r}.")
        if not (0 < self.gain < 1):
            raise ParameterError(
                f"`gain` must be in (0, 1) (quieter than the loud impact), got {self.gain!r}."
            )
        if not (0 < self.share <= 1):
            raise ParameterError(f"`share` must be in (0, 1], got {self.share!r}.")

    def leads(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """(count,) the lead of the precursor before each of ``count`` ticks, s, NaN
        before the ticks it does not come before: each tick has one with probability
        ``share``, its lead Gaussian about ``lead`` with std ``spread``, truncated to
        `PRECURSOR_LEADS` (a lead outside is drawn again)."""
        present = rng.random(count) < self.share
        lead = rng.normal(self.lead, self.spread, count)
        low, high = PRECURSOR_LEADS
        while np.any(outside := (lead < low) | (lead > high)):
            lead[outside] = rng.normal(self.lead, self.spread, int(outside.sum()))
        return np.where(present, lead, np.nan)


@dataclass(frozen=True)
class Voice:
    """The sound of one metronome.

    resonances : (M,) frequencies of its case's resonances, Hz, the first the main one.
    weights : (M,) their relative amplitudes (the first 1).
    decays : (M,) their decay times as fractions of the slowest's (the first 1).
    ring : time for the slowest resonance to fall by 60 dB, s.
    sub_delays : (J,) delays of the secondary impacts after the main one, s,
        increasing, J in 1..3.
    sub_gains : (J,) their amplitudes relative to the main impact.
    tock_shift : factor on the resonances for the tock (≠ 1).
    tock_gain : loudness of the tock relative to the tick (< 1).
    level : loudness of the tick (its RMS over `LOUDNESS_WINDOW` is
        ``level · REFERENCE_RMS``), in (0, 1].
    transient : weight of the broadband transient of each impact, relative to the
        resonances.
    seed : seed of the transient's noise.
    tock_sub_delays, tock_sub_gains : the tock's secondary impacts, when they differ
        from the tick's (None: the same as the tick's).
    precursor, tock_precursor : the `Precursor` before the ticks, before the tocks
        (None: none).
    """

    resonances: tuple[float, ...]
    weights: tuple[float, ...]
    decays: tuple[float, ...]
    ring: float
    sub_delays: tuple[float, ...]
    sub_gains: tuple[float, ...]
    tock_shift: float
    tock_gain: float
    level: float = 1.0
    transient: float = 0.6
    seed: int = 0
    tock_sub_delays: tuple[float, ...] | None = None
    tock_sub_gains: tuple[float, ...] | None = None
    precursor: Precursor | None = None
    tock_precursor: Precursor | None = None

    def __post_init__(self) -> None:
        m = len(self.resonances)
        if m < 1 or len(self.weights) != m or len(self.decays) != m:
            raise ParameterError(
                f"`resonances`, `weights` and `decays` must have the same length ≥ 1, got "
                f"{len(self.resonances)}, {len(self.weights)} and {len(self.decays)}."
            )
        if not all(0 < f < MAX_RESONANCE * 1.5 for f in self.resonances):
            raise ParameterError(
                f"`resonances` must lie in (0, {MAX_RESONANCE * 1.5:g}) Hz, got "
                f"{self.resonances!r}."
            )
        if not all(0 < d <= 1 for d in self.decays):
            raise ParameterError(f"`decays` must lie in (0, 1], got {self.decays!r}.")
        if not (0.005 <= self.ring <= 1.0):
            raise ParameterError(f"`ring` must be in [0.005, 1] s, got {self.ring!r}.")
        _check_impacts("sub_delays", self.sub_delays, "sub_gains", self.sub_gains)
        if (self.tock_sub_delays is None) != (self.tock_sub_gains is None):
            raise ParameterError(
                "`tock_sub_delays` and `tock_sub_gains` must both be given or both be None."
            )
        if self.tock_sub_delays is not None and self.tock_sub_gains is not None:
            _check_impacts(
                "tock_sub_delays", self.tock_sub_delays, "tock_sub_gains", self.tock_sub_gains
            )
        for name in ("precursor", "tock_precursor"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, Precursor):
                raise ParameterError(f"`{name}` must be a Precursor or None, got {value!r}.")
        if not (0 < self.tock_shift and self.tock_shift != 1):
            raise ParameterError(
                f"`tock_shift` must be > 0 and ≠ 1 (tick and tock differ), got {self.tock_shift!r}."
            )
        if not (0 < self.tock_gain <= 1):
            raise ParameterError(f"`tock_gain` must be in (0, 1], got {self.tock_gain!r}.")
        if not (0 < self.level <= 1):
            raise ParameterError(f"`level` must be in (0, 1], got {self.level!r}.")

    @classmethod
    def draw(
        cls, seed: int = 0, *, main_resonance: float | None = None, structure: str = "classic"
    ) -> Voice:
        """A voice drawn from the ranges of this module (`SUB_DELAY_RANGE`, …).

        seed : the same seed gives the same voice.
        main_resonance : the main resonance, Hz (default: drawn log-uniformly in
            `RESONANCE_RANGE`).
        structure : the structure of its ticks, a name in
            `metrosync.synthetic.structures.STRUCTURES`. "classic" (the default) is the
            voice this method has always drawn, sample for sample; any other is that
            voice with the traits of the structure added (`structures.widen`).
        """
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise ParameterError(f"`seed` must be an integer ≥ 0, got {seed!r}.")
        if structure != "classic":
            from .structures import widen

            return widen(cls.draw(seed, main_resonance=main_resonance), structure)
        rng = np.random.default_rng([25, int(seed)])
        low, high = np.log(RESONANCE_RANGE)
        f0 = float(np.exp(rng.uniform(low, high))) if main_resonance is None else main_resonance
        extra = int(rng.integers(2, 4))
        ratios = np.sort(rng.uniform(1.35, 3.2, extra))
        resonances = [f0] + [f for f in f0 * ratios if f < MAX_RESONANCE]
        weights = [1.0] + list(rng.uniform(0.3, 0.8, len(resonances) - 1))
        decays = [1.0] + list(rng.uniform(0.35, 0.8, len(resonances) - 1))
        n_sub = int(rng.integers(1, 4))
        sub_delays = later_delays(n_sub, rng)
        sign = rng.choice([-1.0, 1.0])
        return cls(
            resonances=tuple(float(f) for f in resonances),
            weights=tuple(float(w) for w in weights),
            decays=tuple(float(d) for d in decays),
            ring=float(rng.uniform(*RING_RANGE)),
            sub_delays=tuple(float(d) for d in sub_delays),
            sub_gains=tuple(float(g) for g in rng.uniform(*SUB_GAIN_RANGE, n_sub)),
            tock_shift=float(1.0 + sign * rng.uniform(*TOCK_SHIFT_RANGE)),
            tock_gain=float(rng.uniform(*TOCK_GAIN_RANGE)),
            level=float(rng.uniform(*LEVEL_RANGE)),
            seed=int(seed),
        )

    def sibling(self, seed: int, *, spread: float = 0.02) -> Voice:
        """Another metronome of the same make: resonances moved by a relative
        Gaussian ``spread`` (default 2 %), secondary impacts by ``spread`` × 50 ms
        (1 ms) and their heights by ``spread`` × 2.5 (5 %), loudness within ``spread``
        × 25 (0.5 dB); the same tock traits. Drawn from ``seed``.
        """
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise ParameterError(f"`seed` must be an integer ≥ 0, got {seed!r}.")
        if not (0 <= spread <= 0.1):
            raise ParameterError(f"`spread` must be in [0, 0.1], got {spread!r}.")
        rng = np.random.default_rng([31, self.seed, int(seed)])
        m, j = len(self.resonances), len(self.sub_delays)
        resonances = np.asarray(self.resonances) * (1 + rng.normal(0.0, spread, m))
        delays = np.asarray(self.sub_delays) + rng.normal(0.0, 50 * spread * 1e-3, j)
        delays = np.maximum.accumulate(np.maximum(np.sort(delays), 0.005))
        gains = np.clip(np.asarray(self.sub_gains) + rng.normal(0.0, 2.5 * spread, j), 0.05, 1)
        level_db = rng.normal(0.0, 25 * spread)
        return dataclasses.replace(
            self,
            resonances=tuple(float(f) for f in np.clip(resonances, 50.0, MAX_RESONANCE * 1.4)),
            sub_delays=tuple(float(d) for d in delays + 1e-4 * np.arange(j)),
            sub_gains=tuple(float(g) for g in gains),
            level=float(np.clip(self.level * 10 ** (level_db / 20), 0.05, 1.0)),
            seed=int(self.seed) * MAX_VOICES + int(seed) + 1,
        )

    @property
    def duration(self) -> float:
        """Length of the waveform, s: the last impact (of the tick or the tock) plus the
        ring."""
        last = self.sub_delays[-1] if self.sub_delays else 0.0
        if self.tock_sub_delays:
            last = max(last, self.tock_sub_delays[-1])
        return last + self.ring

    def later_impacts(self, *, tock: bool = False) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(delays (s), gains) of the secondary impacts of the tick, or of the tock."""
        if tock and self.tock_sub_delays is not None and self.tock_sub_gains is not None:
            return self.tock_sub_delays, self.tock_sub_gains
        return self.sub_delays, self.sub_gains

    def precursor_of(self, *, tock: bool = False) -> Precursor | None:
        """The `Precursor` before the ticks, or before the tocks (None: none)."""
        return self.tock_precursor if tock else self.precursor

    def impact(self, sample_rate: int, *, tock: bool = False) -> np.ndarray:
        """(L,) one impact (no secondary ones), peak 1, L = ring · sample_rate."""
        check_sample_rate(sample_rate)
        t = np.arange(int(round(self.ring * sample_rate))) / sample_rate
        shift = self.tock_shift if tock else 1.0
        slowest = self.ring / math.log(1000.0)  # amplitude time constant for −60 dB
        rng = np.random.default_rng([25, self.seed, int(tock)])
        y = np.zeros_like(t)
        for f, w, d in zip(self.resonances, self.weights, self.decays, strict=True):
            phase = rng.uniform(0, 2 * np.pi)
            if f * shift >= 0.45 * sample_rate:
                continue  # above what the sample rate holds
            y += w * np.exp(-t / (d * slowest)) * np.sin(2 * np.pi * f * shift * t + phase)
        y /= max(np.abs(y).max(), 1e-12)
        y += self.transient * rng.normal(0.0, 1.0, t.size) * np.exp(-t / TRANSIENT_DECAY)
        y *= 1.0 - np.exp(-t / ATTACK)
        return y / np.abs(y).max()

    def waveform(self, sample_rate: int, *, tock: bool = False) -> np.ndarray:
        """(L,) a tick (or, with ``tock``, a tock): the main impact at sample 0, the
        secondary impacts after it; RMS over `LOUDNESS_WINDOW` ``level · REFERENCE_RMS``
        for the tick, ``tock_gain`` times that for the tock.
        L = round(duration · sample_rate) + 1."""
        out, scale = self._impacts(sample_rate, tock)
        return out * scale

    def precursor_waveform(self, sample_rate: int, *, tock: bool = False) -> np.ndarray:
        """(L,) the precursor before a tick (or a tock): the same impact as the loud one,
        ``gain`` times as high, its onset at sample 0. L = ring · sample_rate.

        The kind must have a precursor (`precursor_of`)."""
        precursor = self.precursor_of(tock=tock)
        if precursor is None:
            kind = "tocks" if tock else "ticks"
            raise ParameterError(f"this voice has no precursor before its {kind}.")
        _, scale = self._impacts(sample_rate, tock)
        return self.impact(sample_rate, tock=tock) * (precursor.gain * scale)

    def _impacts(self, sample_rate: int, tock: bool) -> tuple[np.ndarray, float]:
        """The impacts of a tick (or a tock) summed, the main one of height 1, and the
        factor that gives the sum its loudness."""
        one = self.impact(sample_rate, tock=tock)
        out = np.zeros(int(round(self.duration * sample_rate)) + 1)
        out[: one.size] += one
        for delay, gain in zip(*self.later_impacts(tock=tock), strict=True):
            k = int(round(delay * sample_rate))
            n = min(one.size, out.size - k)
            out[k : k + n] += gain * one[:n]
        rms = np.sqrt(np.mean(out[: int(round(LOUDNESS_WINDOW * sample_rate))] ** 2))
        loudness = REFERENCE_RMS * self.level * (self.tock_gain if tock else 1.0)
        return out, loudness / rms


def voices(n: int, seed: int = 0, *, structure: str = "classic") -> list[Voice]:
    """``n`` voices that differ from each other: their main resonances are drawn in
    ``n`` separate bands spanning `RESONANCE_RANGE` (log-spaced, in shuffled order),
    so no two sound alike (the more voices, the closer their bands). The same
    (n, seed) gives the same voices; ``structure`` as in `Voice.draw`."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= MAX_VOICES:
        raise ParameterError(f"`n` must be an integer in [1, {MAX_VOICES}], got {n!r}.")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError(f"`seed` must be an integer ≥ 0, got {seed!r}.")
    rng = np.random.default_rng([26, int(seed), int(n)])
    edges = np.exp(np.linspace(*np.log(RESONANCE_RANGE), n + 1))
    order = rng.permutation(n)
    out = []
    for i in range(n):
        lo, hi = edges[order[i]], edges[order[i] + 1]
        # The middle 60 % of each band: neighbours stay apart.
        f0 = float(np.exp(rng.uniform(np.log(lo) * 0.8 + np.log(hi) * 0.2,
                                      np.log(lo) * 0.2 + np.log(hi) * 0.8)))  # fmt: skip
        out.append(Voice.draw(int(seed) * MAX_VOICES + i, main_resonance=f0, structure=structure))
    return out


def later_delays(count: int, rng: np.random.Generator) -> np.ndarray:
    """(count,) increasing delays of secondary impacts, s, uniform in `SUB_DELAY_RANGE`
    and at least 4 ms apart, so that each is an impact of its own."""
    while True:
        delays = np.sort(rng.uniform(*SUB_DELAY_RANGE, count))
        if count <= 1 or np.diff(delays).min() >= 0.004:
            return delays


def _check_impacts(delays_name: str, delays, gains_name: str, gains) -> None:
    if len(delays) != len(gains):
        raise ParameterError(
            f"`{delays_name}` and `{gains_name}` must have the same length, got "
            f"{len(delays)} and {len(gains)}."
        )
    if any(d <= 0 for d in delays) or list(delays) != sorted(delays):
        raise ParameterError(
            f"`{delays_name}` must be positive and increasing, s, got {tuple(delays)!r}."
        )
    if not all(0 < g <= 1 for g in gains):
        raise ParameterError(f"`{gains_name}` must lie in (0, 1], got {tuple(gains)!r}.")


def click_waveform(pitch: float, sample_rate: int) -> np.ndarray:
    """(L,) one click: a decaying cosine burst whose first sample is its peak, 1."""
    u = np.arange(int(round(CLICK_LENGTH * sample_rate))) / sample_rate
    taper = np.cos(0.5 * np.pi * u / CLICK_LENGTH) ** 2
    return np.exp(-u / CLICK_DECAY) * np.cos(2 * np.pi * pitch * u) * taper


def check_sample_rate(sample_rate) -> None:
    """Refuse a ``sample_rate`` no sound of ours is made at: an integer in [8000, 192000] Hz."""
    if (
        isinstance(sample_rate, bool)
        or not isinstance(sample_rate, int | np.integer)
        or not (8000 <= sample_rate <= 192000)
    ):
        raise ParameterError(
            f"`sample_rate` must be an integer in [8000, 192000] Hz, got {sample_rate!r}."
        )

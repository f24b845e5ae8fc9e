"""Tick trains: when each metronome of a synthetic recording ticks, which ticks are
tocks, and how each sounds.

``TickTrain(times, is_tock, voice, gain=1.0, levels=None, bounce_jitter_s=0.0,
precursor_leads=None)``: the time of each tick (s, at the metronome: the onset of its
loud, main impact), which ticks are tocks, the metronome's sound
(`metrosync.synthetic.ticks.Voice`), its loudness, optional per-tick level factors
(K,), how much (s, std) the secondary impacts of each tick wander about the voice's
delays, and, for a voice with a precursor, how long before each tick it comes (K,) s,
NaN where it does not (None: drawn by the recording from the voice's `Precursor`).
Build them with

- ``steady_train(bpm, duration, *, phase=0, limp=0, drift_bpm_per_min=0,
  jitter_s=0, level_jitter_db=0, tock_first=False, voice=None, gain=1, seed=0,
  bounce_jitter_s=0)``:
  a free-running metronome; ``bpm`` ticks per minute (tick and tock each count),
  the first tick at ``phase`` beats (0 ≤ phase < 1), beats alternating
  (1 ± limp/2)·T (limp = (long − short)/mean beat, a fraction, as
  `metrosync.audio.metronome` measures it), the tempo rising by
  ``drift_bpm_per_min`` BPM per minute as the spring unwinds, each tick displaced
  by independent Gaussian jitter (s, std), each tick's level by Gaussian dB.
  Locked metronomes: the same ``bpm`` (and drift) with the phases you want;
- ``simulated_trains(ds, *, run=0, voices=None, start=None, end=None)``: the ticks
  of a run of `metrosync.simulate(..., trajectories=True)`: every crossing of θ_i
  through its escapement angle, upward a tick, downward a tock (audio time 0 at
  ``start``);
- ``random_trains(n, duration, *, seed=0, bpm_range=(90, 200), locked=False,
  phase_spread=0.1, min_bpm_gap=2, same_voice=False, limp_max=0.04,
  drift_max_bpm_per_min=1, jitter_s=0.0002, level_jitter_db=0.5,
  bounce_jitter_s=0, same_make=False)``: n metronomes drawn from the seed,
  free-running (tempos at least ``min_bpm_gap`` apart) or ``locked`` (one tempo,
  phases within ``phase_spread`` beats), distinct voices unless ``same_make``
  (siblings of one voice, `Voice.sibling`) or ``same_voice`` (one voice): for
  tests over many recordings;
- ``metrosync.synthetic.ticks.voices(n, seed)``: n voices that differ from each other.
  A train built by `steady_train` without a voice gets ``Voice.draw(seed)``; give
  ``voice=`` from `voices` to metronomes that should sound different, the same
  voice to metronomes of one make.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .ticks import Voice
from .ticks import voices as draw_voices

MAX_TRAINS = 8
#: Variants of a tick (and of a tock) rendered for a train with bounce jitter.
BOUNCE_VARIANTS = 16


@dataclass(frozen=True, eq=False)
class TickTrain:
    """The ticks of one metronome.

    times : (K,) increasing times of the ticks at the metronome (the onset of each
        tick's loud, main impact), s, ≥ 0.
    is_tock : (K,) True where the tick is a tock.
    voice : the metronome's sound.
    gain : its loudness (the tick's peak is ``gain · voice.level`` before impairments).
    levels : (K,) optional factor on each tick's loudness.
    bounce_jitter_s : standard deviation of each tick's secondary-impact delays about
        the voice's, s (the pallet bounces a little differently each time; rendered
        from `BOUNCE_VARIANTS` variants of the tick and of the tock).
    precursor_leads : (K,) optional lead of the precursor before each tick, s (NaN:
        none before that tick), for a voice with a precursor; None: drawn from the
        voice's `Precursor` by the recording.
    """

    times: np.ndarray
    is_tock: np.ndarray
    voice: Voice
    gain: float = 1.0
    levels: np.ndarray | None = None
    bounce_jitter_s: float = 0.0
    precursor_leads: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not (0 <= self.bounce_jitter_s <= 0.005):
            raise ParameterError(
                f"`bounce_jitter_s` must be in [0, 0.005] s, got {self.bounce_jitter_s!r}."
            )
        times = np.asarray(self.times, dtype=float)
        is_tock = np.asarray(self.is_tock, dtype=bool)
        if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(times < 0):
            raise ParameterError(
                f"`times` must be a 1-D array of finite times ≥ 0 s, got {times!r}."
            )
        if np.any(np.diff(times) <= 0):
            raise ParameterError("`times` must be strictly increasing.")
        if is_tock.shape != times.shape:
            raise ParameterError(
                f"`is_tock` must have the shape of `times` {times.shape}, got {is_tock.shape}."
            )
        if not isinstance(self.voice, Voice):
            raise ParameterError(f"`voice` must be a Voice, got {self.voice!r}.")
        if not (math.isfinite(self.gain) and self.gain > 0):
            raise ParameterError(f"`gain` must be a number > 0, got {self.gain!r}.")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "is_tock", is_tock)
        if self.levels is not None:
            levels = np.asarray(self.levels, dtype=float)
            if levels.shape != times.shape or np.any(levels <= 0):
                raise ParameterError(
                    f"`levels` must be {times.shape} positive factors, got {levels!r}."
                )
            object.__setattr__(self, "levels", levels)
        if self.precursor_leads is not None:
            leads = np.asarray(self.precursor_leads, dtype=float)
            heard = leads[np.isfinite(leads)]
            if leads.shape != times.shape or np.any(heard <= 0) or np.any(heard >= 0.1):
                raise ParameterError(
                    f"`precursor_leads` must be {times.shape} leads in (0, 0.1) s or NaN, got "
                    f"{leads!r}."
                )
            object.__setattr__(self, "precursor_leads", leads)


def steady_train(
    bpm: float,
    duration: float,
    *,
    phase: float = 0.0,
    limp: float = 0.0,
    drift_bpm_per_min: float = 0.0,
    jitter_s: float = 0.0,
    level_jitter_db: float = 0.0,
    tock_first: bool = False,
    voice: Voice | None = None,
    gain: float = 1.0,
    seed: int = 0,
    bounce_jitter_s: float = 0.0,
) -> TickTrain:
    """A free-running metronome (see the module docstring); ticks in [0, duration)."""
    if not (math.isfinite(bpm) and 10 <= bpm <= 600):
        raise ParameterError(f"`bpm` must be in [10, 600] ticks per minute, got {bpm!r}.")
    if not (math.isfinite(duration) and duration > 0):
        raise ParameterError(f"`duration` must be > 0 s, got {duration!r}.")
    if not (0 <= phase < 1):
        raise ParameterError(f"`phase` must be in [0, 1) beats, got {phase!r}.")
    if not (0 <= limp < 0.5):
        raise ParameterError(f"`limp` must be in [0, 0.5) of a beat, got {limp!r}.")
    if not (math.isfinite(drift_bpm_per_min) and abs(drift_bpm_per_min) <= 0.5 * bpm):
        raise ParameterError(
            f"`drift_bpm_per_min` must be within ±bpm/2, got {drift_bpm_per_min!r}."
        )
    if not (0 <= jitter_s < 0.1 * 60 / bpm) or not (0 <= level_jitter_db <= 12):
        raise ParameterError(
            f"`jitter_s` must be in [0, a tenth of a beat) and `level_jitter_db` in [0, 12], "
            f"got {jitter_s!r} and {level_jitter_db!r}."
        )
    rng = np.random.default_rng([27, check_seed(seed)])
    # Beats counted since t = 0: n(t) = b t + c t² with b = bpm/60 and c = drift/7200
    # (the tempo bpm + drift·t/60); tick k (unlimped) falls where n = k + phase.
    b, c = bpm / 60.0, drift_bpm_per_min / 7200.0
    last = b * duration + c * duration**2
    beats = np.arange(0, math.ceil(max(last, 0.0)) + 2) + phase
    if c == 0:
        t = beats / b
    else:
        disc = np.maximum(b * b + 4 * c * beats, 0.0)
        t = 2 * beats / (b + np.sqrt(disc))  # the root that tends to n/b as c → 0
    period = 1.0 / (b + 2 * c * t)
    k = np.arange(t.size)
    t = t + np.where(k % 2 == 1, limp / 2, 0.0) * period  # long beat first
    if jitter_s:
        t = t + rng.normal(0.0, jitter_s, t.size)
    is_tock = (k % 2 == 1) != tock_first
    keep = (t >= 0) & (t < duration)
    t, is_tock = t[keep], is_tock[keep]
    levels = None
    if level_jitter_db:
        levels = 10 ** (rng.normal(0.0, level_jitter_db, t.size) / 20)
    voice = Voice.draw(seed) if voice is None else voice
    return TickTrain(t, is_tock, voice, gain, levels, bounce_jitter_s)


def random_trains(
    n: int,
    duration: float,
    *,
    seed: int = 0,
    bpm_range: tuple[float, float] = (90.0, 200.0),
    locked: bool = False,
    phase_spread: float = 0.1,
    min_bpm_gap: float = 2.0,
    same_voice: bool = False,
    limp_max: float = 0.04,
    drift_max_bpm_per_min: float = 1.0,
    jitter_s: float = 0.0002,
    level_jitter_db: float = 0.5,
    bounce_jitter_s: float = 0.0,
    same_make: bool = False,
) -> list[TickTrain]:
    """``n`` metronomes drawn from ``seed``, for tests over many recordings.

    Free-running (default): tempos uniform in ``bpm_range``, at least ``min_bpm_gap``
    apart; phases uniform. ``locked``: one tempo for all, phases within
    ``phase_spread`` beats of each other (in step, as on the disk), the same drift.
    Each has a limp uniform in [0, ``limp_max``], a drift uniform in
    [0, ``drift_max_bpm_per_min``], and the given timing and level jitter. Voices
    are ``voices(n, seed)`` (all different), with ``same_make`` siblings of one drawn
    voice (`Voice.sibling`: metronomes of one make, alike but not identical), or with
    ``same_voice`` one voice for all (indistinguishable by sound).
    """
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_TRAINS:
        raise ParameterError(f"`n` must be an integer in [1, {MAX_TRAINS}], got {n!r}.")
    low, high = bpm_range
    if not (10 <= low <= high <= 600):
        raise ParameterError(f"`bpm_range` must be (low, high) in [10, 600], got {bpm_range!r}.")
    if not locked and (high - low) < (n - 1) * min_bpm_gap:
        raise ParameterError(
            f"`bpm_range` {bpm_range!r} cannot hold {n} tempos `min_bpm_gap` = "
            f"{min_bpm_gap!r} apart; widen it or lower `min_bpm_gap`."
        )
    if not 0 <= phase_spread < 1:
        raise ParameterError(f"`phase_spread` must be in [0, 1) beats, got {phase_spread!r}.")
    rng = np.random.default_rng([29, check_seed(seed)])
    if locked:
        bpms = np.full(n, rng.uniform(low, high))
        base = rng.uniform(0, 1 - phase_spread)
        phases = base + rng.uniform(0, phase_spread, n)
        drifts = np.full(n, rng.uniform(0, drift_max_bpm_per_min))
    else:
        while True:
            bpms = rng.uniform(low, high, n)
            if n == 1 or np.diff(np.sort(bpms)).min() >= min_bpm_gap:
                break
        phases = rng.uniform(0, 1, n)
        drifts = rng.uniform(0, drift_max_bpm_per_min, n)
    if same_voice:
        sounds = [Voice.draw(int(seed))] * n
    elif same_make:
        sounds = [Voice.draw(int(seed)).sibling(i) for i in range(n)]
    else:
        sounds = draw_voices(n, int(seed))
    return [
        steady_train(
            float(bpms[i]),
            duration,
            phase=float(phases[i]),
            limp=float(rng.uniform(0, limp_max)),
            drift_bpm_per_min=float(drifts[i]),
            jitter_s=jitter_s,
            level_jitter_db=level_jitter_db,
            voice=sounds[i],
            seed=int(seed) * MAX_TRAINS + i,
            bounce_jitter_s=bounce_jitter_s,
        )
        for i in range(n)
    ]


def simulated_trains(
    ds, *, run: int = 0, voices: Sequence[Voice] | None = None, start=None, end=None
) -> list[TickTrain]:
    """The ticks of run ``run`` of a simulated dataset (with trajectories), one train
    per metronome: upward crossings of the escapement angle are ticks, downward ones
    tocks; times from ``start`` (default: the first record) to ``end``."""
    from metrosync.show.recording import RecordedRun
    from metrosync.show.sound import crossing_times

    recorded = RecordedRun.from_dataset(ds, run)
    start, end = recorded.window(start, end)
    voices = draw_voices(recorded.n) if voices is None else list(voices)
    if len(voices) != recorded.n:
        raise ParameterError(
            f"`voices` must hold one voice per metronome ({recorded.n}), got {len(voices)}."
        )
    trains = []
    for i, times in enumerate(crossing_times(recorded)):
        times = times[(times >= start) & (times < end)]
        downward = recorded.theta_dot_at(times)[:, i] < 0
        trains.append(TickTrain(times - start, downward, voices[i]))
    return trains


def check_seed(seed) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError(f"`seed` must be an integer ≥ 0, got {seed!r}.")
    return int(seed)

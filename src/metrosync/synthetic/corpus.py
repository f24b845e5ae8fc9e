"""The benchmark corpus: frozen, versioned phone recordings of metronomes with their
truth, in a development split and a held-out split drawn from different seeds.

Each split (`SPLITS`, a `CorpusSpec`) holds

- ``mixed`` recordings of 1 to 4 metronomes, as many of each number (recording j has
  1 + j mod 4), ``duration`` s each, one for each seed of ``mixed_seeds``;
- ``singles`` single-metronome recordings of each tick structure of `STRUCTURES`,
  ``single_duration`` s each, for the check that one metronome is never counted as
  two. The structures share the seeds ``single_seeds``: recording j of each is the
  same metronome (make, tempo, limp, room) but for the structure of its ticks.

A recording of seed s draws, from its own generator ([`KEY`, kind, s]):

- each metronome's tick structure (mixed: uniform over `STRUCTURES`; singles: the
  one asked) on a voice of its own make (`voices`: distinct makes; widened by
  `widen`);
- tempo uniform in `BPM_RANGE` (mixed: at least `MIN_BPM_GAP` apart), phase uniform,
  limp uniform in [0, `LIMP_MAX`], tempo drift uniform in ±`DRIFT_MAX` BPM a
  minute, escapement jitter uniform in `JITTER_RANGE` (the loud impacts' timing
  spread), loudness uniform in `GAIN_RANGE`, 0.5 dB of level jitter from tick to tick;
- every impairment of `Impairments.phone()`: reverberation (RT60 uniform in
  `RT60_RANGE`), pink noise (SNR uniform in `SNR_RANGE` dB), 1 to 3 handling bumps,
  the phone's band, compression, made at 48 kHz and resampled to 44.1 kHz, 16 bits.

`VERSION` names all of this: a recording of (version, split, kind, index) is the same
on every run, made on the fly (no audio is kept). Anything that changes a recording
of a split (a range, a count, the order of the draws, a generator's model) needs a new
version, and scores are comparable only within one. Tune on ``dev``; report on
``heldout``.

`entries(split)` lists the recordings of a split (`Entry`), `Entry.plan()` says what
was drawn (`Plan`, for the scores), `Plan.recording()` makes it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .impairments import Impairments
from .recording import Recording, make_recording
from .structures import STRUCTURES, widen
from .ticks import voices
from .trains import TickTrain, steady_train

#: The corpus's version: what every recording of every split is.
VERSION = "1"
#: The first number of every seed the corpus draws from.
KEY = 36
BPM_RANGE = (60.0, 208.0)  # a mechanical metronome's dial
MIN_BPM_GAP = 2.0
LIMP_MAX = 0.05
DRIFT_MAX = 1.0  # BPM a minute, either way
JITTER_RANGE = (0.3e-3, 1.0e-3)  # s: the escapement's
GAIN_RANGE = (0.6, 1.0)
LEVEL_JITTER_DB = 0.5
RT60_RANGE = (0.25, 0.6)  # s
SNR_RANGE = (20.0, 40.0)  # dB
BUMPS = (1, 3)  # handling bumps in a recording, at least and at most
SAMPLE_RATE = 44100
KINDS = ("mixed", "single")


@dataclass(frozen=True)
class CorpusSpec:
    """One split: the seeds of its recordings and their lengths.

    mixed_seeds : one recording of 1 to 4 metronomes for each.
    single_seeds : one single-metronome recording of each tick structure for each.
    duration, single_duration : their lengths, s.
    """

    name: str
    mixed_seeds: range
    single_seeds: range
    duration: float = 40.0
    single_duration: float = 20.0


#: The splits, by name: seeds of one never those of another.
SPLITS: dict[str, CorpusSpec] = {
    "dev": CorpusSpec("dev", range(100_000, 100_120), range(110_000, 110_200)),
    "heldout": CorpusSpec("heldout", range(900_000, 900_120), range(910_000, 910_200)),
}


@dataclass(frozen=True)
class Metronome:
    """What was drawn for one metronome of a recording."""

    structure: str
    bpm: float
    phase: float
    limp: float
    drift_bpm_per_min: float
    jitter_s: float
    gain: float


@dataclass(frozen=True)
class Plan:
    """What was drawn for one recording: its metronomes, its impairments, its length."""

    metronomes: tuple[Metronome, ...]
    impairments: Impairments
    duration: float
    seed: int

    def trains(self) -> list[TickTrain]:
        """The metronomes' tick trains: voices of distinct makes (`voices`), each
        widened to its structure."""
        sounds = voices(len(self.metronomes), self.seed)
        return [
            steady_train(
                m.bpm,
                self.duration,
                phase=m.phase,
                limp=m.limp,
                drift_bpm_per_min=m.drift_bpm_per_min,
                jitter_s=m.jitter_s,
                level_jitter_db=LEVEL_JITTER_DB,
                voice=widen(sounds[i], m.structure),
                gain=m.gain,
                seed=self.seed * 8 + i,
            )
            for i, m in enumerate(self.metronomes)
        ]

    def recording(self) -> Recording:
        """The recording, with its truth (`make_recording`)."""
        return make_recording(self.trains(), sample_rate=SAMPLE_RATE,
                              impairments=self.impairments, duration=self.duration,
                              seed=self.seed)  # fmt: skip


@dataclass(frozen=True)
class Entry:
    """One recording of a split: its kind ("mixed" or "single"), its index among those
    of its kind (and structure), its seed, how many metronomes, and for a single one
    its structure."""

    split: str
    kind: str
    index: int
    seed: int
    metronomes: int
    structure: str | None = None

    @property
    def name(self) -> str:
        part = self.kind if self.structure is None else f"{self.kind}-{self.structure}"
        return f"{self.split}/{part}/{self.index}"

    def plan(self) -> Plan:
        """What this recording is made of, drawn from its seed."""
        spec = SPLITS[self.split]
        kind = KINDS.index(self.kind)
        rng = np.random.default_rng([KEY, kind, self.seed])
        n = self.metronomes
        if self.structure is None:
            names = list(STRUCTURES)
            structures = [names[int(i)] for i in rng.integers(len(names), size=n)]
        else:
            structures = [self.structure] * n
        while True:
            bpms = rng.uniform(*BPM_RANGE, n)
            if n == 1 or np.diff(np.sort(bpms)).min() >= MIN_BPM_GAP:
                break
        metronomes = tuple(
            Metronome(
                structure=structures[i],
                bpm=float(bpms[i]),
                phase=float(rng.uniform(0, 1)),
                limp=float(rng.uniform(0, LIMP_MAX)),
                drift_bpm_per_min=float(rng.uniform(-DRIFT_MAX, DRIFT_MAX)),
                jitter_s=float(rng.uniform(*JITTER_RANGE)),
                gain=float(rng.uniform(*GAIN_RANGE)),
            )
            for i in range(n)
        )
        impairments = Impairments.phone(
            reverb_rt60=float(rng.uniform(*RT60_RANGE)),
            snr_db=float(rng.uniform(*SNR_RANGE)),
            bumps=int(rng.integers(BUMPS[0], BUMPS[1] + 1)),
        )
        duration = spec.duration if self.kind == "mixed" else spec.single_duration
        return Plan(metronomes, impairments, duration, self.seed)

    def recording(self) -> Recording:
        return self.plan().recording()


def entries(split: str) -> list[Entry]:
    """The recordings of ``split`` (a name in `SPLITS`): the mixed ones in order, then
    the single ones of each structure in turn."""
    if split not in SPLITS:
        raise ParameterError(
            f"`split` must be one of {', '.join(map(repr, SPLITS))}, got {split!r}."
        )
    spec = SPLITS[split]
    out = [Entry(split, "mixed", j, seed, 1 + j % 4) for j, seed in enumerate(spec.mixed_seeds)]
    for structure in STRUCTURES:
        out += [
            Entry(split, "single", j, seed, 1, structure)
            for j, seed in enumerate(spec.single_seeds)
        ]
    return out

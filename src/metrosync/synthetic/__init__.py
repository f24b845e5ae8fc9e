"""Synthetic data: metronomes' ticks and recordings of them with their truth, apart
from the analysis they test.

The modules, each a part of one generative model:

- `ticks`: the sound of one tick (`Voice`, drawn from a seed; `voices` for several
  that differ; a `Precursor` before the loud impact; `click_waveform`, a plain click);
- `structures`: what different makes' ticks are made of (`STRUCTURES`: "classic",
  "uneven", "precursor");
- `trains`: when each metronome ticks (`TickTrain`; `steady_train`, `random_trains`,
  `simulated_trains`);
- `impairments`: what the room, the phone and the hand do (`Impairments`);
- `recording`: the sum heard by one or more microphones, with the truth of every
  tick (`make_recording` → `Recording`);
- `corpus`: the frozen benchmark corpus, versioned, in a development and a held-out
  split (`corpus.SPLITS`, `corpus.entries`; scored by benchmarks/audio_corpus.py);
- `clicks`: click-track recordings for tests of the detector;
- `score`: the yardstick an analysis is scored with against the truth.

Used by `metrosync listen` (its realistic ticks), the tests and the benchmarks; the
analysis (`metrosync.audio`) never imports it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .impairments import Impairments
    from .recording import MAX_MICROPHONES, Microphone, Recording, TrainTruth, make_recording
    from .structures import STRUCTURES, TickStructure, widen
    from .ticks import Precursor, Voice, click_waveform, voices
    from .trains import MAX_TRAINS, TickTrain, random_trains, simulated_trains, steady_train

#: Where each public name lives. They are loaded when first asked for, so that
#: `metrosync listen` (which needs only `ticks`) does not load the recording's filters.
_HOME = {
    "Impairments": "impairments",
    "MAX_MICROPHONES": "recording",
    "Microphone": "recording",
    "Recording": "recording",
    "TrainTruth": "recording",
    "make_recording": "recording",
    "STRUCTURES": "structures",
    "TickStructure": "structures",
    "widen": "structures",
    "Precursor": "ticks",
    "Voice": "ticks",
    "click_waveform": "ticks",
    "voices": "ticks",
    "MAX_TRAINS": "trains",
    "TickTrain": "trains",
    "random_trains": "trains",
    "simulated_trains": "trains",
    "steady_train": "trains",
}

__all__ = [
    "MAX_MICROPHONES", "MAX_TRAINS", "STRUCTURES", "Impairments", "Microphone", "Precursor",
    "Recording", "TickStructure", "TickTrain", "TrainTruth", "Voice", "click_waveform",
    "make_recording", "random_trains", "simulated_trains", "steady_train", "voices", "widen",
]  # fmt: skip


def __getattr__(name: str):
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))

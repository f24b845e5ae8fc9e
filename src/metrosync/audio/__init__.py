"""Listen to real metronomes: ticks, tempo, beat and synchrony from a sound recording.

One entry point, `analyze_audio(path)`; the steps are modules of their own:
`reader` (files, in blocks), `detection` (tick onsets), `tempo` (the beat period),
`metronome` (one metronome's tempo, jitter and beat), `order` (the acoustic order
parameter and clusters), `attribution` (two metronomes told apart), `plots`.
"""

from .dataset import analyze_audio
from .reader import AUDIO_SUFFIXES, AudioFileError, is_audio_path, open_recording

__all__ = ["AUDIO_SUFFIXES", "AudioFileError", "analyze_audio", "is_audio_path", "open_recording"]

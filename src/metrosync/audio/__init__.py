"""Listen to real metronomes: ticks, tempo, beat and synchrony from a sound recording.

One entry point, `analyze_audio(path)` (`analysis`), the timing model of docs/sound.md;
the steps are modules of their own:
`reader` (files, in blocks), `detection` (impact onsets), `voices` (each impact's
sound: its features), `periodicity` (candidate tempi by epoch folding), `timing` (a
metronome's timing model: phase, period, limp, drift, jitter), `wander` (its beat's
smooth wander), `structure` (a tick's impacts learned from the recording, and a
metronome followed), `sounds` (each metronome's sound, and whose an onset is by it),
`decompose` (the onsets explained as metronomes and clutter), `seek` (beats no onset
was detected at, sought where the timing puts them), `waveform` (each metronome's
learned waveform, and its ticks timed against it), `together` (several microphones
aligned), `metronome` (one metronome's tempo, jitter and beat), `order` (the acoustic
order parameter and clusters), `attribution` (the phase of one metronome in another's
beat), `tempo` (the beat period of ticks nobody told apart), `dataset` (the dataset's
variables), `summary` and `plots`.
`analyze_audio` is imported on first use (it needs scipy and xarray), so that the
reader's checks stay quick to import.
"""

from .reader import AUDIO_SUFFIXES, AudioFileError, is_audio_path, open_recording

__all__ = ["AUDIO_SUFFIXES", "AudioFileError", "analyze_audio", "is_audio_path", "open_recording"]


def __getattr__(name: str):
    if name == "analyze_audio":
        from .analysis import analyze_audio

        return analyze_audio
    raise AttributeError(f"module 'metrosync.audio' has no attribute {name!r}")

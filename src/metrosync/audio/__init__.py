"""Listen to real metronomes: ticks, tempo, beat and synchrony from a sound recording.

One entry point, `analyze_audio(path)`; the steps are modules of their own:
`reader` (files, in blocks), `detection` (tick onsets), `tempo` (the beat period),
`voices` (each impact's sound, clustered), `trains` (impacts grouped into ticks,
ticks followed as one train per metronome), `separation` (the two together: the
metronomes told apart), `subdivision` (a train on every k-th beat of its metronome
given the beats between), `interleaved` (one metronome followed as two trains, each
on its own kind of beat and the other kind's later impacts, joined), `fills` (a
train made of another's missed beats, given back to it), `recovery`
(ticks another hid, found again), `templates`
(each metronome's learned sound: ticks in another's ring timed on it), `together`
(several microphones aligned), `metronome` (one metronome's tempo, jitter and beat),
`order` (the acoustic order parameter and clusters), `attribution` (the phase of one
metronome in another's beat), `plots`.

The timing model that is to replace the stages (`timing_analysis.analyze_timing`,
``metrosync analyze --analysis timing``; docs/sound.md) is made of `timing` (a
metronome's timing model), `wander` (its beat's smooth wander), `periodicity`
(candidate tempi by epoch folding), `structure` (a tick's impacts learned from the
recording, and a metronome followed), `decompose` (the onsets explained as metronomes
and clutter), `sounds` (each metronome's sound, and whose an onset is by it) and
`seek` (beats no onset was detected at, sought where the timing puts them).
`analyze_audio` is imported on first use (it needs scipy and xarray), so that the
reader's checks stay quick to import.
"""

from .reader import AUDIO_SUFFIXES, AudioFileError, is_audio_path, open_recording

__all__ = ["AUDIO_SUFFIXES", "AudioFileError", "analyze_audio", "is_audio_path", "open_recording"]


def __getattr__(name: str):
    if name == "analyze_audio":
        from .dataset import analyze_audio

        return analyze_audio
    raise AttributeError(f"module 'metrosync.audio' has no attribute {name!r}")

"""Metronome death: a metronome whose escapement no longer fires.

The escapement gives its impulse only when the pendulum swings through the
escapement's angle δ (``escapement_offset``, 0 in the paper). A swing that no longer
reaches δ gets no drive, and the pendulum decays like an undriven one. Goldsztein,
Nadeau and Strogatz call this "metronome death" and observed it, with "suppression" of
the oscillation by the platform, in real metronomes (Chaos 32, 043119 (2022)). In the
model it happens when δ lies beyond the swing (a start below δ, or a swing worn down
by friction, dry friction on the disk, a strong applied torque or a small drive).

Decaying pendulums can swing in step (with the escapement beyond every swing, seven
of them on the default disk end at r = 1.0000): a run with a dead metronome can look
synchronized when it is not. Every integrator therefore
keeps the time of each metronome's last impulse (``last_kick``), and a run in which
some metronome's last impulse is older than `SILENT_PERIODS` of its periods at the
end is flagged `metrosync.status.STATUS_STOPPED`. A live metronome gives two
impulses per period, so this leaves room for a slower swing; a run shorter than that
span is not judged.
"""

from __future__ import annotations

import numpy as np

from ..status import STATUS_DIVERGED, STATUS_STOPPED

#: A metronome whose last impulse is older than this many of its natural periods at
#: the end of the run has stopped.
SILENT_PERIODS = 2.0


def stopped_metronomes(last_kick, duration: float, omega) -> np.ndarray:
    """Which metronomes' escapements have stopped firing by the end of the run.

    last_kick : (B, N) time of each metronome's last impulse, s; negative for none.
    duration : the run's length, s.   omega : (B, N) natural angular frequencies, rad/s.
    Returns (B, N) bool: no impulse within the last `SILENT_PERIODS` periods
    2π/ω (False where the run is shorter than that).
    """
    span = SILENT_PERIODS * 2.0 * np.pi / np.asarray(omega, dtype=float)
    last = np.asarray(last_kick, dtype=float)
    return (duration >= span) & (last < duration - span)


def flag_stopped(status, last_kick, duration: float, omega) -> np.ndarray:
    """``status`` (B,) with `STATUS_STOPPED` set on the runs with a stopped metronome
    (`stopped_metronomes`), except those that diverged (they stopped at that step)."""
    status = np.array(status, copy=True)
    dead = stopped_metronomes(last_kick, duration, omega).any(axis=1)
    dead &= (status & STATUS_DIVERGED) == 0
    status[dead] |= STATUS_STOPPED
    return status

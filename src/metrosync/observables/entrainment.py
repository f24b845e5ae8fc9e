"""Entrainment of a metronome by a periodic drive: the phase lag between the two, and
whether it stays bounded.

The drive is the disk's applied torque A sin(Ω t), Ω = π·BPM/60 (the metronomes'
convention: a drive at a metronome's BPM has its period). At the k-th upward zero
crossing t_k of the metronome, the drive's phase is Ω t_k; the *lag*

    ψ_k = Ω (t_k − t_0) − 2π k

is constant when the metronome is locked 1:1 to the drive and falls behind (or runs
ahead) by 2π at each phase slip otherwise. A run counts as entrained when ψ varies by
less than π over a final window (`is_entrained`).

Resolution: near the edge of a locking range the slips become rare (their period
diverges as the edge is approached), so a window W tells a locked run from a slowly
slipping one only down to a frequency detuning of order (π/W)²/(2K), K the half-width
of the range in rad/s; and a run must have had time to lock (a few 1/K) before the
window starts. Choose the run length and the window with both in mind.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..model.metronome import bpm_to_omega


def upward_crossings(time, theta) -> np.ndarray:
    """Times at which a sampled angle crosses 0 upwards, linearly interpolated between
    samples. time, theta : (T,). Returns (K,)."""
    time = np.asarray(time, dtype=float)
    theta = np.asarray(theta, dtype=float)
    k = np.nonzero((theta[:-1] < 0) & (theta[1:] >= 0))[0]
    return time[k] + (time[k + 1] - time[k]) * theta[k] / (theta[k] - theta[k + 1])


def forcing_lag(crossings, forcing_bpm: float) -> np.ndarray:
    """The lag ψ_k = Ω (t_k − t_0) − 2π k of the drive at each upward crossing t_k, rad,
    (K,): constant when locked 1:1, changing by 2π at each phase slip."""
    crossings = np.asarray(crossings, dtype=float)
    if crossings.size == 0:
        return crossings
    omega = float(bpm_to_omega(forcing_bpm))
    return omega * (crossings - crossings[0]) - 2 * np.pi * np.arange(crossings.size)


def is_entrained(time, theta, forcing_bpm: float, *, window: float) -> bool:
    """Whether one metronome's swing ``theta`` (sampled at ``time``) is locked 1:1 to a
    drive at ``forcing_bpm``: its lag varies by less than π over the crossings in the
    last ``window`` seconds (see the module docstring for the resolution).

    Raises `ParameterError` when the window holds fewer than three crossings."""
    time = np.asarray(time, dtype=float)
    crossings = upward_crossings(time, theta)
    crossings = crossings[crossings >= time[-1] - window]
    if crossings.size < 3:
        raise ParameterError(
            f"`window` = {window!r} s holds {crossings.size} upward crossings; at least 3 "
            f"are needed to judge entrainment. Lengthen the run or the window."
        )
    return bool(np.ptp(forcing_lag(crossings, forcing_bpm)) < np.pi)

"""
Does a periodic torque on the disk entrain a metronome?
=======================================================

Turn the disk back and forth with a torque A sin(Ω t) and a single metronome on it
locks to the drive when Ω is close to its own rate, and drifts past it farther away.
The locking range (an Arnold tongue) grows linearly with A.
"""

import matplotlib.pyplot as plt
import numpy as np

import metrosync as ms
from metrosync.observables.entrainment import is_entrained

drive_bpms = np.arange(182.7, 186.8, 0.5)
amplitudes = np.array([0.005, 0.01, 0.02])
locked = np.zeros((amplitudes.size, drive_bpms.size), dtype=bool)
for i, amplitude in enumerate(amplitudes):
    for j, bpm in enumerate(drive_bpms):
        ds = ms.simulate(1, 192.0, duration=300, theta0=[0.76], trajectories=True,
                         record_every=2,
                         changes={"forcing_amplitude": float(amplitude), "forcing_bpm": float(bpm)})
        theta = ds.theta.isel(run=0, metronome=0)
        locked[i, j] = is_entrained(ds.time, theta, float(bpm), window=150)

fig, ax = plt.subplots(figsize=(6, 3.2))
for i, amplitude in enumerate(amplitudes):
    ax.scatter(drive_bpms, np.full(drive_bpms.size, amplitude * 1e3),
               c=np.where(locked[i], "tab:blue", "white"), edgecolors="tab:blue", s=60)
ax.set_xlabel("drive frequency (BPM); the metronome alone ticks at 184.7")
ax.set_ylabel("A (mN m)")
ax.set_title("filled: locked to the drive")
fig.tight_layout()

"""
Can I hear two metronomes lock?
===============================

``write_wav`` renders a simulated run as a stereo click track, one click per tick, as
``metrosync listen`` does; ``analyze_audio`` listens to a recording (here that track,
from a phone it would be the same call), tells the metronomes apart and times their
ticks. The phase of metronome 1's ticks in metronome 0's beat drifts, then settles:
the two have locked, about a third of a beat apart.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import metrosync as ms

ds = ms.simulate(2, 192.0, sigma_bpm=0.75, runs=1, duration=120, seed=1, trajectories=True)
with tempfile.TemporaryDirectory() as folder:
    wav = Path(folder) / "two.wav"
    ms.write_wav(ds, wav)
    heard = ms.analyze_audio(wav)
print(heard.summary)

fig, ax = plt.subplots(figsize=(6, 3.5))
second = heard.tick_metronome == 1
ax.plot(heard.tick_time[second], np.degrees(heard.phase_difference[second]), ".", ms=3)
ax.set_xlabel("time (s)")
ax.set_ylabel("phase of 1's ticks in 0's beat (°)")
fig.tight_layout()

"""
What does a light-gate log look like, and what does analyze make of it?
========================================================================

The paper's experiment times each metronome's passes through a light gate. A virtual
gate turns a simulated run into the logger's own format, so that ``analyze`` (the
same code that reads a real capture) can be compared with the simulation's r.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import metrosync as ms
from metrosync.lightgate.virtual import write_logs

ds = ms.simulate(3, 192.0, sigma_bpm=0.75, runs=1, duration=90, seed=4, trajectories=True,
                 record_every=1)
with tempfile.TemporaryDirectory() as folder:
    (log,) = write_logs(ds, folder)
    print("".join(Path(log).read_text().splitlines(keepends=True)[:6]))
    measured = ms.analyze([log])

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(ds.time, ds.r_crossing.isel(run=0), label="simulation (crossings)")
ax.plot(measured.time, measured.r, "--", label="analyze, from the log")
ax.set_xlabel("time (s)")
ax.set_ylabel("r")
ax.legend()
fig.tight_layout()

"""
Is the disk really what couples the metronomes?
===============================================

Pin the disk (infinite moment of inertia) and the metronomes become independent
pendulums on a rigid support: r stays where the random start put it. Let the disk
turn and the same metronomes, started the same way, fall into step.
"""

import math

import matplotlib.pyplot as plt

import metrosync as ms

fig, ax = plt.subplots(figsize=(6, 3.5))
for label, changes in (("free disk", None), ("pinned disk", {"inertia": math.inf})):
    ds = ms.simulate(7, 192.0, runs=8, duration=200, seed=5, changes=changes)
    ax.plot(ds.time, ds.r.mean("run"), label=label)
ax.set_xlabel("time (s)")
ax.set_ylabel("r, mean of 8 runs")
ax.set_ylim(0, 1)
ax.legend()
fig.tight_layout()

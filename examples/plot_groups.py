"""
What happens to two groups tuned 20 BPM apart?
==============================================

Seven metronomes at 184 BPM and seven at 204 BPM on one disk. Each group falls into
step by itself (its own r → 1), but the groups keep their own tempos, so the order
parameter of all fourteen beats between nearly 0 and nearly 1.
"""

import matplotlib.pyplot as plt

import metrosync as ms

ds = ms.simulate(None, None, groups=[(7, 184.0), (7, 204.0)], sigma_bpm=0.25, runs=1,
                 duration=200, seed=3)
run = ds.isel(run=0)
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(run.time, run.r, color="0.6", lw=0.8, label="all 14")
for g in range(run.sizes["group"]):
    bpm = float(run.group_bpm[g])
    ax.plot(run.time, run.r_group.isel(group=g), label=f"group at {bpm:.0f} BPM")
ax.set_xlabel("time (s)")
ax.set_ylabel("r")
ax.legend(loc="lower right")
fig.tight_layout()

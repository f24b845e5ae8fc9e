"""
Which integrator, and how small a step?
=======================================

``verlet`` gives each escapement kick at the end of the step in which the pendulum
crosses the vertical, so with kicks it converges at first order; ``located`` applies
each kick at its own instant and stays second order. Both against ``exact`` (DOP853)
over 5 s for two metronomes.
"""

import matplotlib.pyplot as plt
import numpy as np

import metrosync as ms

start = dict(frequencies_bpm=[192.0, 192.0], theta0=[0.1, -0.05], duration=5.0,
             trajectories=True)
exact = ms.simulate(None, None, integrator="exact", dt=0.01, record_every=10, **start)
dts = np.array([0.01, 0.005, 0.002, 0.001, 0.0005])  # each divides the 0.1 s record
fig, ax = plt.subplots(figsize=(6, 3.5))
for name in ("verlet", "located"):
    errors = []
    for dt in dts:
        ds = ms.simulate(None, None, integrator=name, dt=dt, record_every=int(round(0.1 / dt)),
                         **start)
        errors.append(float(np.max(np.abs(ds.theta.values - exact.theta.values))))
    slope = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    ax.loglog(dts, errors, "o-", label=f"{name}: slope {slope:.2f}")
ax.set_xlabel("time step dt (s)")
ax.set_ylabel("largest angle error over 5 s (rad)")
ax.legend()
fig.tight_layout()

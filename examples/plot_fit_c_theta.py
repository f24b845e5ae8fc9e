"""
How do I fit c_θ to my metronome?
=================================

Stop the escapement (or take the key out), stand the metronome on a table and let it
swing down: the decay of its amplitude gives the pivot's friction c_θ. Here the
"metronome" is simulated with the drive off on a pinned disk, so the answer is
known (5 × 10⁻⁵ kg m²/s); with a real one, record the decay with a light gate and use
``metrosync calibrate c-theta --log decay.log --offset 0.1``.
"""

import matplotlib.pyplot as plt

import metrosync as ms
from metrosync.calibration.damping import c_theta_from_trajectory

ds = ms.simulate(1, 192.0, duration=30, theta0=[0.7], theta_dot0=[0.0], trajectories=True,
                 record_every=1, changes={"drive": 0.0, "inertia": float("inf")})
metronome = ms.get_preset("default").metronome.with_l2(float(ds.l2.isel(run=0, metronome=0)))
fit = c_theta_from_trajectory(ds.time.values, ds.theta.isel(run=0, metronome=0).values,
                              metronome=metronome)
print(f"c_theta = {fit.value:.4g} {fit.unit} (true {ds.attrs['c_theta']:.4g})")

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(fit.x, fit.y, ".", label="each swing")
ax.plot(fit.fit_x, fit.fit_y, "-", label=f"fit: c_θ = {fit.value:.3g} {fit.unit}")
ax.set_xlabel(fit.xlabel)
ax.set_ylabel(fit.ylabel)
ax.set_title(fit.title)
ax.legend()
fig.tight_layout()

"""
What does the phase-model reduction predict?
============================================

Near the onset each metronome behaves like a phase oscillator, and the ensemble like
the Kuramoto–Sakaguchi model with coupling K and phase lag α. Its incoherent state
loses stability at K_c (``metrosync.theory.onset``); the simulated phase model shows r
leaving zero there. K and σ are in rad/s here; the theory page measures K(ω₀) and
α(ω₀) on the full model.
"""

import matplotlib.pyplot as plt
import numpy as np

import metrosync as ms
from metrosync.theory import onset

sigma, alpha = 0.05, np.deg2rad(-26.0)
couplings = np.linspace(0.0, 0.25, 11)
r_eq = [float(ms.simulate_reduced(2000, k=float(k), alpha=alpha, sigma=sigma, duration=400,
                                  seed=1).r_eq.mean()) for k in couplings]
k_c = onset(alpha, sigma).k_c

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(couplings, r_eq, "o-", label="simulated, N = 2000")
ax.axvline(k_c, color="tab:red", ls="--", label=f"linear threshold K_c = {k_c:.3f} rad/s")
ax.set_xlabel("coupling K (rad/s)")
ax.set_ylabel("equilibrium r")
ax.legend()
fig.tight_layout()

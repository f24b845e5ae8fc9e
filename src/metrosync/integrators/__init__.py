"""Integrators, picked by name.

``verlet``  the paper's fixed-step scheme with the discrete ±M/dt kick (compiled).
``exact``   DOP853 between impulses, with each crossing located and kicked exactly.
"""

INTEGRATORS = ("verlet", "exact")

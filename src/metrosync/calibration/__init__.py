"""Parameter estimation (paper §5): c_θ, M and c_φ from measurements.

``pendulum``  exact amplitude relations of one pendulum (envelope, gate timing)
``damping``   c_θ from a free decay (trajectory or light-gate log)
``drive``     M from a steady amplitude, by solving the model
``platform``  c_φ from the synchronized disk's amplitude, by solving the model
``estimate``  the `Estimate` result, with a plot of each fit
"""

from .damping import c_theta_from_log, c_theta_from_trajectory, fit_c_theta
from .drive import fit_drive, simulated_steady_amplitude
from .estimate import Estimate
from .platform import disk_amplitude, fit_c_phi

__all__ = [
    "Estimate",
    "c_theta_from_log",
    "c_theta_from_trajectory",
    "disk_amplitude",
    "fit_c_phi",
    "fit_c_theta",
    "fit_drive",
    "simulated_steady_amplitude",
]

"""Compiled pieces of the ``located`` scheme shared by its layouts: one escapement
impulse applied at its crossing instant (see `located` for the scheme).

Everything is built from the `_physics` functions, used for their linearity in the
kick and in φ̈: `pendulum_terms` with an impulse (N m s) in place of the kick torque
gives the impulse's direct velocity jump and its share of φ̈'s numerator,
`disk_acceleration` then gives the disk's velocity jump, and `theta_ddot` with zero
``rest`` the jump of any pendulum through the disk. A model term added to those
functions therefore reaches this scheme too.
"""

from __future__ import annotations

import numba as nb

from ._physics import (
    disk_acceleration,
    disk_torque,
    escapement_angle,
    pendulum_terms,
    theta_ddot,
)
from .trig import sincos


@nb.njit(cache=True, inline="always")
def crossing_time(c, m, theta, theta_next, dt):
    """Time from the step's start at which metronome ``m`` crosses its escapement angle,
    interpolated linearly between the step's ends ``theta`` and ``theta_next``."""
    level = escapement_angle(c, m)
    return dt * (theta - level) / (theta - theta_next)


@nb.njit(cache=True, inline="always")
def kick(c, m, r, impulse, frac, den_start, den_end, sin_end, cos_end, vel_end, q_end, phi_dot_end):  # fmt: skip  # noqa: E501
    """One escapement impulse (N m s) on metronome ``m`` at the fraction ``frac`` of the
    step, and what it changes in the velocity-dependent forces.

    The impulse acts with the kicked pendulum at its escapement angle and the others'
    geometry interpolated between the step's ends: Σ q_j²/I_j is ``den_start`` +
    ``frac`` (``den_end`` − ``den_start``). Its effect on the forces is evaluated at the
    step's end, where the kicked pendulum has angle θ' (``sin_end``, ``cos_end``, q'),
    predicted velocity ``vel_end`` and the disk ``phi_dot_end``.

    Returns
    -------
    dv : the kicked pendulum's own velocity jump (M/I); every pendulum j, itself
        included, also jumps by ``theta_ddot(c, j, r, 0, q_j, dphi_dot)``.
    dforce : the disk's momentum jump (the escapement's reaction).
    dphi_dot : the disk's velocity jump.
    jrest, jforce, jphi : the jump of the kicked pendulum's ``rest``, of the disk
        torque F and of φ̈ caused by the velocity jumps.
    """
    s_lev, c_lev = sincos(escapement_angle(c, m))
    rest1, _, num1, _ = pendulum_terms(c, m, impulse, s_lev, c_lev, 0.0)
    rest0, _, num0, _ = pendulum_terms(c, m, 0.0, s_lev, c_lev, 0.0)
    dv = rest1 - rest0
    dforce = disk_torque(c, r, 0.0, impulse) - disk_torque(c, r, 0.0, 0.0)
    den = den_start + frac * (den_end - den_start)
    dphi_dot = disk_acceleration(c, r, num1 - num0, den, dforce)
    own = dv + theta_ddot(c, m, r, 0.0, q_end, dphi_dot)
    rest_b, _, num_b, _ = pendulum_terms(c, m, 0.0, sin_end, cos_end, vel_end + own)
    rest_a, _, num_a, _ = pendulum_terms(c, m, 0.0, sin_end, cos_end, vel_end)
    jforce = disk_torque(c, r, phi_dot_end + dphi_dot, 0.0) - disk_torque(c, r, phi_dot_end, 0.0)
    jphi = disk_acceleration(c, r, num_b - num_a, den_end, jforce)
    return dv, dforce, dphi_dot, rest_b - rest_a, jforce, jphi

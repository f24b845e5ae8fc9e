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

from ._physics import disk_torque, escapement_angle, pendulum_terms
from .trig import sincos


@nb.njit(cache=True, inline="always")
def crossing_fraction(c, m, theta, theta_next):
    """The fraction of the step at which metronome ``m`` crosses its escapement angle,
    interpolated linearly between the step's ends ``theta`` and ``theta_next``."""
    level = escapement_angle(c, m)
    return (theta - level) / (theta - theta_next)


@nb.njit(cache=True, inline="always")
def kick(c, m, r, impulse, theta_dot):
    """An escapement impulse (N m s) on metronome ``m`` at its escapement angle, moving
    at ``theta_dot`` just before it.

    Returns
    -------
    dv : the pendulum's own velocity jump, M/I; with the disk's jump Δφ̇ =
        ``disk_acceleration(c, r, dnum, den, dforce)`` every pendulum j, itself
        included, also jumps by ``theta_ddot(c, j, r, 0, q_j, Δφ̇)``.
    dnum, dforce : the impulse's share of φ̈'s numerator sum and of the disk torque
        (the escapement's reaction), in impulse units: the disk's momentum jumps by
        ``dforce``.
    jrest, jnum : what the jump ``dv`` changes in the pendulum's ``rest`` and in its
        share of φ̈'s numerator (friction, the θ̇² sin θ term), per unit time.
    """
    level = escapement_angle(c, m)
    # At the vertical (the paper's escapement) skip the trig: a sincos per impulse
    # costs 10 % of the scheme's rate at N = 64.
    s_lev, c_lev = (0.0, 1.0) if level == 0.0 else sincos(level)
    rest1, _, num1, _ = pendulum_terms(c, m, impulse, s_lev, c_lev, 0.0)
    rest0, _, num0, _ = pendulum_terms(c, m, 0.0, s_lev, c_lev, 0.0)
    dv = rest1 - rest0
    dforce = disk_torque(c, r, 0.0, impulse) - disk_torque(c, r, 0.0, 0.0)
    after, _, num_after, _ = pendulum_terms(c, m, 0.0, s_lev, c_lev, theta_dot + dv)
    before, _, num_before, _ = pendulum_terms(c, m, 0.0, s_lev, c_lev, theta_dot)
    return dv, num1 - num0, dforce, after - before, num_after - num_before

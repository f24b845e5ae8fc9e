"""A platform of two coordinates made from one of one: what no parameter builds yet
(capability ``platform-coordinates``), for the tests that ask consumers about it."""

import numpy as np

from metrosync.equations import SystemArrays


def padded(sys: SystemArrays, lever_y=None, inertia_y=0.3) -> SystemArrays:
    """``sys`` (one coordinate) with a second coordinate: idle (lever 0) by default."""
    runs, n = sys.shape
    lever_y = np.zeros((runs, n)) if lever_y is None else lever_y
    lever = np.stack([sys.lever[:, :, 0], lever_y], axis=-1)
    inertia = np.zeros((runs, 2, 2))
    inertia[:, 0, 0] = sys.total_inertia[:, 0, 0]
    inertia[:, 1, 1] = inertia_y
    return SystemArrays(
        **{
            **vars(sys),
            "lever": lever,
            "total_inertia": inertia,
            "c_phi": np.concatenate([sys.c_phi, np.zeros((runs, 1))], axis=1),
            "forcing_amplitude": np.concatenate([sys.forcing_amplitude, np.zeros((runs, 1))], 1),
            "escapement_reaction": np.concatenate(
                [sys.escapement_reaction, np.zeros((runs, 1))], 1
            ),
        }
    )

"""Pendulums of known period, written as instruments write them.

`driven` integrates a damped pendulum under a periodic force, θ'' + 2γθ' + ω0² sin θ =
F cos(2πt/T), from rest, for a warm-up of 40 s (the transient falls as e^{-γt}, to
e^{-16}), so that what is returned swings at the drive's period T exactly: the truth
a table's analysis must find, 120/T BPM (two beats per period). `encoder_csv` writes
what an Arduino with a rotary encoder logs; `tracker_table` what Tracker exports for
several point masses marked on a video.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

#: Warm-up before the first sample, s.
WARM = 40.0


def driven(period, times, *, gamma=0.4, force=1.2, detuning=1.05, phase=0.0):
    """θ (rad) at ``times`` (s from the first sample) of a pendulum driven at ``period``."""
    omega = 2 * np.pi / period
    omega0 = detuning * omega

    def rhs(t, s):
        return [s[1], -2 * gamma * s[1] - omega0**2 * np.sin(s[0])
                + force * np.cos(omega * t + phase)]  # fmt: skip

    times = np.asarray(times, dtype=float)
    solution = solve_ivp(rhs, (-WARM, float(times[-1])), [0.0, 0.0], t_eval=times,
                         method="DOP853", rtol=1e-10, atol=1e-12)  # fmt: skip
    return solution.y[0]


def encoder_csv(path, period, *, start=56.0, stop=264.0, rate=100.0, step_deg=0.36,
                zero_deg=7.1, header="time_s,angle_deg", millis=False):  # fmt: skip
    """An Arduino's log of a rotary encoder on the pendulum's axle: the time and the
    angle in degrees, counted in whole encoder steps from wherever it was at power-on
    (``zero_deg`` from the vertical). Returns the drive's period."""
    times = np.arange(0.0, stop - start, 1 / rate)
    theta = np.degrees(driven(period, times))
    counts = np.round((theta + zero_deg) / step_deg)
    clock = start + times
    rows = [f"{round(1000 * t)},{c * step_deg:.2f}" if millis else f"{t:.2f},{c * step_deg:.2f}"
            for t, c in zip(clock, counts, strict=True)]  # fmt: skip
    path.write_text("\n".join(([header] if header else []) + rows) + "\n")
    return path


def bob_positions(period, times, *, pivot, length=0.25, noise=3e-4, seed=0, phase=0.0):
    """x, y (m, y up) of a bob on a rod ``length`` about ``pivot``, marked with
    Gaussian noise of ``noise`` m, as Tracker's marks scatter."""
    rng = np.random.default_rng(seed)
    theta = driven(period, times, phase=phase)
    x = pivot[0] + length * np.sin(theta) + rng.normal(0, noise, theta.size)
    y = pivot[1] - length * np.cos(theta) + rng.normal(0, noise, theta.size)
    return x, y


def tracker_table(path, masses, times, *, decimal=".", blank=()):
    """Tracker's data export of several point masses side by side (its "#multi:"
    layout): the track names over their columns, one shared ``t``, then x and y per
    mass, tab-separated, each row ending in a tab. ``masses`` : {name: (x, y)};
    ``blank`` : (mass index, row) cells left empty (frames not marked)."""
    names = list(masses)
    head = ["#multi:", "\t" + "\t".join(f"{name}\t" for name in names),
            "t\t" + "\t".join("x\ty" for _ in names)]  # fmt: skip
    rows = []
    for i, t in enumerate(times):
        cells = [f"{t:.6E}"]
        for j, name in enumerate(names):
            x, y = masses[name]
            empty = (j, i) in blank
            cells += ["", ""] if empty else [f"{x[i]:.9E}", f"{y[i]:.9E}"]
        row = "\t".join(cells) + "\t"
        rows.append(row.replace(".", ",") if decimal == "," else row)
    path.write_text("\n".join(head + rows) + "\n")
    return path

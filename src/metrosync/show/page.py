"""Play a run back in a browser: one self-contained, offline HTML file.

The page holds its CSS and JavaScript inline and the run's data as JSON in a
``<script type="application/json">`` element, so it opens from the file system with
no server and no network. It shows the disk seen from above (as in `animate`; on a
board run, the board from the side on its two rollers, drawn about its mean motion), r(t)
with a cursor (click it to seek), and a phase wheel: each metronome's phase as a dot
on the unit circle, with the order parameter r e^{iψ} as an arrow. Controls: play /
pause (space bar), a seek slider, and the playback speed.

The JSON holds, for the chosen window, the record times as (t0, dt, count), θ and θ̇
per metronome, φ and φ̇, the recorded r, and the natural ω_i. The browser
interpolates between records with the same cubic Hermite scheme as `RecordedRun`.
Records denser than ``max_rate`` per second are thinned to keep the file small.
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

import numpy as np

from .._files import write_text
from ..budget import Budget
from ..errors import ParameterError
from ._page_template import TEMPLATE
from .recording import RecordedRun


def check_max_rate(max_rate: float) -> None:
    """Refuse a ``max_rate`` that keeps no record (made before simulating, too)."""
    if not (isinstance(max_rate, int | float) and math.isfinite(max_rate) and max_rate > 0):
        raise ParameterError(f"`max_rate` must be a number > 0 records/s, got {max_rate!r}.")


def page_data(run: RecordedRun, *, start=None, end=None, max_rate: float = 50.0) -> dict:
    """The JSON-ready data of a run's window [start, end] (see the module docstring)."""
    check_max_rate(max_rate)
    start, end = run.window(start, end)
    stride = max(1, int(math.ceil(1.0 / (max_rate * run.record_interval) - 1e-9)))
    first = int(np.searchsorted(run.time, start, side="right")) - 1
    last = int(np.searchsorted(run.time, end, side="left"))
    # Evenly spaced records that cover [start, end], as far as the recording goes.
    index = first + stride * np.arange(int(math.ceil((last - first) / stride)) + 1)
    index = index[index < run.time.size]
    if index.size < 2:
        if last - first >= 1:  # the window has the records; thinning took them away
            lowest = 1.0 / ((last - first) * run.record_interval)
            raise ParameterError(
                f"`max_rate` = {max_rate:g} records/s keeps fewer than two records of the "
                f"window [{start:g}, {end:g}] s; give `max_rate` >= {_round_up(lowest)}."
            )
        raise ParameterError(
            f"the window [{start:g}, {end:g}] s holds fewer than two records; widen it."
        )
    page_budget(index.size, run.n).check()
    end = min(end, float(run.time[index[-1]]))

    def rounded(values, digits=5):
        return np.round(np.asarray(values, dtype=float), digits).tolist()

    a = run.attrs
    return {
        "title": f"N = {run.n}, {a.get('bpm', '?')} BPM, σ = {a.get('sigma_bpm', '?')} BPM, "
        f"run {run.run}",
        "n": run.n,
        "radius": run.radius,
        "platform": run.platform,
        # The board is drawn about its mean motion, φ − (a + b t) (`RecordedRun.phi_trend`).
        "phi_trend": list(run.phi_trend) if run.platform == "board" else None,
        "t0": float(run.time[index[0]]),
        "dt": float(run.record_interval * stride),
        "count": int(index.size),
        "start": start,
        "end": end,
        "omega": rounded(run.omega, 8),
        "theta": [rounded(run.theta[index, i]) for i in range(run.n)],
        "theta_dot": [rounded(run.theta_dot[index, i], 4) for i in range(run.n)],
        "phi": rounded(run.phi[index]),
        "phi_dot": rounded(run.phi_dot[index]),
        "r": rounded(run.r[index], 4),
        "equilibrium_start": float(run.time[-1] - run.equilibrium_window)
        if math.isfinite(run.equilibrium_window)
        else None,
        "r_eq": run.r_eq if math.isfinite(run.r_eq) else None,
    }


def page_budget(records: int, n: int) -> Budget:
    """Memory and time of a page of ``records`` records of ``n`` metronomes: each
    number is held as a Python float in a list, then as JSON text twice (the
    payload and the page), about 100 bytes and 1 µs a number."""
    numbers = float(records) * (2 * n + 4)
    return Budget(
        "the page",
        {"the page's numbers and text": 100.0 * numbers},
        seconds=1e-6 * numbers,
        work=f"{numbers:.3g} numbers",
        fixes="lower `max_rate` or shorten the window (`start`, `end`)",
    )


def render_page(run: RecordedRun, **options) -> str:
    """The page's HTML text; ``options`` as for `page_data`."""
    data = page_data(run, **options)
    # "</" inside a script element would end it early; JSON allows "<\/" for it.
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    return TEMPLATE.replace("@TITLE@", html.escape(data["title"])).replace("@DATA@", payload)


def write_page(ds, path: Path | str, *, run: int = 0, **options) -> Path:
    """Write the interactive page of run ``run`` of ``ds`` (with trajectories).

    ``options``: ``start``, ``end`` (s) and ``max_rate`` (records/s), as in
    `page_data`. The write is atomic. Returns the path.
    """
    return write_text(render_page(RecordedRun.from_dataset(ds, run), **options), path)


def _round_up(value: float, digits: int = 3) -> str:
    """``value`` rounded up to ``digits`` significant digits, as text."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return f"{math.ceil(value / scale - 1e-9) * scale:.{digits}g}"

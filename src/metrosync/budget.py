"""Size before work: what a request will allocate and how long it will take, known
before anything is allocated.

Contract: every entry point whose memory or time grows with its inputs (`simulate`,
`sweep`, `animate`, `write_wav`, `write_page`, the bootstrap of `critical_frequency`)
describes its request as a `Budget`: the bytes of each large array it will hold at
once, by name, and its estimated wall time. It calls `Budget.check` before it
allocates anything. `check` refuses with `ResourceError` a request whose arrays do
not fit in the memory available now, giving the numbers and the arguments that
shrink it; it warns (`LongRunWarning`) when the work is estimated to take longer than
`WARN_SECONDS`, with the estimate.

Estimates err on the safe side: sizes count every large array together with the
temporaries that live beside it, and times use throughputs below those measured on
the 2-core x86-64 development machine, so that a warning may come early, not late.
They are of the work itself: compiling the kernels, once per machine on first use, is
announced on its own (`metrosync.integrators._cache`) and counted in no throughput.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from .capabilities import consumer_of
from .errors import MetrosyncError, ParameterError

#: Estimated work above this many seconds draws a `LongRunWarning`.
WARN_SECONDS = 180.0
#: Share of the available memory a request may plan to use; the rest is the
#: interpreter, the compiled kernels and whatever else the machine runs meanwhile.
MEMORY_SHARE = 0.8

#: Bytes per oscillator (run × metronome) of the ensemble's constants, its state and
#: the temporaries of building them: about 40 float64 arrays of shape (runs, N).
ENSEMBLE_BYTES = 320
#: Bytes per record and run of r(t): r, two crossing sums and a count (28 bytes),
#: and the temporaries of turning the sums into r_crossing.
RECORD_BYTES = 56

#: Wall time of the fixed-step scheme, s: per run-step and per oscillator-step with
#: the compiled kernel (measured 100-250 ns and 8-36 ns), per step and per
#: oscillator-step with the NumPy twin (measured 0.6-1.1 ms and < 1 µs).
NUMBA_RUN_STEP, NUMBA_OSC_STEP = 150e-9, 15e-9
NUMPY_STEP, NUMPY_OSC_STEP = 1e-3, 1e-7
#: Wall time of the reference integrator per simulated second: per run and per
#: metronome (measured 0.09-0.17 s per run-second at N = 2-7).
EXACT_RUN_SECOND, EXACT_OSC_SECOND = 0.15, 0.015


class ResourceError(MetrosyncError, ValueError):
    """A request needs more memory than the machine has available."""


class LongRunWarning(UserWarning):
    """A request is estimated to take several minutes or more."""


@dataclass(frozen=True)
class Budget:
    """What one request will hold in memory at once, and how long it will take.

    what : the entry point, for messages (``"simulate"``).
    arrays : bytes by array name (the largest ones are named when refusing).
    seconds : estimated wall time, s.
    work : the work in words, e.g. ``"7.0e+10 oscillator-steps"``.
    fixes : how to shrink the request, in the library's argument names
        (``"lower `runs`"``); the command line adds its option names.
    """

    what: str
    arrays: Mapping[str, float] = field(default_factory=dict)
    seconds: float = 0.0
    work: str = ""
    fixes: str = ""

    @property
    def nbytes(self) -> float:
        """Total bytes of the arrays held at once."""
        return float(sum(self.arrays.values()))

    def refusal(self, available: float) -> str | None:
        """The refusal message when the arrays do not fit in ``available`` bytes."""
        if self.nbytes <= MEMORY_SHARE * available:
            return None
        largest = sorted(self.arrays.items(), key=lambda item: -item[1])[:3]
        parts = ", ".join(f"{name} {format_bytes(size)}" for name, size in largest if size > 0)
        return (
            f"{self.what} would need about {format_bytes(self.nbytes)} of memory ({parts}), "
            f"more than the {format_bytes(MEMORY_SHARE * available)} it may use "
            f"({MEMORY_SHARE:.0%} of the {format_bytes(available)} available); "
            f"{self.fixes or 'ask for less'}."
        )

    def check(self, *, available: float | None = None, stacklevel: int = 3) -> Budget:
        """Refuse what does not fit (`ResourceError`), warn about long work; returns self.

        available : bytes of memory available (default: measured now).
        stacklevel : of the warning, as for `warnings.warn`: by default the line that
            called the caller of ``check``.
        """
        message = self.refusal(available_memory() if available is None else available)
        if message:
            raise ResourceError(message)
        if self.seconds > WARN_SECONDS:
            warnings.warn(
                f"{self.what} is estimated to take about {format_seconds(self.seconds)}"
                + (f" ({self.work})" if self.work else "")
                + "; Ctrl-C stops it"
                + (f", or {self.fixes}" if self.fixes else "")
                + ".",
                LongRunWarning,
                stacklevel=stacklevel,
            )
        return self


def combine(what: str, *budgets: Budget, fixes: str = "") -> Budget:
    """One budget for work done one part after another: memory of the largest part
    (its arrays, by name), time of all parts together."""
    biggest = max(budgets, key=lambda b: b.nbytes)
    return Budget(
        what,
        dict(biggest.arrays),
        sum(b.seconds for b in budgets),
        "; ".join(b.work for b in budgets if b.work),
        fixes or biggest.fixes,
    )


def simulation_budget(
    *,
    n: int,
    runs: int,
    steps: int,
    records: int,
    trajectories: bool,
    integrator: str = "verlet",
    backend: str = "numba",
    dt: float = 0.01,
    what: str = "the simulation",
) -> Budget:
    """Memory and time of one `simulate` call (see `metrosync.simulate`).

    n, runs : metronomes and runs.   steps : integration steps.   records : records
    per run.   trajectories : θ, θ̇, φ, φ̇ kept at every record.
    """
    oscillators = float(n) * runs
    arrays = {
        "ensemble and state": ENSEMBLE_BYTES * oscillators,
        "r(t) records": RECORD_BYTES * float(records) * runs,
    }
    if trajectories:
        # θ and θ̇ (runs, records, N), φ and φ̇ (runs, records), and one transposed
        # copy of the largest while a NetCDF file is written.
        arrays["trajectories"] = 8.0 * records * runs * (3 * n + 2)
    # How a consumer's time grows is the capability table's (`Consumer.cost`); a
    # request for none (refused later, by name) is sized as a compiled kernel.
    try:
        cost = consumer_of(integrator, backend).cost
    except ParameterError:
        cost = "compiled"
    if cost == "whole-run":
        # one run at a time: its dense samples (records, 2N + 2) and the phases.
        arrays["one run's samples"] = 8.0 * records * (5 * n + 2)
        seconds = runs * steps * dt * (EXACT_RUN_SECOND + EXACT_OSC_SECOND * n)
    elif cost == "numpy":
        seconds = steps * (NUMPY_STEP + NUMPY_OSC_STEP * oscillators)
    else:
        seconds = runs * float(steps) * (NUMBA_RUN_STEP + NUMBA_OSC_STEP * n)
    fixes = "use fewer `runs`, a shorter `duration` or a larger `dt`"
    if trajectories:
        fixes = "record less often: a larger `record_every`; or " + fixes
    return Budget(what, arrays, seconds, f"{oscillators * steps:.2g} oscillator-steps", fixes)


def available_memory() -> float:
    """Bytes of memory available now: the system's, or the control group's limit when
    that is lower (a container)."""
    try:
        import psutil

        available = float(psutil.virtual_memory().available)
    except Exception:  # noqa: BLE001 - psutil missing or unsupported: read /proc
        available = _meminfo_available()
    limit = _cgroup_headroom()
    return min(available, limit) if limit is not None else available


def _meminfo_available() -> float:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024
    except OSError:
        pass
    return math.inf  # nothing to measure with: refuse nothing


def _cgroup_headroom() -> float | None:
    root = Path("/sys/fs/cgroup")
    try:
        limit = (root / "memory.max").read_text().strip()
        if limit == "max":
            return None
        return float(limit) - float((root / "memory.current").read_text())
    except (OSError, ValueError):
        return None


def format_bytes(size: float) -> str:
    """``1536`` -> ``'1.5 KiB'``."""
    if not math.isfinite(size):
        return "unlimited"
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(size) < 1024 or unit == "PiB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.3g} {unit}"
        size /= 1024
    raise AssertionError("unreachable")


def format_seconds(seconds: float) -> str:
    """``7200`` -> ``'2.0 h'``."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 2 * 3600:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    if seconds < 2 * 365 * 86400:
        return f"{seconds / 86400:.0f} days"
    return f"{seconds / (365.25 * 86400):.2g} years"

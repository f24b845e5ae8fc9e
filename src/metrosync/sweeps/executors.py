"""Executors: where grid points run.

Contract: `execute` computes the given points and writes each to the store as soon as
it is done, from the calling process (the store never needs to be shared with remote
workers). Each point is one `metrosync.simulate` call, a pure function of its
`PointSpec`, so the stored results do not depend on the executor:

``None``            in this process, one point after another; the compiled kernel
                    already spreads each point's runs over all cores.
``"local"``         a Dask `LocalCluster` on 127.0.0.1, one single-threaded process
                    per worker (points in parallel).
``"tcp://H:P"``     an existing Dask scheduler (``dask.distributed``), so a sweep can
                    use many machines.

A point whose simulation raises is stored as failed (with the message) and the sweep
goes on; a point lost with its worker is not stored, so the next run computes it.
Warnings of a point's simulation are kept in its file (``warnings`` attribute), not
printed: a worker's output would be lost, and the caller decides what to report.
`check_scheduler` validates the executor options before any work, for every caller.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import socket
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import xarray as xr
from tqdm import tqdm

from .. import interrupts
from ..budget import LongRunWarning
from ..errors import ParameterError
from .keep import kept_dataset
from .points import PointSpec
from .store import PointStore

#: Seconds to wait for a Dask client and cluster to close.
CLOSE_SECONDS = 10
#: Seconds between two looks at the cluster's finished points.
POLL_SECONDS = 0.1


@dataclass
class Execution:
    """What one `execute` call did.

    computed : keys computed now.   failed : key -> error message (stored as failed).
    lost : key -> why no result came back (not stored; the next run retries them).
    seconds : wall time.   work : oscillator-steps computed now.
    """

    computed: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    lost: dict[str, str] = field(default_factory=dict)
    seconds: float = 0.0
    work: int = 0

    @property
    def throughput(self) -> float:
        """Oscillator-steps per second of wall time."""
        return self.work / self.seconds if self.seconds > 0 else float("nan")

    def then(self, later: Execution) -> Execution:
        """This execution followed by ``later`` (a sweep's rounds, added up)."""
        return Execution(
            self.computed + later.computed,
            {**self.failed, **later.failed},
            {**self.lost, **later.lost},
            self.seconds + later.seconds,
            self.work + later.work,
        )


def run_point(spec: PointSpec, threads: int | None = None):
    """Simulate one point; returns (point dataset, seconds, host). Never raises for a
    simulation error: that becomes a failed point. The seconds leave out compiling the
    kernels (once per machine), so that they measure the point's own work."""
    from ..integrators._cache import compile_seconds
    from ..simulate import simulate

    if threads is not None:
        import numba

        numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    compiling, started = compile_seconds(), time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # The sweep estimated its whole work up front; a point's own estimate is noise.
        warnings.simplefilter("ignore", LongRunWarning)
        try:
            ds = kept_dataset(spec, simulate(**spec.kwargs, progress=False))
        except Exception as error:  # noqa: BLE001 - one bad point must not stop a sweep
            ds = kept_dataset(spec, None, f"{type(error).__name__}: {error}")
    ds.attrs["warnings"] = " | ".join(sorted({str(w.message) for w in caught})) or "none"
    seconds = time.perf_counter() - started - (compile_seconds() - compiling)
    return ds, seconds, socket.gethostname()


def check_scheduler(scheduler: str | None, n_workers: int | None) -> None:
    """Refuse an unknown ``scheduler`` or a ``n_workers`` it cannot use, before any work."""
    if scheduler is not None and (
        not isinstance(scheduler, str)
        or (scheduler != "local" and not scheduler.startswith("tcp://"))
    ):
        raise ParameterError(
            "`scheduler` must be None (in process), 'local' or 'tcp://HOST:PORT', "
            f"got {scheduler!r}."
        )
    if n_workers is not None and (
        isinstance(n_workers, bool) or not isinstance(n_workers, int) or n_workers < 1
    ):
        raise ParameterError(f"`n_workers` must be an integer >= 1, got {n_workers!r}.")
    if n_workers is not None and scheduler != "local":
        where = "in process" if scheduler is None else "on an existing cluster"
        raise ParameterError(
            f"`n_workers` = {n_workers} applies to scheduler='local' only, but the sweep runs "
            f"{where}; add `scheduler='local'` (CLI: --scheduler local) or drop it."
        )


def execute(
    specs: Sequence[PointSpec],
    store: PointStore,
    *,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool = False,
    desc: str = "sweep",
    on_done: Callable[[PointSpec], None] | None = None,
    on_result: Callable[[PointSpec, xr.Dataset], None] | None = None,
) -> Execution:
    """Compute ``specs`` with the chosen executor, storing each point when it is done.

    ``desc`` labels the progress bar; ``on_done(spec)`` is called after each point is
    stored (e.g. to log progress); ``on_result(spec, ds)`` gets the point as stored
    (cost attributes included), so a caller need not read it back.
    """
    check_scheduler(scheduler, n_workers)
    report = Execution()
    started = time.perf_counter()
    total = sum(spec.work for spec in specs)
    with tqdm(
        total=total, unit="osc-step", unit_scale=True, desc=desc, disable=not progress,
        dynamic_ncols=True, leave=False,
    ) as bar:  # fmt: skip

        def done(spec: PointSpec, ds, seconds: float, host: str) -> None:
            failed = bool(ds.attrs["error"])
            ds = store.write(ds, seconds=seconds, host=host, work=0 if failed else spec.work)
            report.computed.append(spec.key)
            if failed:
                report.failed[spec.key] = ds.attrs["error"]
            else:
                report.work += spec.work
            bar.update(spec.work)
            bar.set_postfix_str(f"{len(report.computed)}/{len(specs)} points", refresh=False)
            if on_result is not None:
                on_result(spec, ds)
            if on_done is not None:
                on_done(spec)

        try:
            with interrupts.sigint_checked():
                if scheduler is None:
                    for spec in specs:
                        interrupts.check()
                        done(spec, *run_point(spec))
                else:
                    _execute_dask(specs, scheduler, n_workers, done, report)
        finally:
            report.seconds = time.perf_counter() - started
    return report


def _execute_dask(specs, scheduler, n_workers, done, report) -> None:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:  # pragma: no cover - dask[distributed] is a dependency
        raise ParameterError(
            "`scheduler` needs dask.distributed: pip install 'dask[distributed]'."
        ) from None
    cluster = None
    if scheduler == "local":
        workers = n_workers or os.cpu_count() or 1
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
        threads = max(1, (os.cpu_count() or 1) // workers)
        client = Client(cluster)
    else:
        threads = None
        try:
            client = Client(scheduler, timeout="20s")
        except OSError as error:
            raise ParameterError(
                f"cannot reach the Dask scheduler at {scheduler!r}: {error}"
            ) from None
    by_key = {}
    try:
        for spec in specs:
            future = client.submit(
                run_point, spec, threads, key=f"metrosync-point-{spec.key}", retries=1
            )
            by_key[future.key] = (spec, future)
        queue = as_completed([f for _, f in by_key.values()])
        while not queue.is_empty():
            interrupts.check()  # polled: a Ctrl-C lost in dask's callbacks still lands
            batch = queue.next_batch(block=False)
            if not batch:
                time.sleep(POLL_SECONDS)
            for future in batch:
                spec, _ = by_key[future.key]
                try:
                    ds, seconds, host = future.result()
                except Exception as error:  # noqa: BLE001 - a lost worker loses a point only
                    report.lost[spec.key] = f"{type(error).__name__}: {error}"
                    continue
                done(spec, ds, seconds, host)
                future.release()
    except BaseException:
        # Ctrl-C (or an error here): drop the queued and running points at once rather
        # than letting the cluster finish them; the finished ones are already stored.
        with contextlib.suppress(Exception):
            client.cancel([future for _, future in by_key.values()], force=True)
        if cluster is not None:
            _stop_local_workers(cluster)
        raise
    finally:
        with _quiet_dask():
            client.close(timeout=CLOSE_SECONDS)
            if cluster is not None:
                cluster.close(timeout=CLOSE_SECONDS)


def _stop_local_workers(cluster) -> None:
    """Kill the worker processes of our own LocalCluster. A worker in the middle of a
    point finishes it before it obeys a polite close (seconds to minutes); its result
    would be thrown away anyway."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        with contextlib.suppress(Exception):
            nanny.auto_restart = False
            process = nanny.process.process
            if process is not None and process.pid:
                os.kill(process.pid, signal.SIGKILL)


@contextlib.contextmanager
def _quiet_dask():
    """Silence distributed's loggers while a cluster shuts down: closing it with work
    cancelled makes them report every cancelled task and closed connection."""
    names = ("distributed", "tornado", "asyncio")
    levels = {name: logging.getLogger(name).level for name in names}
    try:
        for name in names:
            logging.getLogger(name).setLevel(logging.CRITICAL)
        yield
    finally:
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)

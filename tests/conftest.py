"""Shared fixtures: small ensembles whose constants tests can reuse; and what lets
`make test` run the suite on every core (pytest-xdist, ``-n auto --dist loadgroup``).

Under xdist each worker is a process of its own with its own session. Two things keep
the work done once per run rather than once per worker:

- `build_once` (a fixture): a session fixture's expensive result (a rendered corpus, a video, a
  tiny reproduction) is built by the first worker that needs it, into a folder shared
  by the run's workers, under a file lock; the others wait for it and read it back.
- `pytest_configure`: before the workers start, the kernels are compiled once, one
  scheme per core (`metrosync.integrators.warm_up`), so that no two workers compile
  the same kernel side by side; with the cache warm this takes a few seconds.
- `pytest_xdist_make_scheduler`: the tests of a module that defines a module-scoped
  fixture are one group, run by one worker, which builds that fixture once
  (``--dist loadgroup``; the other tests are dealt out one by one).

Without xdist (``pytest`` alone) both do what plain fixtures do.
"""

import functools
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np
import pytest

from metrosync import build_ensemble, get_preset
from metrosync.equations import SystemArrays

# A suite started in the background of a non-interactive shell (`make test &`) inherits
# SIGINT ignored, and so would every process it starts. The Ctrl-C tests need Python's
# handler here and the default disposition in their children: restore it.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

T = TypeVar("T")


def _build_once(tmp_path_factory, name: str, build: Callable[[Path], T]) -> T:
    """``build(folder)`` once per test run, for every xdist worker; returns its result.

    ``folder`` is a fresh directory for the files ``build`` writes (they stay in place
    for the whole run, shared by the workers: tests must only read them). Under xdist
    the first worker to get here builds, holding a file lock, and leaves the result
    pickled beside the folder; the others wait on the lock and unpickle it. Without
    xdist this is ``build(tmp_path_factory.mktemp(name))``."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return build(tmp_path_factory.mktemp(name))
    from filelock import FileLock

    # getbasetemp() is this worker's folder (.../pytest-N/popen-gw0); its parent is the
    # run's, shared by its workers and new for each run.
    root = tmp_path_factory.getbasetemp().parent / "built-once"
    root.mkdir(exist_ok=True)
    folder, result = root / name, root / f"{name}.pickle"
    with FileLock(str(root / f"{name}.lock")):
        if result.is_file():
            return pickle.loads(result.read_bytes())
        shutil.rmtree(folder, ignore_errors=True)  # a build that failed part way
        folder.mkdir()
        value = build(folder)
        result.write_bytes(pickle.dumps(value))
        return value


@pytest.fixture(scope="session")
def build_once(tmp_path_factory):
    """``build_once(name, build)``: ``build(folder)`` once per run for all the xdist
    workers (`_build_once`), for session fixtures whose building takes seconds."""
    return lambda name, build: _build_once(tmp_path_factory, name, build)


#: A test module that defines a fixture of one of these scopes (its simulated runs, the
#: documentation site, the built wheel): its tests stay on one xdist worker, which
#: builds the fixture once. An ``xdist_group`` mark in a module groups it by that name.
_MODULE_FIXTURE = re.compile(
    r"""@pytest\.fixture\([^)]*scope\s*=\s*["'](module|class|package|session)["']"""
)
#: Node ids are relative to it (pyproject.toml's folder).
ROOTDIR = Path(__file__).resolve().parents[1]
_GROUP_MARK = re.compile(r"""xdist_group\(\s*(?:name\s*=\s*)?["']([^"']+)["']""")


@functools.cache
def _module_group(path: str) -> str | None:
    """The group of the tests of module ``path`` (relative to the rootdir), or None to
    deal them out one by one."""
    try:
        text = (ROOTDIR / path).read_text(encoding="utf-8")
    except OSError:
        return None
    names = set(_GROUP_MARK.findall(text))
    if len(names) == 1:
        return names.pop()
    return path if names or _MODULE_FIXTURE.search(text) else None


def pytest_configure(config):
    """On the xdist controller of a run on several workers: the kernels compiled first
    (see the module's docstring), each scheme in a process of its own."""
    workers = getattr(config.option, "numprocesses", None)
    if os.environ.get("PYTEST_XDIST_WORKER") or not workers or config.option.collectonly:
        return
    from metrosync.integrators.warm_up import SCHEMES

    compiling = [
        subprocess.Popen([sys.executable, "-m", "metrosync.integrators.warm_up", scheme],
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        for scheme in SCHEMES
    ]  # fmt: skip
    for process in compiling:
        process.wait()  # a failure shows again, with its traceback, in the tests themselves


@pytest.hookimpl(optionalhook=True)  # a pytest-xdist hook: absent without the plugin
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup`` (what `make test` uses), with the groups found per module.

    xdist's own loadgroup reads the ``xdist_group`` marks through a suffix it adds to
    each node id, which pytest >= 9.2 no longer lets it change (pytest-xdist#1386): the
    marks would be ignored. Here the groups come from the test modules' source
    (`_module_group`): a module with a module-scoped fixture is one group, run by one
    worker (which builds that fixture once); every other test is dealt out on its own.
    Groups go out first, the largest first; the single tests fill in after them."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class ModuleGroups(LoadGroupScheduling):
        def _split_scope(self, nodeid):
            if nodeid.rfind("@") > nodeid.rfind("]"):  # a suffix from an older pytest
                return super()._split_scope(nodeid)
            return _module_group(nodeid.split("::", 1)[0]) or nodeid

    return ModuleGroups(config, log)


@pytest.fixture
def small_ensemble():
    """3 runs × 5 metronomes with spread, friction and drive, random phases."""
    return build_ensemble(5, 192.0, params=get_preset("default"), sigma_bpm=2.0, runs=3, seed=11)


@pytest.fixture
def rng():
    return np.random.default_rng(20131)


@pytest.fixture
def random_system(rng):
    """A factory of random, physically sensible `SystemArrays` of B runs × N metronomes."""

    def make(b=4, n=6):
        mass = rng.uniform(0.02, 0.05, (b, n))
        h = rng.uniform(0.005, 0.03, (b, n))
        j = rng.uniform(1e-5, 1e-4, (b, n))
        radius = rng.uniform(0.1, 0.5, b)
        return SystemArrays(
            mh=mass * h,
            mgh=mass * 9.81 * h,
            inertia=mass * h**2 + j,
            c_theta=rng.uniform(0, 1e-4, (b, n)),
            drive=rng.uniform(0, 1e-3, (b, n)),
            omega=np.ones((b, n)),
            lever=radius,
            c_phi=rng.uniform(0, 1e-4, b),
            total_inertia=rng.uniform(0.05, 0.5, b) + radius**2 * mass.sum(axis=1),
            dry_friction=np.zeros(b),
        )

    return make

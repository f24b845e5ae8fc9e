"""The wheel that `python -m build` makes works where the source tree is not.

The package is built as `python -m build` builds it (an sdist from a copy of the
tracked sources, then the wheel from that sdist), without network: no build isolation,
the build tools come from the environment running the tests (the ``test`` extra). The
wheel goes into a fresh virtual environment in a temporary folder. That environment
sees the dependencies (numpy, scipy, numba, ...) of the environment running the tests
through a path file, never its metrosync: so a file missing from the wheel (package
data such as the playground's scripts or the firmware's sources) fails here.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

import metrosync

ROOT = Path(__file__).resolve().parents[1]


def run(args, cwd, **kw) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in {"PYTHONPATH", "PYTHONHOME"}}
    done = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=600, **kw)
    assert done.returncode == 0, f"{args}: {done.stdout[-2000:]}{done.stderr[-3000:]}"
    return done


def tracked_copy(into: Path) -> Path:
    """The checkout's tracked files (and the ones about to be), as a fresh clone has."""
    listed = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
        cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip
    if listed.returncode != 0:
        pytest.skip(f"not a git checkout, so no list of its files: {listed.stderr.strip()}")
    for name in filter(None, listed.stdout.split("\0")):
        source = ROOT / name
        if source.is_file() and not name.startswith(("tests/", "docs/", "benchmarks/")):
            (into / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, into / name)
    return into


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    missing = [m for m in ("build", "setuptools", "wheel") if importlib.util.find_spec(m) is None]
    if missing or shutil.which("git") is None:
        pytest.skip(f"needs git and the test extra ({', '.join(missing) or 'git'} missing): "
                    "`pip install -e '.[test]'`, which `make test` does")  # fmt: skip
    work = tmp_path_factory.mktemp("wheel")
    source = tracked_copy(work / "source")
    dist = work / "dist"
    run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(dist), str(source)],
        cwd=work)  # fmt: skip
    wheels, sdists = list(dist.glob("*.whl")), list(dist.glob("*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1, list(dist.iterdir())

    venv = work / "fresh"
    run([sys.executable, "-m", "venv", str(venv)], cwd=work)
    python = venv / "bin" / "python"
    purelib = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    site = Path(run([str(python), "-c", purelib], cwd=work).stdout.strip())
    # The dependencies: this environment's site-packages as a plain path. Its own path
    # files (an editable metrosync among them) are not processed from there.
    (site / "zz_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "--quiet", str(wheels[0])],
        cwd=work)  # fmt: skip
    outside = work / "elsewhere"
    outside.mkdir()
    return {"wheel": wheels[0], "venv": venv, "python": python, "cwd": outside}


def test_the_wheel_carries_the_package_data(installed):
    names = set(zipfile.ZipFile(installed["wheel"]).namelist())
    for name in ("metrosync/py.typed", "metrosync/show/_playground/page.html",
                 "metrosync/_firmware/gate-logger/gate_logger.c"):  # fmt: skip
        assert name in names


def test_the_installed_package_is_the_wheel_s_not_the_checkout_s(installed):
    where = run([str(installed["python"]), "-c", "import metrosync; print(metrosync.__file__)"],
                cwd=installed["cwd"]).stdout.strip()  # fmt: skip
    assert Path(where).is_relative_to(installed["venv"]), where


def test_version_simulate_and_playground_run_from_the_wheel(installed):
    metrosync_cli = str(installed["venv"] / "bin" / "metrosync")
    cwd = installed["cwd"]
    version = run([metrosync_cli, "--version"], cwd=cwd).stdout
    assert metrosync.__version__ in version
    # The NumPy twin: no kernels to compile for a freshly installed package.
    run([metrosync_cli, "simulate", "--n", "2", "--runs", "1", "--duration", "5",
         "--backend", "numpy", "--out", "s.nc"], cwd=cwd)  # fmt: skip
    assert (cwd / "s.nc").stat().st_size > 0
    run([metrosync_cli, "playground", "--out", "play.html"], cwd=cwd)
    page = (cwd / "play.html").read_text()
    assert "metrosync" in page and len(page) > 20_000


def test_the_firmware_s_sources_come_with_the_wheel(installed):
    script = (
        "import metrosync.lightgate.firmware as f; print(f.firmware_dir()); "
        "f.copy_to('gate-logger')"
    )
    where = run([str(installed["python"]), "-c", script], cwd=installed["cwd"]).stdout.strip()
    assert Path(where).is_relative_to(installed["venv"]), where
    copied = installed["cwd"] / "gate-logger"
    assert (copied / "gate_logger.c").read_bytes() == (
        ROOT / "firmware" / "gate-logger" / "gate_logger.c"
    ).read_bytes()
    assert {p.name for p in copied.iterdir()} == {"gate_logger.c", "gate-logger.ino", "Makefile"}

"""The suite never changes the machine: system packages come from `tools/system-deps`."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
INSTALLERS = re.compile(r"""["'](apt-get|apt|dpkg|pip|npm)["']\s*,\s*["'](install|-i)["']""")


#: The one test that installs, and why: the built wheel goes into a virtual environment
#: of its own under the test's temporary folder, from the file alone (``--no-index``),
#: so the machine and the project's environment are left as they were.
INSTALLS_INTO_ITS_OWN_VENV = {"tests/test_wheel.py"}


def test_no_test_runs_an_installer():
    offenders = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in TESTS.rglob("*.py")
        if path != Path(__file__).resolve()
        and str(path.relative_to(ROOT)) not in INSTALLS_INTO_ITS_OWN_VENV
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if INSTALLERS.search(line)
    ]
    assert offenders == [], f"tests must detect and skip, not install: {offenders}"


def test_the_wheel_test_installs_only_from_its_file_into_its_own_venv():
    for name in INSTALLS_INTO_ITS_OWN_VENV:
        lines = [line for line in (ROOT / name).read_text(encoding="utf-8").splitlines()
                 if INSTALLERS.search(line)]  # fmt: skip
        assert lines, f"{name} no longer installs: drop it from the exemption"
        for line in lines:
            assert "--no-index" in line and "[str(python)" in line, line


def test_the_check_catches_an_installer():
    assert INSTALLERS.search('subprocess.run(["apt-get", "install", "-y", "chromium"])')


def test_every_package_the_tests_probe_is_one_system_deps_installs():
    from system_packages import PROBES

    script = (ROOT / "tools" / "system-deps").read_text(encoding="utf-8")
    for package in PROBES:
        assert f"[{package}]=" in script, f"{package} is probed but never installed"


def test_system_deps_never_fails_when_it_cannot_install(tmp_path):
    done = subprocess.run(
        ["bash", str(ROOT / "tools" / "system-deps")],
        env={"PATH": "/usr/bin:/bin", "METROSYNC_SYSTEM_DEPS": "skip"},
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 0
    assert "system-deps:" in done.stdout + done.stderr

"""Detect the system packages some tests need; never install them.

`tools/system-deps` (run by `make test`, or alone as `make system-deps`) installs them
where it can. A test that lacks one skips and says which package and how to get it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

#: Debian package -> how to tell it is installed (a program on PATH or a file).
PROBES = {
    "chromium": ("program", "chromium"),
    "gcc-avr": ("program", "avr-gcc"),
    "avr-libc": ("file", "/usr/lib/avr/include/avr/io.h"),
    "simavr": ("program", "simavr"),
    "libsimavr-dev": ("file", "/usr/include/simavr/sim_avr.h"),
    "gcc": ("program", "gcc"),
    "arduino-core-avr": ("file", "/usr/share/arduino/hardware/arduino/avr/platform.txt"),
}


def present(package: str) -> bool:
    kind, what = PROBES[package]
    return shutil.which(what) is not None if kind == "program" else Path(what).is_file()


def require(*packages: str) -> None:
    """Skip the calling test unless every Debian package in ``packages`` is installed."""
    missing = [p for p in packages if not present(p)]
    if missing:
        pytest.skip(
            f"needs the Debian package(s) {', '.join(missing)}: run `make system-deps` "
            f"(as root) or `sudo apt-get install {' '.join(missing)}`"
        )

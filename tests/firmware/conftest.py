"""Fixtures of the firmware tests: the firmware and the simavr harness, built once."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from simlogger import build_firmware, build_harness

from system_packages import require


@pytest.fixture(scope="session")
def sim(tmp_path_factory):
    """The harness and a builder of firmware variants (cached per set of defines)."""
    require("gcc-avr", "avr-libc", "simavr", "libsimavr-dev", "gcc")
    root = tmp_path_factory.mktemp("firmware")
    cache = {}

    def firmware(**defines):
        key = tuple(sorted(defines.items()))
        if key not in cache:
            cache[key] = build_firmware(root / f"build{len(cache)}", **defines)
        return cache[key]

    return SimpleNamespace(harness=build_harness(root), firmware=firmware)

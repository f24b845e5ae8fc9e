"""The firmware's build: a changed option rebuilds (so `flash` sends what was asked for),
an unchanged one does not, and a missing toolchain or flasher is named with its remedy."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from simlogger import FIRMWARE_DIR, REPO

from system_packages import require

MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(MAKE is None, reason="needs make")


def make(*args, cwd=FIRMWARE_DIR, env=None) -> subprocess.CompletedProcess:
    return subprocess.run([MAKE, *args], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=120)  # fmt: skip


def hex_bytes(path: Path) -> bytes:
    """The data of an Intel HEX file, in address order (the firmware is one block)."""
    data = {}
    for row in path.read_text().split():
        raw = bytes.fromhex(row[1:])
        count, address, kind = raw[0], int.from_bytes(raw[1:3], "big"), raw[3]
        if kind == 0:
            data[address] = raw[4 : 4 + count]
    return b"".join(data[a] for a in sorted(data))


@pytest.fixture
def build(tmp_path):
    require("gcc-avr", "avr-libc")
    return tmp_path / "build"


def test_a_changed_option_rebuilds_and_an_unchanged_one_does_not(build):
    elf, hexfile = build / "gate-logger.elf", build / "gate-logger.hex"
    assert make(f"BUILD={build}").returncode == 0
    assert b"channels=8 " in elf.read_bytes()
    stamp = hexfile.stat().st_mtime_ns
    again = make(f"BUILD={build}")
    assert again.returncode == 0 and "avr-gcc" not in again.stdout
    assert hexfile.stat().st_mtime_ns == stamp
    for option, text in (("CHANNELS=7", b"channels=7 "), ("BAUD=57600", b"baud=57600 "),
                         ("EXTRA_CFLAGS=-DHOLDOFF_TICKS=6", b"holdoff_ticks=6")):  # fmt: skip
        done = make(f"BUILD={build}", option)
        assert done.returncode == 0 and "avr-gcc" in done.stdout, option
        assert text in hex_bytes(hexfile), option
    # Back to the defaults: rebuilt again, not the last variant kept.
    assert make(f"BUILD={build}").returncode == 0
    assert b"channels=8 " in hex_bytes(hexfile) and b"holdoff_ticks=4" in hex_bytes(hexfile)


def test_flash_sends_the_firmware_of_the_options_given(build, tmp_path):
    assert make(f"BUILD={build}").returncode == 0  # an 8-gate build first
    # A stand-in for avrdude that keeps the file it was asked to write.
    flasher = tmp_path / "avrdude"
    flasher.write_text('#!/bin/sh\nfor a; do case "$a" in flash:w:*) f=${a#flash:w:}; '
                       'cp "${f%:i}" "$0.hex";; esac; done\n')  # fmt: skip
    flasher.chmod(0o755)
    done = make(f"BUILD={build}", "CHANNELS=7", "flash", f"AVRDUDE={flasher}", "PORT=/dev/null")
    assert done.returncode == 0, done.stderr
    flashed = hex_bytes(tmp_path / "avrdude.hex")
    assert b"channels=7 " in flashed and b"channels=8 " not in flashed


def test_the_top_level_firmware_target_passes_the_options(build):
    done = make("firmware", f"BUILD={build}", "CHANNELS=5", cwd=REPO)
    assert done.returncode == 0, done.stderr
    assert b"channels=5 " in (build / "gate-logger.elf").read_bytes()


def bare_path(tmp_path: Path) -> dict:
    """An environment whose PATH has the shell's usual tools but no AVR toolchain."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("sh", "mkdir", "rm", "cp", "cat", "echo"):
        found = shutil.which(tool)
        if found:
            (bin_dir / tool).symlink_to(found)
    return {**os.environ, "PATH": str(bin_dir)}


@pytest.mark.parametrize("where", ["firmware", "top"])
def test_without_avr_gcc_the_build_says_what_to_install(tmp_path, where):
    env = bare_path(tmp_path)
    build = tmp_path / "build"
    if where == "top":
        done = make("firmware", f"BUILD={build}", cwd=REPO, env=env)
    else:
        done = make(f"BUILD={build}", env=env)
    assert done.returncode != 0
    assert "avr-gcc not found" in done.stderr
    assert "apt-get install gcc-avr avr-libc" in done.stderr and "Arduino IDE" in done.stderr
    assert not (build / "gate-logger.elf").exists()


def test_without_avrdude_flash_says_what_to_install(build, tmp_path):
    done = make(f"BUILD={build}", "flash", f"AVRDUDE={tmp_path / 'no-avrdude'}")
    assert done.returncode != 0
    assert "no-avrdude not found" in done.stderr and "apt-get install avrdude" in done.stderr

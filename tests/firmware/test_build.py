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
    assert "avr-gcc not found" in done.stderr and done.stderr.count("not found") == 1
    assert "apt-get install gcc-avr avr-libc" in done.stderr and "Arduino IDE" in done.stderr
    assert "'sudo make system-deps' at the top of the repository" in done.stderr
    assert not (build / "gate-logger.elf").exists()


def test_without_avrdude_flash_says_what_to_install(build, tmp_path):
    done = make(f"BUILD={build}", "flash", f"AVRDUDE={tmp_path / 'no-avrdude'}")
    assert done.returncode != 0
    assert "no-avrdude not found" in done.stderr and "apt-get install avrdude" in done.stderr


ARDUINO_AVR = Path("/usr/share/arduino/hardware/arduino/avr")  # Debian's arduino-core-avr


def platform_flags(name: str) -> list[str]:
    """A flag set of the Arduino AVR platform (platform.txt), as the IDE expands it."""
    values = dict(row.split("=", 1) for row in (ARDUINO_AVR / "platform.txt").read_text()
                  .splitlines() if "=" in row and not row.startswith("#"))  # fmt: skip
    text = values[name].replace("{compiler.warning_flags}", values["compiler.warning_flags"])
    return [flag for flag in text.split() if flag != "-MMD"]


@pytest.mark.slow
def test_the_arduino_sketch_builds_as_the_ide_builds_it_and_runs_alike(sim, tmp_path):
    """docs/logger.md's Arduino IDE route: the sketch and gate_logger.c, compiled and
    linked with the Arduino AVR core's flags and the core's library (whose main() the
    firmware's replaces), make firmware that sends what the Makefile's sends."""
    require("gcc-avr", "avr-libc", "arduino-core-avr")
    core, variant = ARDUINO_AVR / "cores" / "arduino", ARDUINO_AVR / "variants" / "standard"
    board = ["-mmcu=atmega328p", "-DF_CPU=16000000L", "-DARDUINO=10607", "-DARDUINO_AVR_UNO",
             "-DARDUINO_ARCH_AVR", f"-I{core}", f"-I{variant}"]  # fmt: skip
    c, cpp = platform_flags("compiler.c.flags"), platform_flags("compiler.cpp.flags")

    def compile_(source: Path, obj: Path) -> bool:
        cc = ["avr-gcc", *c] if source.suffix == ".c" else ["avr-g++", *cpp]
        if source.suffix == ".S":
            cc = ["avr-gcc", *platform_flags("compiler.S.flags")]
        done = subprocess.run([*cc, *board, str(source), "-o", str(obj)], capture_output=True)
        return done.returncode == 0

    # The IDE turns the .ino into C++ that includes Arduino.h, and compiles the .c beside it.
    sketch = tmp_path / "gate-logger.ino.cpp"
    ino = (FIRMWARE_DIR / "gate-logger.ino").read_text()
    sketch.write_text(f'#include <Arduino.h>\n#line 1 "gate-logger.ino"\n{ino}')
    objects = [tmp_path / "sketch.o", tmp_path / "gate_logger.o"]
    assert compile_(sketch, objects[0]) and compile_(FIRMWARE_DIR / "gate_logger.c", objects[1])
    # The core's library; a file Debian's compiler cannot build (WString.cpp) is not
    # needed by the firmware, and the link below would fail if it were.
    sources = sorted(s for s in core.iterdir() if s.suffix in (".c", ".cpp", ".S"))
    built = [tmp_path / f"core-{s.name}.o" for s in sources]
    built = [o for s, o in zip(sources, built, strict=True) if compile_(s, o)]
    assert any("main.cpp" in o.name for o in built) and any("wiring.c" in o.name for o in built)
    subprocess.run(["avr-gcc-ar", "rcs", str(tmp_path / "core.a"), *map(str, built)], check=True)
    elf = tmp_path / "gate-logger.ino.elf"
    subprocess.run(["avr-gcc", *platform_flags("compiler.c.elf.flags"), "-mmcu=atmega328p",
                    "-o", str(elf), *map(str, objects), str(tmp_path / "core.a"), "-lm"],
                   check=True, capture_output=True)  # fmt: skip

    from simlogger import run_logger

    edges = [(0.01 + 0.013 * k, 1 + k % 8, 1 - (k // 8) % 2) for k in range(40)]
    runs = [run_logger(sim.harness, firmware, edges, end=0.7, workdir=tmp_path, rx=[(0.3, 63)])
            for firmware in (elf, sim.firmware())]  # fmt: skip
    assert runs[0].text == runs[1].text and len(runs[0].lines) == 43


def test_without_avr_libc_the_build_says_what_to_install(tmp_path):
    env = bare_path(tmp_path)
    fake = tmp_path / "bin" / "avr-gcc"  # a compiler that finds no avr/io.h
    fake.write_text("#!/bin/sh\necho 'avr/io.h: No such file or directory' >&2\nexit 1\n")
    fake.chmod(0o755)
    done = make(f"BUILD={tmp_path / 'build'}", env=env)
    assert done.returncode != 0
    assert "avr-gcc has no avr-libc (avr/io.h not found)" in done.stderr
    assert "apt-get install gcc-avr avr-libc" in done.stderr

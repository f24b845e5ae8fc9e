"""Build hook: the wheel carries the gate-logger firmware's sources as package data.

They live at the repository's top (``firmware/gate-logger``, where ``make firmware``
builds them); building copies them into ``metrosync/_firmware/gate-logger`` of the
built package, where `metrosync.lightgate.firmware` finds them. Everything else is in
pyproject.toml.
"""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

FIRMWARE = Path(__file__).resolve().parent / "firmware" / "gate-logger"
FILES = ("gate_logger.c", "gate-logger.ino", "Makefile")


class BuildWithFirmware(build_py):
    def run(self):
        super().run()
        if self.editable_mode:  # an editable install reads the checkout's firmware/
            return
        target = Path(self.build_lib) / "metrosync" / "_firmware" / "gate-logger"
        target.mkdir(parents=True, exist_ok=True)
        for name in FILES:
            (target / name).write_bytes((FIRMWARE / name).read_bytes())


setup(cmdclass={"build_py": BuildWithFirmware})

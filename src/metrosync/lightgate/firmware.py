"""The gate-logger firmware's sources, as the installed package carries them.

The repository keeps them in ``firmware/gate-logger/`` (``make firmware``, ``make
flash``); a wheel carries a copy in ``metrosync/_firmware/gate-logger/``, so that a
``pip install`` without the repository can still build and flash the logger:

    python -c "import metrosync.lightgate.firmware as f; f.copy_to('gate-logger')"
    make -C gate-logger flash PORT=/dev/ttyACM0
"""

from __future__ import annotations

from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

from ..errors import MetrosyncError

#: The firmware's files: the C source, the Arduino IDE's sketch and the Makefile.
FILES = ("gate_logger.c", "gate-logger.ino", "Makefile")


def firmware_dir() -> Traversable:
    """The folder of the firmware's sources: the installed copy, or the checkout's."""
    packaged = resources.files("metrosync").joinpath("_firmware", "gate-logger")
    if packaged.is_dir():
        return packaged
    checkout = Path(__file__).resolve().parents[3] / "firmware" / "gate-logger"
    if checkout.is_dir():
        return checkout
    raise MetrosyncError(
        "the gate-logger firmware's sources are not installed with this metrosync "
        "(metrosync/_firmware is missing); reinstall it from a wheel or the repository"
    )


def firmware_source(name: str = "gate_logger.c") -> str:
    """The text of one of the firmware's `FILES`."""
    if name not in FILES:
        raise MetrosyncError(f"the firmware has no file {name!r}; it has {', '.join(FILES)}")
    return firmware_dir().joinpath(name).read_text(encoding="utf-8")


def copy_to(folder: str | Path) -> Path:
    """Write the firmware's `FILES` into ``folder`` (created) and return it."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name in FILES:
        (folder / name).write_text(firmware_source(name), encoding="utf-8")
    return folder

"""The gate-logger firmware in simavr, for tests: build it, drive its gates, read its UART.

`build_firmware` builds the firmware with `make` (test-only defines such as
``START_TICKS`` allowed), `build_harness` compiles ``harness.c`` against libsimavr,
and `run_logger` runs the firmware on a list of gate edges (and bytes for its serial
input) and returns what its UART sent, with the cycle at which each line left it and
the cycle at which Timer1 (the origin of the firmware's ticks) started.
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from metrosync.lightgate.virtual import LightGate, gate_edges

REPO = Path(__file__).resolve().parents[2]
FIRMWARE_DIR = REPO / "firmware" / "gate-logger"
HARNESS_C = Path(__file__).with_name("harness.c")
F_CPU = 16_000_000
CYCLES_PER_TICK = 1024
TICK = CYCLES_PER_TICK / F_CPU
#: START_TICKS of the test builds that reach the counter's wraps in seconds.
NEAR_32_BIT_WRAP = 0xFFFFF000  # 4096 ticks (0.262 s) before 2**32
NEAR_16_BIT_WRAP = 0x0000F000  # 4096 ticks before the hardware counter's first overflow


def build_firmware(build_dir: Path, *, channels: int = 8, **defines) -> Path:
    """Build the firmware into ``build_dir``; returns the ELF file simavr runs."""
    extra = " ".join(f"-D{name}={value}" for name, value in defines.items())
    subprocess.run(
        ["make", "-s", "-C", str(FIRMWARE_DIR), f"BUILD={build_dir}", f"CHANNELS={channels}",
         f"EXTRA_CFLAGS={extra}", f"{build_dir}/gate-logger.elf"],
        check=True, capture_output=True,
    )  # fmt: skip
    return Path(build_dir) / "gate-logger.elf"


def build_harness(build_dir: Path) -> Path:
    """Compile the simavr harness; returns the program."""
    exe = Path(build_dir) / "harness"
    subprocess.run(["gcc", "-O2", "-Wall", "-o", str(exe), str(HARNESS_C), "-lsimavr"],
                   check=True, capture_output=True)  # fmt: skip
    return exe


@dataclass(frozen=True)
class LoggerRun:
    """What the simulated logger sent.

    text : the UART's bytes, decoded.
    timer_start : CPU cycle at which Timer1 started: tick k spans cycles
        timer_start + 1024·k .. + 1024.
    line_cycles : (L,) cycle at which each line's last byte left the UART.
    """

    text: str
    timer_start: int
    line_cycles: np.ndarray

    @property
    def lines(self) -> list[str]:
        return self.text.splitlines()


def edge_file(path: Path, edges, *, end: float, init: str = "00000000", rx=()) -> Path:
    """Write the harness's input: ``edges`` are (time s, gate 1..8, level) in time order,
    ``rx`` (time s, byte) what the UART receives."""
    timed = sorted([(round(t * F_CPU), f"{g} {lv}") for t, g, lv in edges]
                   + [(round(t * F_CPU), f"rx {byte}") for t, byte in rx],
                   key=lambda row: row[0])  # fmt: skip
    rows = [f"init {init}"]
    rows += [f"{cycle} {what}" for cycle, what in timed]
    rows.append(f"end {round(end * F_CPU)}")
    Path(path).write_text("\n".join(rows) + "\n")
    return Path(path)


def run_logger(harness: Path, elf: Path, edges, *, end: float, workdir: Path,
               init: str = "00000000", speed: float = 0.0, stdout=None, stdin=None,
               timeout: float = 120, rx=()) -> LoggerRun | subprocess.Popen:  # fmt: skip
    """Run the firmware on ``edges`` until ``end`` s (simulated), sending it the bytes
    ``rx`` [(time s, byte)] on its serial input, and with ``stdin`` (a file descriptor,
    e.g. the pty's master end) what arrives there too.

    With ``stdout`` (a file descriptor, e.g. a pty's master end) the harness writes the
    UART there, paced at ``speed`` simulated seconds per second, and the started
    process is returned; otherwise the run is waited for and returned as `LoggerRun`.
    """
    workdir = Path(workdir)
    edges_path = edge_file(workdir / "edges.txt", edges, end=end, init=init, rx=rx)
    lines_path = workdir / "line_cycles.txt"
    argv = [str(harness), str(elf), str(edges_path), "--lines", str(lines_path)]
    if speed:
        argv += ["--speed", repr(float(speed))]
    if stdin is not None:
        argv.append("--rx-stdin")
    if stdout is not None:
        return subprocess.Popen(argv, stdin=stdin, stdout=stdout, stderr=subprocess.PIPE)
    done = subprocess.run(argv, capture_output=True, timeout=timeout, check=True)
    return LoggerRun(
        text=done.stdout.decode("ascii"),
        timer_start=timer_start(done.stderr.decode()),
        line_cycles=np.loadtxt(lines_path, dtype=np.int64, ndmin=1),
    )


def timer_start(stderr: str) -> int:
    """The harness's report of the cycle at which Timer1 started."""
    for row in stderr.splitlines():
        if row.startswith("timer1-start-cycle "):
            return int(row.split()[1])
    raise AssertionError(f"the harness did not report Timer1's start: {stderr!r}")


def simulation_edges(ds, run: int, gate: LightGate, *, until: float):
    """Gate edges of one run of a `simulate` dataset with trajectories.

    Returns (init, edges): the gates' pin levels at t = 0 (1 = interrupted, as the
    firmware's wiring prints it) and [(t, gate 1..N, level)] in time order, t < until.
    """
    time = ds.time.values
    init, rows = [], []
    for i in range(ds.sizes["metronome"]):
        inside0, times, entering = gate_edges(
            time, ds.theta.values[:, run, i], ds.theta_dot.values[:, run, i],
            offset=gate.offset, width=gate.width,
        )  # fmt: skip
        init.append("1" if inside0 else "0")
        rows += [(float(t), i + 1, int(e)) for t, e in zip(times, entering, strict=True)
                 if 0 < t < until]  # fmt: skip
    rows.sort(key=lambda r: r[0])
    return "".join(init).ljust(8, "0"), rows

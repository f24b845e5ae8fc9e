"""Wall and CPU time of `metrosync reproduce` in a fresh output folder, then once more.

The first invocation computes every point; the second finds them all in the point
store and only redraws the figures and the report. CPU time (user + system of the
child) hardly depends on other jobs; wall time does, so the load average is printed
with each figure. The compiled kernels come from numba's cache when it is warm: run
the script twice to see both cases.

    python benchmarks/reproduce.py [--full] [--out DIR]

``--full`` runs the paper's statistics (about a quarter of an hour on 2 idle cores).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed(command: list[str]) -> tuple[float, float]:
    """(wall seconds, CPU seconds) of one child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the paper's statistics")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: temp)")
    args = parser.parse_args()
    mode = "--full" if args.full else "--quick"
    out = args.out or Path(tempfile.mkdtemp(prefix="metrosync-reproduce-"))
    if out.exists():
        shutil.rmtree(out)
    binary = Path(sys.executable).with_name("metrosync")
    command = [str(binary), "reproduce", mode, "--out", str(out), "--no-progress"]
    print(f"{' '.join(command)}; {os.cpu_count()} cores")
    for label in ("every point computed", "every point cached"):
        load = os.getloadavg()[0]
        wall, cpu = timed(command)
        print(f"  {label}: {wall:.1f} s wall, {cpu:.1f} s CPU (load average {load:.1f} before)")
    if args.out is None:
        shutil.rmtree(out)


if __name__ == "__main__":
    main()

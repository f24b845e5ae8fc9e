"""Wall time and peak memory of `metrosync animate` and `metrosync listen`, as a user
runs them: each command in a fresh process, from launch to exit, simulation included.

    python benchmarks/show.py [--repeats 3]

Cases:
  * animate a 120 s run to GIF at the defaults (15 fps, speed-up 4: 451 frames of
    640 x 320 pixels), the target being under 20 s and 500 MB;
  * animate at the defaults (a 600 s run, speed-up 20);
  * listen at the defaults (a 600 s run: a 10 min, 106 MB WAV).

Peak memory is the child's maximum resident set size (``wait4``'s ru_maxrss). The
compile cache is warmed first. Prints the best and the median of ``--repeats`` runs.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The installed command, next to this interpreter (as `make` installs it).
METROSYNC = [str(Path(sys.executable).with_name("metrosync"))]
CASES = {
    "animate, 120 s run to GIF": ["animate", "--duration", "120", "--out", "{dir}/a.gif"],
    "animate, defaults (600 s run)": ["animate", "--out", "{dir}/b.gif"],
    "listen, defaults (600 s run)": ["listen", "--out", "{dir}/t.wav"],
}  # fmt: skip


def run(argv: list[str]) -> tuple[float, float]:
    """(wall seconds, peak RSS in MB) of one command in a fresh process."""
    started = time.perf_counter()
    child = subprocess.Popen([*METROSYNC, *argv], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE)  # fmt: skip
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - started
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed: {child.stderr.read().decode()}")
    child.stderr.close()
    return wall, usage.ru_maxrss / 1024  # KiB on Linux


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="metrosync-show-bench-"))
    try:
        run(["simulate", "--runs", "1", "--duration", "1"])  # warm the compile cache
        for name, argv in CASES.items():
            argv = [a.format(dir=folder) for a in argv]
            results = [run(argv) for _ in range(args.repeats)]
            walls = [w for w, _ in results]
            peaks = [m for _, m in results]
            out = Path(argv[-1])
            print(f"{name}: wall {min(walls):.1f} s best, {statistics.median(walls):.1f} s "
                  f"median; peak RSS {max(peaks):.0f} MB; output {out.stat().st_size / 1e6:.1f} MB "
                  f"({args.repeats} runs)")  # fmt: skip
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()

"""Tracking a video: speed and peak memory on a 10-minute 1080p 60 fps phone video.

Films 20 s of three metronomes with the camera model (1920x1080, 60 fps, every
impairment on, H.264 at a phone's bit rate), repeats the clip's packets with shifted
timestamps into a 10-minute file (no re-encoding: the decoder does the same work as on
a real 10-minute file), and times `metrosync track FILE --out ...` in a fresh process
under /usr/bin/time -v: wall time against the video's length, and the peak resident
memory.

    python benchmarks/video.py                 # 10 minutes
    python benchmarks/video.py --minutes 2     # shorter
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import av
import numpy as np

from metrosync.video.camera import Camera, Scene, film


def clip(path: Path, seconds: float = 20.0) -> None:
    """Three metronomes near 192 BPM, filmed at 1080p60 with every impairment."""
    t = np.arange(0.0, seconds + 0.5, 2e-3)
    freq = np.array([1.58, 1.6, 1.62])
    theta = 0.4 * np.sin(2 * np.pi * freq * t[:, None] + np.array([0.0, 2.0, 4.0]))
    camera = Camera(fps=60, width=1920, height=1080, vfr_jitter_s=0.001, drop_fraction=0.01)
    film(path, t, theta, scene=Scene.random(3, seed=7, overlap=0.0), camera=camera, seed=1)


def repeat(source: Path, target: Path, minutes: float) -> float:
    """Write ``source``'s video packets again and again, shifted, for ``minutes``."""
    with av.open(str(source)) as first:
        stream = first.streams.video[0]
        packets = [p for p in first.demux(stream) if p.pts is not None]
        base = stream.time_base
    span = max(p.pts + (p.duration or 0) for p in packets) - min(p.pts for p in packets)
    copies = int(np.ceil(minutes * 60 / float(span * base)))
    with av.open(str(source)) as src, av.open(str(target), "w") as out:
        template = src.streams.video[0]
        stream = out.add_stream_from_template(template)
        for k in range(copies):
            for p in packets:
                p.pts += span if k else 0
                p.dts = None if p.dts is None else p.dts + (span if k else 0)
                p.stream = stream
                out.mux(p)
    return copies * float(span * base)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--keep", type=Path, default=None, help="keep the video in this folder")
    args = parser.parse_args()
    folder = Path(args.keep or tempfile.mkdtemp(prefix="metrosync-video-"))
    folder.mkdir(parents=True, exist_ok=True)
    source, long = folder / "clip.mp4", folder / f"long-{args.minutes:g}min.mp4"
    if not source.exists():
        started = time.perf_counter()
        clip(source)
        print(f"filmed the 20 s clip in {time.perf_counter() - started:.0f} s")
    if not long.exists():
        length = repeat(source, long, args.minutes)
    else:
        with av.open(str(long)) as c:
            length = c.duration / av.time_base
    print(f"video: {long} ({length:.0f} s, {long.stat().st_size / 1e6:.0f} MB)")
    metrosync = Path(sys.executable).parent / "metrosync"
    command = ["/usr/bin/time", "-v", str(metrosync), "track", str(long),
               "--out", str(folder / "track.nc")]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - started
    if done.returncode:
        sys.exit(done.stderr)
    peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)[1])
    cpu = sum(float(re.search(rf"{kind} time \(seconds\): ([\d.]+)", done.stderr)[1])
              for kind in ("User", "System"))  # fmt: skip
    print(done.stdout.strip().splitlines()[0])
    load = os.getloadavg()[0]
    print(f"wall {wall:.0f} s for {length:.0f} s of video: {length / wall:.2f}x real time; "
          f"CPU {cpu:.0f} s ({cpu / length:.2f} s per s of video); peak memory "
          f"{peak_kb / 1024:.0f} MiB; {os.cpu_count()} cores, load average {load:.1f}")  # fmt: skip


if __name__ == "__main__":
    main()

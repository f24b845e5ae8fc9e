"""Filming a run with the camera model: time and memory per frame, and the cost of an hour.

Films a closed-form swing of N metronomes (default three, 1080p at 60 fps, 10 s, all
of a phone's impairments at `Camera`'s defaults, sound on) after a short warm-up that
compiles the kernels, and prints the frames made, wall time, CPU time (all threads:
drawing and the encoder's), peak resident memory, and what a 10-minute video would
take at the same rate.

    python benchmarks/camera.py                                   # 1080p60, veryfast
    python benchmarks/camera.py --preset ultrafast --seconds 30
    python benchmarks/camera.py --width 640 --height 360 --seconds 10
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from pathlib import Path

import numpy as np

from metrosync.video.camera import Camera, Scene, film


def swing(duration: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, duration, 1e-3)
    f = 1.6 * (1.0 + 0.01 * np.arange(n))
    return t, 0.5 * np.sin(2 * np.pi * f[None, :] * t[:, None] + np.arange(n))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--fps", type=float, default=60.0)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--n", type=int, default=3)
    parser.add_argument("--preset", default="veryfast")
    args = parser.parse_args()
    camera = Camera(fps=args.fps, width=args.width, height=args.height, preset=args.preset)
    scene = Scene.random(args.n, seed=3)
    with tempfile.TemporaryDirectory() as folder:
        t, theta = swing(1.0, args.n)
        film(Path(folder) / "warm.mp4", t, theta, scene=scene,
             camera=Camera(width=160, height=120))  # fmt: skip
        t, theta = swing(args.seconds + 0.3, args.n)
        wall, cpu = time.perf_counter(), time.process_time()
        truth = film(Path(folder) / "clip.mp4", t, theta, scene=scene, camera=camera,
                     audio=True)  # fmt: skip
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        size = truth.path.stat().st_size
    frames = truth.frame_times.size
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{args.width}x{args.height} at {args.fps:g} fps, N = {args.n}, preset {args.preset}: "
          f"{frames} frames ({truth.frame_times[-1]:.1f} s), {size / 1e6:.1f} MB")  # fmt: skip
    print(
        f"  wall {wall:.1f} s ({wall / frames * 1e3:.1f} ms/frame), "
        f"CPU {cpu:.1f} s ({cpu / frames * 1e3:.1f} ms/frame), peak memory {peak:.0f} MB"
    )
    ten = 600.0 * args.fps
    print(
        f"  10 minutes at this rate: wall {ten * wall / frames / 60:.1f} min, "
        f"CPU {ten * cpu / frames / 60:.1f} min"
    )


if __name__ == "__main__":
    main()

"""Analysing a sound recording: speed, peak memory, and accuracy of the round trip.

1. Speed. Simulates seven metronomes for 10 minutes, renders the WAV that
   `metrosync listen` writes (44.1 kHz, 16-bit stereo), and times
   `metrosync analyze FILE.wav --out ... --plot ...` in a fresh process (wall time,
   peak resident memory), and `analyze_audio` alone in this process (median of 3).
2. Accuracy. Three simulated metronomes (90 s): the clicks found against the
   simulated crossings (recall, precision, timing error), and the acoustic order
   parameter against the one computed from the crossings (merged at the detector's
   refractory time, and raw), clean and with reverberation and noise at several SNRs.

    python benchmarks/audio.py            # both
    python benchmarks/audio.py --accuracy # only the second
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import soundfile as sf

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "audio"))

import synth  # noqa: E402

import metrosync  # noqa: E402
from metrosync.audio import analyze_audio  # noqa: E402
from metrosync.audio.order import acoustic_order  # noqa: E402
from metrosync.audio.tempo import beat_period  # noqa: E402
from metrosync.show.recording import RecordedRun  # noqa: E402
from metrosync.show.sound import crossing_times, write_wav  # noqa: E402


def simulated(n, duration, folder, seed=4):
    ds = metrosync.simulate(n, 192.0, sigma_bpm=0.75, duration=duration, record_every=1,
                            trajectories=True, seed=seed)  # fmt: skip
    path = folder / f"sim{n}_{duration:g}.wav"
    write_wav(ds, path)
    return path, crossing_times(RecordedRun.from_dataset(ds))


def speed(folder: Path) -> None:
    # Simulate in a child process: Linux carries a parent's peak memory into the
    # children it forks, so this process must stay small for the measurement below.
    subprocess.run([sys.executable, __file__, "--make", str(folder)], check=True)
    path = folder / "sim7_600.wav"
    info = sf.info(str(path))
    print(f"recording: {info.duration:.0f} s, {info.samplerate} Hz, {info.channels} channels")
    # the peak memory of the command itself, measured inside the fresh process
    probe = (
        "import resource, sys; from metrosync.cli import main; code = main(sys.argv[1:]); "
        "print('maxrss', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); "
        "sys.exit(code)"
    )
    command = [sys.executable, "-c", probe, "analyze", str(path),
               "--out", str(folder / "a.nc"), "--plot", str(folder / "a.png")]  # fmt: skip
    t0 = time.perf_counter()
    done = subprocess.run(command, check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    peak = int(done.stderr.split("maxrss")[-1].split()[0])
    print(f"metrosync analyze (fresh process, with --out and --plot): {wall:.2f} s wall, "
          f"peak memory {peak / 1024:.0f} MiB")  # fmt: skip
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        ds = analyze_audio(path)
        times.append(time.perf_counter() - t0)
    print(
        f"analyze_audio alone: {statistics.median(times):.2f} s (median of 3), "
        f"{ds.sizes['tick']} ticks"
    )


def accuracy(folder: Path) -> None:
    path, crossings = simulated(3, 90.0, folder)
    clean, rate = sf.read(str(path))
    truth = np.sort(np.concatenate(crossings))
    print(
        "condition               recall  precision  timing rms/max (ms)  "
        "|dR| merged max  |dR| raw mean/max"
    )
    for label, snr in [("clean", None), ("reverb, SNR 20 dB", 20.0), ("reverb, SNR 10 dB", 10.0),
                       ("reverb, SNR 0 dB", 0.0), ("reverb, SNR -5 dB", -5.0)]:  # fmt: skip
        x = clean
        if snr is not None:
            rng = np.random.default_rng(15)
            x = synth.add_noise(synth.add_reverb(clean, rng, rate), snr, crossings, rng, rate)
        noisy = synth.write(folder / "noisy.wav", x, rate)
        try:
            ds = analyze_audio(noisy, metronomes=3)
        except metrosync.MetrosyncError as error:
            print(f"{label:22s}  failed: {error}")
            continue
        found = ds.tick_time.values
        times, alone = synth.resolvable(crossings, ds.attrs["refractory"])
        recall, _, errors = synth.match(times[alone], found)
        _, precision, _ = synth.match(times, found)
        diffs = []
        for merge in (True, False):
            t = truth[np.concatenate([[True], np.diff(truth) > ds.attrs["refractory"]])] \
                if merge else truth  # fmt: skip
            o = acoustic_order(t, beat_period(t), window=ds.attrs["order_window"],
                               centres=ds.window.values, metronomes=3)  # fmt: skip
            diffs.append(np.abs(o.r - ds.r_acoustic.values))
        print(
            f"{label:22s}  {recall:6.4f}  {precision:9.4f}  "
            f"{1e3 * np.sqrt(np.mean(errors**2)):7.3f} / {1e3 * np.abs(errors).max():5.3f}"
            f"     {diffs[0].max():13.3f}  {diffs[1].mean():8.3f} / {diffs[1].max():5.3f}"
        )


def main() -> None:
    if sys.argv[1:2] == ["--make"]:
        simulated(7, 600.0, Path(sys.argv[2]))
        return
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if "--accuracy" not in sys.argv:
            speed(folder)
        accuracy(folder)


if __name__ == "__main__":
    main()

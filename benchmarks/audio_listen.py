"""The sound analysis on `metrosync listen`'s click track of metronomes falling into step.

Three simulated metronomes at 192 BPM (σ = 0.75 BPM, seed 4, 90 s: the suite's round
trip, `tests/audio/test_audio_roundtrip.py`) fall into step; their clicks, a pitch of
their own each, are written as `metrosync listen` writes them, and again with room
reverberation and noise at 10 dB SNR. The analysis (`analyze_audio`), told there are
three metronomes, is scored as the round trip scores it: recall over the clicks no
other falls within the detector's resolution of, precision over all, a click matched
within 1 ms.

    python benchmarks/audio_listen.py

Prints one line per recording: recall, precision, the largest timing
error, the metronomes found and the seconds the analysis took.
"""

from __future__ import annotations

import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import soundfile as sf

import metrosync
from metrosync.audio import analyze_audio
from metrosync.show.recording import RecordedRun
from metrosync.show.sound import crossing_times, write_wav
from metrosync.synthetic import clicks, score


def recordings(folder: Path):
    """(name, path) of the clean and the noisy click track, and the crossing times."""
    ds = metrosync.simulate(3, 192.0, sigma_bpm=0.75, duration=90.0, record_every=1,
                            trajectories=True, seed=4)  # fmt: skip
    clean = folder / "listen.wav"
    write_wav(ds, clean)
    crossings = crossing_times(RecordedRun.from_dataset(ds))
    x, rate = sf.read(str(clean))
    rng = np.random.default_rng(15)
    x = clicks.add_noise(clicks.add_reverb(x, rng, rate), 10.0, crossings, rng, rate)
    noisy = clicks.write(folder / "noisy.wav", x, rate)
    return [("clean", clean), ("noise+reverb 10 dB", noisy)], crossings


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        made, crossings = recordings(Path(tmp))
        for name, path in made:
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ds = analyze_audio(path, metronomes=3)
            seconds = time.perf_counter() - t0
            found = ds.tick_time.values
            times, alone = score.resolvable(crossings, ds.attrs["resolution"])
            recall, _, errors = score.match(times[alone], found)
            _, precision, _ = score.match(times, found)
            worst = 1e3 * float(np.abs(errors).max()) if errors.size else float("nan")
            print(f"{name:20s} recall {recall:.4f}  precision {precision:.4f}  "
                  f"timing max {worst:.3f} ms  metronomes {ds.attrs['metronomes']}  "
                  f"{seconds:.1f} s")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())

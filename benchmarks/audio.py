"""Analysing a sound recording: speed, peak memory, and accuracy.

1. Speed. Simulates seven metronomes for 10 minutes, renders the WAV that
   `metrosync listen` writes (44.1 kHz, 16-bit stereo), and times
   `metrosync analyze FILE.wav --out ... --plot ...` in a fresh process (wall time,
   peak resident memory), and `analyze_audio` alone in this process (median of 3).
2. Accuracy. Three simulated metronomes (90 s): the clicks found against the
   simulated crossings (recall, precision, timing error), and the acoustic order
   parameter against the one computed from the crossings (merged at the detector's
   refractory time, and raw), clean and with reverberation and noise at several SNRs.

3. Real-sounding metronomes (`metrosync.synthetic`, as the tests draw them; the frozen
   benchmark corpus is benchmarks/audio_corpus.py's): ten minutes of
   four metronomes of different makes (112, 138, 161 and 187 BPM, speeding up by 0.05
   BPM a minute) heard through a phone (reverberation, noise, bumps, band limits,
   compression), timed as `metrosync analyze FILE.wav` in a fresh process; and over
   24 40 s recordings of one to four metronomes at tempi drawn in 100-200 BPM, how
   often the number of metronomes is right, and each metronome's recall (ticks no
   other hid), precision, timing and tempo error.

    python benchmarks/audio.py            # all
    python benchmarks/audio.py --accuracy # only the second
    python benchmarks/audio.py --corpus   # only the third
    python benchmarks/audio.py --corpus --baseline da6763e  # the ten minutes timed with
        # revision da6763e's analysis too, in turn with this tree's (A B A B)
    python benchmarks/audio.py --seeds 12-23  # the corpus's recordings of seeds 12-23
                                              # (one to four metronomes), not timed
    python benchmarks/audio.py --seeds 0-239 --failures  # and a line for each wrong
        # count and each metronome below 0.99: diff two runs to see what a change moved
"""

from __future__ import annotations

import contextlib
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import soundfile as sf

import metrosync
from metrosync import synthetic
from metrosync.audio import analyze_audio
from metrosync.audio.order import acoustic_order
from metrosync.audio.tempo import beat_period
from metrosync.show.recording import RecordedRun
from metrosync.show.sound import crossing_times, write_wav
from metrosync.synthetic import clicks, score


def simulated(n, duration, folder, seed=4):
    ds = metrosync.simulate(n, 192.0, sigma_bpm=0.75, duration=duration, record_every=1,
                            trajectories=True, seed=seed)  # fmt: skip
    path = folder / f"sim{n}_{duration:g}.wav"
    write_wav(ds, path)
    return path, crossing_times(RecordedRun.from_dataset(ds))


def speed(folder: Path) -> None:
    subprocess.run([sys.executable, __file__, "--make", str(folder)], check=True)
    path = folder / "sim7_600.wav"
    info = sf.info(str(path))
    print(f"recording: {info.duration:.0f} s, {info.samplerate} Hz, {info.channels} channels")
    wall, _, peak, _ = measured_command(["analyze", str(path), "--out", str(folder / "a.nc"),
                                         "--plot", str(folder / "a.png")])  # fmt: skip
    print(f"metrosync analyze (fresh process, with --out and --plot): {wall:.2f} s wall, "
          f"peak memory {peak:.0f} MiB")  # fmt: skip
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
            x = clicks.add_noise(clicks.add_reverb(clean, rng, rate), snr, crossings, rng, rate)
        noisy = clicks.write(folder / "noisy.wav", x, rate)
        try:
            ds = analyze_audio(noisy, metronomes=3)
        except metrosync.MetrosyncError as error:
            print(f"{label:22s}  failed: {error}")
            continue
        found = ds.tick_time.values
        times, alone = score.resolvable(crossings, ds.attrs["resolution"])
        recall, _, errors = score.match(times[alone], found)
        _, precision, _ = score.match(times, found)
        diffs = []
        for merge in (True, False):
            t = truth[np.concatenate([[True], np.diff(truth) > ds.attrs["resolution"]])] \
                if merge else truth  # fmt: skip
            o = acoustic_order(t, beat_period(t), window=ds.attrs["order_window"],
                               centres=ds.window.values, metronomes=3)  # fmt: skip
            diffs.append(np.abs(o.r - ds.r_acoustic.values))
        print(
            f"{label:22s}  {recall:6.4f}  {precision:9.4f}  "
            f"{1e3 * np.sqrt(np.mean(errors**2)):7.3f} / {1e3 * np.abs(errors).max():5.3f}"
            f"     {diffs[0].max():13.3f}  {diffs[1].mean():8.3f} / {diffs[1].max():5.3f}"
        )


def corpus_recording(n, seed, folder, duration=40.0, bpms=None, drift=0.1):
    """A phone recording of n metronomes of different makes, and the true tick times."""
    rng = np.random.default_rng(seed)
    bpms = list(rng.uniform(100, 200, n)) if bpms is None else bpms
    sounds = synthetic.voices(n, seed)
    trains = [synthetic.steady_train(b, duration, phase=rng.uniform(),
                                     limp=0.05 * rng.uniform(), voice=sounds[i],
                                     seed=10 * seed + i, jitter_s=0.5e-3,
                                     drift_bpm_per_min=drift)  # fmt: skip
              for i, b in enumerate(bpms)]  # fmt: skip
    rec = synthetic.make_recording(trains, impairments=synthetic.Impairments.phone(), seed=seed)
    return rec.write(folder / f"corpus{n}_{seed}.wav"), [t.times for t in rec.truth]


def measured_command(args: list[str], root: Path | None = None
                     ) -> tuple[float, float, float, str]:  # fmt: skip
    """``metrosync ARGS`` in a fresh process: (wall s, CPU s, peak memory MiB, stdout);
    from the source of the worktree ``root`` where given (`_baseline`).

    The peak is the process's own high-water mark (VmHWM), read inside it at the end.
    Not `getrusage`'s ru_maxrss: Linux carries the peak of the process that spawned it
    across exec into that figure, and this benchmark's own process is large by then."""
    import resource

    probe = (
        "import sys; from metrosync.cli import main; code = main(sys.argv[1:]); "
        "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM')][0]; "
        "print('peak_kib', hwm.split()[1], file=sys.stderr); sys.exit(code)"
    )
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    from _baseline import environment

    done = subprocess.run([sys.executable, "-c", probe, *args], check=True,
                          capture_output=True, text=True, env=environment(root))  # fmt: skip
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    peak = int(done.stderr.split("peak_kib")[-1].split()[0]) / 1024
    return wall, cpu, peak, done.stdout


def timed_analysis(folder: Path, baseline: str | None = None) -> None:
    """Ten minutes of four metronomes through a phone, analysed in a fresh process: wall
    time, CPU time (user + system of the child) and peak memory; with ``baseline`` (a
    revision), that revision's analysis of the same file too, the two in turn, twice."""
    subprocess.run([sys.executable, __file__, "--make-corpus", str(folder)], check=True)
    command = ["analyze", str(folder / "corpus4_7.wav")]
    with contextlib.ExitStack() as stack:
        trees = [("this tree", None)]
        if baseline is not None:
            from _baseline import checkout

            trees = [(f"revision {baseline}", stack.enter_context(checkout(baseline))),
                     *trees] * 2  # fmt: skip
        for name, root in trees:
            wall, cpu, peak, stdout = measured_command(command, root=root)
            found = [line.strip() for line in stdout.splitlines() if "metronome" in line][:6]
            print(f"10 min, 4 real-sounding metronomes through a phone, metrosync analyze "
                  f"({name}): {wall:.1f} s wall, {cpu:.1f} s CPU (fresh process), peak "
                  f"memory {peak:.0f} MiB")  # fmt: skip
            print("  " + "\n  ".join(found))


def seeds_option(default: range = range(6)) -> list[int]:
    """The corpus's seeds from ``--seeds A-B`` (inclusive) or ``--seeds A,B,C``."""
    if "--seeds" not in sys.argv:
        return list(default)
    at = sys.argv.index("--seeds") + 1
    text = sys.argv[at] if at < len(sys.argv) else ""
    try:
        if "-" in text:
            first, last = (int(x) for x in text.split("-"))
            return list(range(first, last + 1))
        return [int(x) for x in text.split(",")]
    except ValueError:
        sys.exit(f"--seeds {text!r}: give a range A-B or a list A,B,C of whole numbers")


def baseline_option() -> str | None:
    """The revision after ``--baseline``, or None."""
    if "--baseline" not in sys.argv:
        return None
    at = sys.argv.index("--baseline") + 1
    if at >= len(sys.argv) or sys.argv[at].startswith("-"):
        sys.exit("--baseline needs a revision, e.g. --baseline da6763e")
    return sys.argv[at]


def realistic(folder: Path, seeds: list[int], timed: bool = True,
              baseline: str | None = None) -> None:  # fmt: skip
    import warnings

    from metrosync.synthetic.score import hearable, scores

    if timed:
        timed_analysis(folder, baseline)
    right, rows, heard = [], [], []
    for n in (1, 2, 3, 4):
        for seed in seeds:
            p, truth = corpus_recording(n, seed, folder)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ds = analyze_audio(p)
            right.append(ds.attrs["metronomes"] == n)
            # a metronome hidden behind another most of the time: beyond one microphone
            heard.append(min(hearable(truth, k).mean() for k in range(n)) >= 0.5)
            rows.append(scores(ds, truth) if right[-1] else None)
            if "--failures" in sys.argv:
                print_failures(n, seed, ds.attrs["metronomes"], rows[-1])
    right, heard = np.array(right), np.array(heard)
    for name, use in (("all", np.ones(right.size, bool)), ("hearable", heard)):
        table = np.concatenate([r for r, u in zip(rows, use, strict=True) if u and r is not None])
        print(
            f"{use.sum()} recordings ({name}) of 1-4 metronomes (40 s): number right in "
            f"{np.mean(right[use]):.1%}; per metronome (where right): recall median "
            f"{np.median(table[:, 0]):.3f} min {table[:, 0].min():.3f}, share >= 0.99 "
            f"{np.mean(table[:, 0] >= 0.99):.2f}; precision median "
            f"{np.median(table[:, 1]):.3f} min {table[:, 1].min():.3f}, share >= 0.99 "
            f"{np.mean(table[:, 1] >= 0.99):.2f}; timing max {1e3 * table[:, 2].max():.2f} "
            f"ms; BPM error max {table[:, 3].max():.3f}"
        )
        both = (table[:, 0] >= 0.99) & (table[:, 1] >= 0.99)
        print(
            f"  metronomes at recall and precision >= 0.99: {both.sum()} of {both.size} "
            f"({both.mean():.1%}), in the {right[use].sum()} recordings counted right"
        )


def print_failures(n: int, seed: int, found: int, table) -> None:
    """A line for a recording whose number of metronomes is wrong, or for each of its
    metronomes below 0.99 in recall or precision."""
    if table is None:
        print(f"n={n} seed={seed}: {found} metronomes")
        return
    for k, (recall, precision, *_) in enumerate(table):
        if recall < 0.99 or precision < 0.99:
            print(f"n={n} seed={seed} metronome {k}: recall {recall:.3f} precision {precision:.3f}")


OPTIONS = ("--accuracy", "--corpus", "--baseline", "--seeds", "--failures", "--make",
           "--make-corpus")


def main() -> None:
    if "-h" in sys.argv or "--help" in sys.argv:
        print(__doc__)
        return
    unknown = [a for a in sys.argv[1:] if a.startswith("-") and a not in OPTIONS]
    if unknown:
        sys.exit(
            f"unknown option {unknown[0]!r}; the options are {', '.join(OPTIONS[:3])} (see --help)"
        )
    if sys.argv[1:2] == ["--make"]:
        simulated(7, 600.0, Path(sys.argv[2]))
        return
    if sys.argv[1:2] == ["--make-corpus"]:
        corpus_recording(4, 7, Path(sys.argv[2]), duration=600.0, bpms=[112, 138, 161, 187],
                         drift=0.05)  # fmt: skip
        return
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if "--corpus" in sys.argv or "--seeds" in sys.argv:
            realistic(folder, seeds_option(), timed="--seeds" not in sys.argv,
                      baseline=baseline_option())
            return
        if "--accuracy" in sys.argv:
            accuracy(folder)
            return
        speed(folder)
        accuracy(folder)
        realistic(folder, seeds_option())


if __name__ == "__main__":
    main()

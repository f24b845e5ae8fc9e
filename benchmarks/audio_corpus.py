"""The sound analysis scored on the frozen benchmark corpus (`metrosync.synthetic.corpus`).

Each recording of the split is made on the fly from its seed (no audio is kept),
written to a temporary 16-bit WAV, analysed by `metrosync.audio.analyze_audio` with its
defaults (its warnings silenced; an analysis that fails finds no metronome), and scored
against its truth with `metrosync.synthetic.score`: for each true metronome, the
analysed metronome holding most of its hearable ticks (no other metronome's tick in the
40 ms before nor 5 ms after); recall over its hearable ticks and precision over all,
a tick matched within 1 ms; the timing error, the largest error of its matched ticks
(at most 1 ms by the matching: a tick further off is a miss); the tempo error, against
the true mean tempo. A tick's true time is its loud impact.

The figures (targets of the sound model):
- recordings with the number of metronomes right (target >= 98 %);
- metronomes with recall and precision both >= 0.99;
- timing error (target <= 1 ms), tempo error (target <= 0.1 BPM);
- single-metronome recordings reported as two or more (target: none).

    python benchmarks/audio_corpus.py --split dev                 # tune on this
    python benchmarks/audio_corpus.py --split heldout --jobs 2    # report this
    python benchmarks/audio_corpus.py --split dev --limit 10 --json dev.json
    python benchmarks/audio_corpus.py --split heldout --baseline da6763e  # beside an
        # older revision's analysis (da6763e: the stages the timing model replaced)

--limit K keeps the first K mixed recordings and the first K single ones of each tick
structure. --json FILE writes every recording's result and the summary;
--from-json FILE prints the table of such a file again, analysing nothing.
--baseline REV scores revision REV's analysis first, by REV's own copy of this script
(from a temporary git worktree, with the same options), then this tree's.
"""

from __future__ import annotations

import os

# One thread per process: the jobs are the parallelism.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import multiprocessing  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from metrosync.synthetic.corpus import SPLITS, VERSION, Entry, entries  # noqa: E402
from metrosync.synthetic.score import hearable, scores  # noqa: E402
from metrosync.synthetic.structures import STRUCTURES  # noqa: E402

#: A recording counts as heard in full when each metronome has this share of its ticks
#: hearable (two metronomes ticking together all along are beyond one microphone).
HEARD = 0.5


def run_one(entry: Entry) -> dict:
    """Make, analyse and score one recording: a dict of plain values (JSON)."""
    from metrosync.audio import analyze_audio

    t0 = time.perf_counter()
    plan = entry.plan()
    rec = plan.recording()
    truth = [t.times for t in rec.truth]
    n = len(truth)
    error = None
    with tempfile.TemporaryDirectory() as tmp:
        path = rec.write(Path(tmp) / "recording.wav")
        t1 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ds = analyze_audio(path)
            found = int(ds.attrs["metronomes"])
            table = scores(ds, truth)
        except Exception as exc:  # one recording's failure is its result, not the run's
            found, error = 0, f"{type(exc).__name__}: {exc}"
            table = np.tile([0.0, 0.0, np.inf, np.inf], (n, 1))
    t2 = time.perf_counter()
    metronomes = []
    for k, (m, row) in enumerate(zip(plan.metronomes, table, strict=True)):
        recall, precision, timing, bpm_error = (float(v) for v in row)
        metronomes.append(
            {
                "structure": m.structure,
                "bpm": round(m.bpm, 3),
                "limp": round(m.limp, 4),
                "drift_bpm_per_min": round(m.drift_bpm_per_min, 3),
                "jitter_ms": round(1e3 * m.jitter_s, 3),
                "gain": round(m.gain, 3),
                "ticks": int(truth[k].size),
                "hearable": round(float(hearable(truth, k).mean()), 4),
                "recall": round(recall, 4),
                "precision": round(precision, 4),
                "timing_ms": None if not np.isfinite(timing) else round(1e3 * timing, 4),
                "bpm_error": None if not np.isfinite(bpm_error) else round(bpm_error, 4),
            }
        )
    return {
        "name": entry.name,
        "kind": entry.kind,
        "structure": entry.structure,
        "index": entry.index,
        "seed": entry.seed,
        "metronomes": n,
        "found": found,
        "right": found == n,
        "error": error,
        "seconds_make": round(t1 - t0, 2),
        "seconds_analyse": round(t2 - t1, 2),
        "per_metronome": metronomes,
    }


def chosen(split: str, limit: int | None) -> list[Entry]:
    """The split's recordings, at most ``limit`` of each part (mixed; single of each
    structure)."""
    out = []
    for e in entries(split):
        if limit is None or e.index < limit:
            out.append(e)
    return out


def figures(results: list[dict]) -> dict:
    """The summary of some results: counts, shares and errors (see the module)."""
    rows = [m for r in results for m in r["per_metronome"]]
    matched = [m for m in rows if m["timing_ms"] is not None]
    timing = np.array([m["timing_ms"] for m in matched])
    tempo = np.array([m["bpm_error"] for m in matched])
    both = [m["recall"] >= 0.99 and m["precision"] >= 0.99 for m in rows]
    tempo_ok = [m["bpm_error"] is not None and m["bpm_error"] <= 0.1 for m in rows]
    singles = [r for r in results if r["kind"] == "single"]
    return {
        "recordings": len(results),
        "count_right": float(np.mean([r["right"] for r in results])) if results else None,
        "metronomes": len(rows),
        "recall_precision_099": float(np.mean(both)) if rows else None,
        "timing_ms_median": float(np.median(timing)) if timing.size else None,
        "timing_ms_max": float(timing.max()) if timing.size else None,
        "bpm_error_median": float(np.median(tempo)) if tempo.size else None,
        "bpm_error_max": float(tempo.max()) if tempo.size else None,
        "bpm_error_within_01": float(np.mean(tempo_ok)) if rows else None,
        "single_as_two_or_more": sum(r["found"] >= 2 for r in singles),
        "singles": len(singles),
        "failed": sum(r["error"] is not None for r in results),
    }


def groups(results: list[dict]) -> dict[str, list[dict]]:
    mixed = [r for r in results if r["kind"] == "mixed"]
    heard = [r for r in mixed if min(m["hearable"] for m in r["per_metronome"]) >= HEARD]
    out = {f"mixed, {n} metronome{'s' * (n > 1)}": [r for r in mixed if r["metronomes"] == n]
           for n in (1, 2, 3, 4)}  # fmt: skip
    out["mixed, all"] = mixed
    out["mixed, each heard"] = heard
    precursor = [r for r in mixed if any(m["structure"] == "precursor" for m in r["per_metronome"])]
    out["mixed, no precursor"] = [r for r in mixed if r not in precursor]
    out["mixed, a precursor"] = precursor
    for name in STRUCTURES:
        out[f"single, {name}"] = [r for r in results if r["structure"] == name]
    out["single, all"] = [r for r in results if r["kind"] == "single"]
    out["all"] = results
    return {name: rows for name, rows in out.items() if rows}


def _share(value) -> str:
    return "—" if value is None else f"{100 * value:.1f} %"


def _number(value, digits: int = 2) -> str:
    return "—" if value is None else f"{value:.{digits}f}"


def table(results: list[dict]) -> str:
    head = (f"{'':22s} {'recs':>5s} {'count right':>11s} {'metr.':>6s} {'R&P>=.99':>9s} "
            f"{'timing ms med/max':>18s} {'BPM err med/max':>16s} {'<=0.1':>7s} "
            f"{'>=2 found':>9s} {'failed':>6s}")  # fmt: skip
    lines = [head, "-" * len(head)]
    for name, rows in groups(results).items():
        f = figures(rows)
        two = f"{f['single_as_two_or_more']}/{f['singles']}" if f["singles"] else "—"
        lines.append(
            f"{name:22s} {f['recordings']:5d} {_share(f['count_right']):>11s} "
            f"{f['metronomes']:6d} {_share(f['recall_precision_099']):>9s} "
            f"{_number(f['timing_ms_median'], 3) + ' / ' + _number(f['timing_ms_max'], 3):>18s} "
            f"{_number(f['bpm_error_median'], 3) + ' / ' + _number(f['bpm_error_max'], 2):>16s} "
            f"{_share(f['bpm_error_within_01']):>7s} {two:>9s} {f['failed']:6d}"
        )
    return "\n".join(lines)


def must_show(results: list[dict], split: str) -> str:
    f = figures(results)
    return "\n".join([
        f"corpus version {VERSION}, split {split}: {f['recordings']} recordings, "
        f"{f['metronomes']} metronomes",
        f"  number of metronomes right: {_share(f['count_right'])} of the recordings "
        "(target >= 98 %)",
        f"  metronomes at tick recall and precision >= 0.99: {_share(f['recall_precision_099'])}",
        f"  timing error (largest per metronome, matched ticks): median "
        f"{_number(f['timing_ms_median'], 3)} ms, max {_number(f['timing_ms_max'], 3)} ms "
        "(target <= 1 ms)",
        f"  tempo error: median {_number(f['bpm_error_median'], 3)} BPM, max "
        f"{_number(f['bpm_error_max'], 2)} BPM; within 0.1 BPM: "
        f"{_share(f['bpm_error_within_01'])} of the metronomes (target <= 0.1 BPM)",
        f"  single-metronome recordings reported as two or more: "
        f"{f['single_as_two_or_more']} of {f['singles']} (target: none)",
        f"  analyses that failed: {f['failed']}",
    ])  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Score the sound analysis on the benchmark corpus's recordings."
    )
    parser.add_argument("--split", choices=sorted(SPLITS))
    parser.add_argument("--baseline", metavar="REV", default=None,
                        help="score revision REV's analysis first (its own copy of this "
                        "script, same options), then this tree's")  # fmt: skip
    parser.add_argument(
        "--limit",
        type=int,
        default=None,
        metavar="K",
        help="at most K mixed recordings and K single ones of each structure",
    )
    parser.add_argument(
        "--jobs", type=int, default=1, metavar="N", help="processes analysing at once (default 1)"
    )
    parser.add_argument("--json", type=Path, default=None, metavar="FILE",
                        help="write each recording's result and the summary here")  # fmt: skip
    parser.add_argument("--from-json", type=Path, default=None, metavar="FILE",
                        help="print the table of a file --json wrote; analyse nothing")  # fmt: skip
    args = parser.parse_args(argv)
    if args.from_json is not None:
        document = json.loads(args.from_json.read_text(encoding="utf-8"))
        print(table(document["results"]))
        print()
        print(must_show(document["results"], document["split"]))
        print(f"\n{document['command']}, {document['date']}, {document['machine']}, "
              f"{document['minutes']} min with {document['jobs']} jobs")  # fmt: skip
        return 0
    if args.split is None:
        parser.error("--split is needed (or --from-json FILE)")
    if args.limit is not None and args.limit < 1:
        parser.error(f"--limit must be a whole number >= 1, got {args.limit}")
    if args.jobs < 1:
        parser.error(f"--jobs must be a whole number >= 1, got {args.jobs}")
    if args.baseline is not None:
        _score_baseline(args.baseline, argv if argv is not None else sys.argv[1:])
    todo = chosen(args.split, args.limit)
    order = {e.name: i for i, e in enumerate(todo)}
    print(f"corpus version {VERSION}, split {args.split}: {len(todo)} recordings, "
          f"{args.jobs} job{'s' * (args.jobs > 1)}", file=sys.stderr)  # fmt: skip
    started = time.perf_counter()
    results = []
    context = multiprocessing.get_context("spawn")
    with context.Pool(args.jobs) as pool:
        for r in pool.imap_unordered(run_one, todo):
            results.append(r)
            elapsed = time.perf_counter() - started
            left = elapsed / len(results) * (len(todo) - len(results))
            mark = "right" if r["right"] else f"WRONG ({r['found']} found)"
            if r["error"]:
                mark += f", failed: {r['error'][:80]}"
            print(f"[{len(results)}/{len(todo)}] {r['name']}: {r['metronomes']} "
                  f"metronome{'s' * (r['metronomes'] > 1)}, {mark}; "
                  f"{elapsed / 60:.1f} min, about {left / 60:.1f} min left",
                  file=sys.stderr, flush=True)  # fmt: skip
    results.sort(key=lambda r: order[r["name"]])
    elapsed = time.perf_counter() - started
    print(table(results))
    print()
    print(must_show(results, args.split))
    print(f"\n{len(results)} recordings in {elapsed / 60:.1f} min with {args.jobs} "
          f"job{'s' * (args.jobs > 1)} on {platform.machine()}, {os.cpu_count()} CPUs")  # fmt: skip
    if args.json is not None:
        document = {
            "corpus_version": VERSION,
            "split": args.split,
            "revision": _revision(),
            "limit": args.limit,
            "command": " ".join(["python", "benchmarks/audio_corpus.py", *sys.argv[1:]]),
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "machine": f"{platform.machine()}, {os.cpu_count()} CPUs, {platform.platform()}",
            "jobs": args.jobs,
            "minutes": round(elapsed / 60, 2),
            "summary": {name: figures(rows) for name, rows in groups(results).items()},
            "results": results,
        }
        args.json.write_text(json.dumps(document, indent=1) + "\n", encoding="utf-8")
        print(f"results: {args.json}")
    return 0


def _score_baseline(rev: str, argv: list[str]) -> None:
    """Revision ``rev``'s own copy of this script, with these options but --baseline and
    --json, on its own source."""
    from _baseline import checkout, environment

    rest, skip = [], 0
    for a in argv:
        if skip:
            skip -= 1
        elif a in ("--baseline", "--json"):
            skip = 1
        elif not a.startswith(("--baseline=", "--json=")):
            rest.append(a)
    with checkout(rev) as root:
        print(f"--- revision {rev} ---", flush=True)
        subprocess.run([sys.executable, str(root / "benchmarks" / "audio_corpus.py"), *rest],
                       env=environment(root), check=True)  # fmt: skip
    print("--- this tree ---", flush=True)


def _revision() -> str:
    """This tree's commit (with "+changes" where the work tree differs from it)."""
    here = str(Path(__file__).resolve().parent)
    head = subprocess.run(["git", "-C", here, "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip()  # fmt: skip
    dirty = subprocess.run(["git", "-C", here, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()  # fmt: skip
    return head + ("+changes" if dirty else "")


if __name__ == "__main__":
    sys.exit(main())

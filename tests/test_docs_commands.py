"""Every command-line example of the README and of the site's pages (```sh blocks) runs,
at reduced size, in the order a reader meets it: each page's commands share one
folder, so a file written by one example is there for the next.

The sizes shrink (``--duration``, ``--runs``, the grid of a sweep), never the options:
the line a reader copies is the line that runs, less work. A command that needs
hardware, a cluster or minutes is listed in ``ELSEWHERE`` with the test that runs it
instead (checked to exist), and a new example that is in neither list fails.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SHELL_BLOCK = re.compile(r"^```(?:sh|bash|console)\n(.*?)^```", flags=re.S | re.M)

#: Commands run by another test, or not at all, and why: (pattern, reason, test or None).
ELSEWHERE = [
    (
        r"^make (run|test)$",
        "the two commands themselves: CI runs `make test`; `make run` is "
        "`reproduce --quick`, which the reproduce tests run study by study",
        "tests/reproduce/test_reproduce_cli.py::test_one_study_end_to_end",
    ),
    (
        r"^make (firmware|flash)\b",
        "the firmware's build and flashing (avrdude is faked there)",
        "tests/firmware/test_build.py::test_flash_sends_the_firmware_of_the_options_given",
    ),
    (
        r"^python -m pip install ",
        "installing: the wheel test installs the built package",
        "tests/test_wheel.py::test_version_simulate_and_playground_run_from_the_wheel",
    ),
    (
        r"^(NUMBA_NUM_THREADS=1 )?dask (scheduler|worker) ",
        "a Dask cluster on other machines",
        "tests/sweeps/test_sweep_executors.py::test_existing_scheduler_over_tcp_is_bit_identical",
    ),
    (
        r"--scheduler tcp://10\.",
        "a sweep on that cluster (a scheduler on this machine there)",
        "tests/sweeps/test_sweep_executors.py::test_existing_scheduler_over_tcp_is_bit_identical",
    ),
    (
        r"^metrosync record /dev/",
        "needs the logger on a serial port; recorded through a pseudo-terminal instead",
        "tests/lightgate/test_pty_roundtrip.py::"
        "test_record_over_a_pty_captures_what_was_sent_and_analyses_like_the_simulation",
    ),
    (
        r"^metrosync analyze --follow ",
        "follows the capture until Ctrl-C",
        "tests/lightgate/test_follow.py::test_analyze_follow_writes_at_ctrl_c_what_analyze_writes",
    ),
    (
        r"^metrosync track ",
        "needs a video of metronomes; tracked on drawn videos",
        "tests/video/test_video_cli.py::test_track_writes_the_dataset_plot_and_preview",
    ),
    (
        r"^metrosync reproduce ",
        "minutes to hours; the pipeline runs one study end to end",
        "tests/reproduce/test_reproduce_cli.py::test_one_study_end_to_end",
    ),
    (
        r"^metrosync pantaleone ",
        "a few minutes; the report runs end to end at a tiny size",
        "tests/pantaleone/test_pantaleone.py::test_the_report_runs_end_to_end",
    ),
    (
        r"^metrosync theory ",
        "measures the coupling on the full model (about 35 s); the "
        "command runs on a cached measurement",
        "tests/theory/test_predict.py::test_cli_prints_writes_and_plots",
    ),
]


def commands(page: Path) -> list[str]:
    """The page's command lines, continuation lines joined, comments dropped."""
    found = []
    for block in SHELL_BLOCK.findall(page.read_text()):
        for line in block.replace("\\\n", " ").splitlines():
            line = re.sub(r"\s+#.*$", "", line).strip()
            line = re.sub(r"^\.venv/bin/", "", line)
            if line and not line.startswith("#"):
                found.append(" ".join(line.split()))
    return found


def elsewhere(command: str):
    return next((entry for entry in ELSEWHERE if re.search(entry[0], command)), None)


def runnable(command: str) -> bool:
    return command.startswith(("metrosync ", "python docs/")) and elsewhere(command) is None


#: Each runnable command once, in the folder of the first page that shows it: every page's
#: folder starts with the same inputs, so a line that two pages show (the README repeats
#: a few of the site's) runs the same there.
FIRST_SHOWN: dict[str, Path] = {}
for _page in PAGES:
    for _command in filter(runnable, commands(_page)):
        FIRST_SHOWN.setdefault(_command, _page)
EXAMPLES = [(page, command) for command, page in FIRST_SHOWN.items()]


def smaller(command: str) -> list[str]:
    """``command`` at reduced size, as an argument list for this interpreter."""
    command = command.replace("docs/figures/", "").replace("studies/", f"{ROOT}/studies/")
    words = shlex.split(command)
    if words[0] == "python":
        # Its coarse grid, at the paper's step instead of 0.002 s: the machinery, not the figure.
        options = ["--quick", "--dt", "0.01", "--out", "tongue.png"]
        return [sys.executable, str(ROOT / words[1]), *words[2:], *options]
    shrink = {"--duration": "20", "--runs": "2", "--window": "5",
              "--n": lambda v: ",".join(v.split(",")[:2]), "--group-offset-bpm": "0:24:12",
              }  # fmt: skip
    out = []
    for i, word in enumerate(words):
        before = words[i - 1] if i else ""
        rule = shrink.get(before)
        out.append(word if rule is None else rule(word) if callable(rule) else rule)
    verb = out[1] if len(out) > 1 else ""
    if verb in {"simulate", "sweep", "animate", "listen"} and "--duration" not in out:
        out += ["--duration", "20"]
    if verb == "critical" and "--bootstrap" not in out:
        out += ["--bootstrap", "20"]  # replicas for the error bars (1000 by default)
    if verb == "sweep":
        out += [] if "--runs" in out else ["--runs", "2"]
        grid_file = any(w.endswith(".toml") for w in out)
        # A grid file's own grid, cut to 7 frequencies at 2 small sizes: enough for
        # `critical` (its collapse fit needs more than 9 points).
        out += ["--bpm", "166:178:2"] if grid_file and "--bpm" not in out else []
        out += ["--n", "16,32"] if grid_file and "--n" not in out else []
        # a grid file that grows each point to a target error grows it two batches at most
        adaptive = any(w.endswith(".toml") and Path(w).is_file()
                       and "target_error" in Path(w).read_text() for w in out)  # fmt: skip
        out += ["--max-runs", "4"] if adaptive and "--max-runs" not in out else []
        out += ["--no-progress"]
    return [sys.executable, "-m", "metrosync", *out[1:]]


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """One folder per page, with the inputs its examples name but do not make."""
    import soundfile

    import metrosync
    from metrosync.lightgate.virtual import LightGate, write_logs

    made = {}
    ds = metrosync.simulate(3, 192.0, sigma_bpm=0.75, runs=2, duration=30, trajectories=True,
                            record_every=1, seed=1)  # fmt: skip
    # A free decay from 0.8 rad swings past the gate at 0.1 rad for about 4 s.
    decay = metrosync.simulate(1, 192.0, duration=4, theta0=[0.8], theta_dot0=[0.0],
                               trajectories=True, record_every=1,
                               changes={"drive": 0.0, "inertia": float("inf")})  # fmt: skip
    fig10 = re.search(r"^```toml\n(.*?)^```", (ROOT / "docs" / "sweeps.md").read_text(),
                      flags=re.S | re.M).group(1)  # fmt: skip
    for page in PAGES:
        folder = tmp_path_factory.mktemp(page.stem)
        logs = write_logs(ds, folder / "gate")
        for i, log in enumerate(logs, start=1):
            (folder / f"run{i}.log").write_bytes(log.read_bytes())
        (decay_log,) = write_logs(decay, folder / "decay", LightGate(offset=0.1))
        (folder / "decay.log").write_bytes(decay_log.read_bytes())
        metrosync.write_wav(ds.isel(run=[0]), folder / "recording.wav")
        audio, rate = soundfile.read(folder / "recording.wav")
        soundfile.write(folder / "recording.flac", audio, rate)
        (folder / "fig10.toml").write_text(fig10)
        made[page] = folder
    return made


def test_every_example_is_run_here_or_by_a_named_test():
    seen = {c for page in PAGES for c in commands(page)}
    assert len(seen) > 30, "the pattern for shell blocks found too few commands"
    unclaimed = [c for c in seen if not runnable(c) and elsewhere(c) is None]
    assert unclaimed == []
    for _pattern, _reason, test in ELSEWHERE:
        path, name = test.split("::")
        assert f"def {name}(" in (ROOT / path).read_text(), test


@pytest.mark.parametrize(
    ("page", "command"),
    # A page's examples run on one xdist worker, in the page's order (`--dist loadgroup`).
    [pytest.param(p, c, marks=pytest.mark.xdist_group(f"docs-{p.stem}")) for p, c in EXAMPLES],
    ids=[f"{p.name}: {c[:60]}" for p, c in EXAMPLES],
)
def test_the_example_runs_at_reduced_size(page, command, folders):
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "MPLBACKEND": "Agg"}
    argv = smaller(command)
    done = subprocess.run(argv, cwd=folders[page], env=env, capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert done.returncode == 0, f"{shlex.join(argv)}\n{done.stdout[-2000:]}{done.stderr[-3000:]}"


def test_reduction_keeps_the_options_and_shrinks_the_sizes():
    argv = smaller("metrosync simulate --n 7 --runs 20 --duration 600 --out r.nc")
    assert argv[4:] == ["--n", "7", "--runs", "2", "--duration", "20", "--out", "r.nc"]
    argv = smaller("metrosync sweep studies/large_n/quick.toml --n 64,256,1024 --out q.nc")
    assert "64,256" in argv and "166:178:2" in argv
    assert argv[argv.index("--max-runs") + 1] == "4"
    assert np.isin(["--runs", "--duration"], argv).all()

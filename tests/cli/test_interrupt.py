"""Ctrl-C: one line that says what was kept, exit status 130, no partial file, and
within a couple of seconds, also in the middle of long compiled work."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from metrosync import interrupts
from metrosync.cli import main
from metrosync.errors import Interrupted

# Runs the command line in a child that leaves a marker when the compiled kernel is
# first entered, so that the test signals it in the middle of the work, not during
# start-up.
CHILD = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    from metrosync.integrators import verlet
    advance = verlet.advance_state
    def marked(*args, **kwargs):
        Path(sys.argv[1]).touch()
        return advance(*args, **kwargs)
    verlet.advance_state = marked
    from metrosync.cli import main
    sys.exit(main(sys.argv[2:]))
    """
)


#: How soon an interrupt must end the process. Generous, so that a loaded machine's slow
#: interpreter shutdown does not fail the test; every interrupted job below would run for
#: minutes uninterrupted, so the bound still tells "stopped at the next check" from
#: "stopped at the end".
PROMPT = 15.0


def interrupt_child(tmp_path: Path, argv: list[str], *, ready, settle: float = 1.0):
    """Start the CLI with ``argv``, wait until ``ready()``, send SIGINT; return
    (exit status, stderr, seconds from the signal to the exit)."""
    marker = tmp_path / "kernel-entered"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(marker), *argv],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "NUMBA_NUM_THREADS": "2"},
    )  # fmt: skip
    deadline = time.monotonic() + 120
    while not (marker.exists() and ready()):
        assert child.poll() is None, child.stderr.read()
        assert time.monotonic() < deadline, "the child never started computing"
        time.sleep(0.05)
    time.sleep(settle)  # well inside the compiled work
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=60)
    # Long jobs warn first that they are long, and a cold compile cache says it compiles;
    # what the interrupt says is the last line.
    lines = err.splitlines(keepends=True)
    assert all(
        "warning: " in line or line.startswith("metrosync: compiling kernels, once")
        for line in lines[:-1]
    ), err
    return child.returncode, "".join(lines[-1:]), time.monotonic() - sent


def test_ctrl_c_in_a_long_kernel_run_of_simulate(tmp_path):
    out = tmp_path / "out"
    # 4000 runs x 600000 steps (minutes of work), recorded every 200000 steps: before
    # chunks were timed, one compiled call ran for a whole record interval.
    argv = ["simulate", "--runs", "4000", "--duration", "6000", "--save-every", "200000",
            "--out", str(out / "r.nc"), "--plot", str(out / "r.png")]  # fmt: skip
    code, err, seconds = interrupt_child(tmp_path, argv, ready=lambda: True)
    assert code == 130
    assert err == "metrosync simulate: interrupted: nothing was written\n"
    assert seconds < PROMPT, f"took {seconds:.1f} s to stop"
    assert not out.exists() or list(out.iterdir()) == []


def test_ctrl_c_in_an_in_process_sweep_says_what_was_kept(tmp_path):
    store = tmp_path / "sw.points"
    points = store / "points"
    argv = ["sweep", "--bpm", "186:194:2", "--n", "7", "--runs", "1000", "--duration", "300",
            "--out", str(tmp_path / "sw.nc")]  # fmt: skip
    code, err, seconds = interrupt_child(
        tmp_path, argv, ready=lambda: points.is_dir() and any(points.glob("*.nc")), settle=0.5
    )
    assert code == 130
    kept = len(list(points.glob("*.nc")))
    assert err == (
        f"metrosync sweep: interrupted: {kept} of 5 points kept in {store}; run the same "
        f"command again to resume\n"
    )
    assert 1 <= kept < 5
    assert seconds < PROMPT, f"took {seconds:.1f} s to stop"
    assert not (tmp_path / "sw.nc").exists()
    assert not list(tmp_path.rglob("*partial*"))


@pytest.mark.slow
def test_ctrl_c_in_a_dask_sweep_stops_the_cluster_quietly(tmp_path):
    store = tmp_path / "sw.points"
    points = store / "points"
    argv = ["sweep", "--bpm", "186:194:2", "--n", "7", "--runs", "1000", "--duration", "300",
            "--scheduler", "local", "--workers", "2", "--out", str(tmp_path / "sw.nc")]  # fmt: skip
    # The kernel runs in the workers: wait for a stored point instead of the marker.
    (tmp_path / "kernel-entered").touch()
    code, err, seconds = interrupt_child(
        tmp_path, argv, ready=lambda: points.is_dir() and any(points.glob("*.nc")), settle=0.5
    )
    assert code == 130
    assert re.fullmatch(
        r"metrosync sweep: interrupted: [1-4] of 5 points kept in .*; run the same command "
        r"again to resume\n",
        err,
    ), err
    assert seconds < PROMPT, f"took {seconds:.1f} s to stop"


def test_a_lost_interrupt_is_raised_again_at_the_next_check(capsys):
    class Swallows:
        def __del__(self):  # Python discards what __del__ raises, as it does in gc callbacks
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(10**7):  # the handler runs at one of these bytecodes
                pass

    with interrupts.sigint_checked():
        Swallows()  # the interrupt is raised and lost in __del__
        with pytest.raises(KeyboardInterrupt):
            interrupts.check()
    interrupts.check()  # outside, nothing is pending
    assert capsys.readouterr().err == ""  # and nothing was printed about it


def test_a_library_error_after_ctrl_c_is_reported_as_the_interrupt(monkeypatch, capsys):
    """SIGINT raised inside a library (matplotlib drawing a frame) can break it so that
    it fails with an error of its own; after Ctrl-C that is the interrupt, not a bug."""
    import metrosync.cli as cli

    def interrupted_then_broken(argv):
        interrupts._requested.set()  # as SIGINT does
        raise ValueError("Invalid affine transformation matrix")

    monkeypatch.setattr(cli, "_run", interrupted_then_broken)
    assert cli.main(["animate"]) == 130
    assert capsys.readouterr().err == "metrosync animate: interrupted: nothing was written\n"

    def broken(argv):  # without an interrupt, an error stays an error
        raise ValueError("a real bug")

    monkeypatch.setattr(cli, "_run", broken)
    with pytest.raises(ValueError, match="a real bug"):
        cli.main(["animate"])


def test_reproduce_says_how_many_points_it_kept(tmp_path, monkeypatch):
    from metrosync.paper import pipeline

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "run_study", stop)
    with pytest.raises(Interrupted) as interrupt:
        pipeline.reproduce(tmp_path, studies=["fig8_top"])
    assert re.fullmatch(
        rf"0 of \d+ points kept in {re.escape(str(tmp_path / 'points'))}; run the same "
        r"command again to resume",
        interrupt.value.kept,
    )


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["animate", "--duration", "1200", "--speedup", "1", "--dpi", "40"], "a.gif"),
        (["listen", "--duration", "3500", "--speedup", "1"], "t.wav"),
    ],
)
def test_ctrl_c_while_writing_leaves_no_partial_file(tmp_path, argv, name):
    out = tmp_path / "out"
    (tmp_path / "kernel-entered").touch()  # wait for the file being written instead
    code, err, seconds = interrupt_child(
        tmp_path, [*argv, "--out", str(out / name)],
        ready=lambda: out.is_dir() and any(out.glob(".*partial*")), settle=0.3,
    )  # fmt: skip
    assert code == 130
    assert err == f"metrosync {argv[0]}: interrupted: nothing was written\n"
    assert seconds < PROMPT, f"took {seconds:.1f} s to stop"
    assert list(out.iterdir()) == []


@pytest.mark.slow
def test_an_interrupted_sweep_prints_nothing_after_its_one_line(tmp_path):
    # Merging opens one file per point: an interrupt in the middle of an h5netcdf open
    # left a half-made file whose finalizer complained after the summary (KeyError,
    # AttributeError '_closed'), about one time in ten. Interrupt it at many moments.
    out = tmp_path / "w.nc"
    argv = ["sweep", "--bpm", "150:200:0.5", "--n", "2", "--runs", "1", "--duration", "1",
            "--no-progress", "--out", str(out)]  # fmt: skip
    assert subprocess.run([sys.executable, "-m", "metrosync", *argv],
                          capture_output=True).returncode == 0  # fmt: skip
    # How long the work lasts after its first line on this machine, now, until its
    # result is written (not until the process ends: a loaded machine's interpreter
    # shut-down would take the interrupts past the work): the interrupts are spread over
    # that, so that most land during it however loaded the machine is.
    out.unlink()
    child = subprocess.Popen([sys.executable, "-m", "metrosync", *argv],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    child.stdout.readline()
    begin = time.monotonic()
    while not out.is_file() and child.poll() is None:
        time.sleep(0.005)
    work = time.monotonic() - begin
    child.communicate(timeout=60)
    rng = np.random.default_rng(7)
    stopped = 0
    for delay in rng.uniform(0.0, 0.9 * work, 12):
        out.unlink(missing_ok=True)
        child = subprocess.Popen(
            [sys.executable, "-m", "metrosync", *argv],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        child.stdout.readline()  # "N points, grid ...": the merge is next
        time.sleep(delay)
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=60)
        assert "Traceback" not in err and "Exception ignored" not in err, err
        if child.returncode == 130:
            stopped += 1
            (line,) = err.splitlines()
            assert line in (
                "metrosync sweep: interrupted: nothing was written",  # before the merge
                f"metrosync sweep: interrupted: 101 of 101 points kept in "
                f"{out.with_suffix('.points')}; run the same command again to resume",
                # after the merge wrote the result, before the command ended
                f"metrosync sweep: interrupted: kept {out} (complete); the rest was not written",
            )
        else:  # the signal came after the work: it finished whole
            assert child.returncode == 0 and out.is_file(), err
    assert stopped >= 4, "too few interrupts landed during the work to test anything"


def test_ctrl_c_absorbed_by_the_work_still_exits_130(monkeypatch, capsys):
    # A write that took the interrupt and completed (HDF5 finishing a dataset), or a
    # capture that ends at Ctrl-C: the command still ends as an interrupted one.
    import metrosync.cli.presets as presets

    def absorbs(args):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)
        except KeyboardInterrupt:
            pass
        print("work finished")
        return 0

    monkeypatch.setattr(presets, "run", absorbs)
    assert main(["presets"]) == 130
    captured = capsys.readouterr()
    assert "work finished" in captured.out
    assert captured.err == "metrosync presets: interrupted: nothing was written\n"


def test_ctrl_c_while_the_command_starts_is_one_line_not_a_traceback():
    # Before the entry point ran, the command line's imports (numpy, xarray: half a
    # second) took Ctrl-C as a traceback ending in KeyboardInterrupt.
    # Before the interpreter reaches metrosync (its own start-up, runpy), Ctrl-C is
    # Python's; time that on this machine and begin just after it.
    begin = time.monotonic()
    subprocess.run([sys.executable, "-c", "import runpy"], check=True)
    python = time.monotonic() - begin
    stopped = 0
    for delay in python * 1.5 + np.array([0.0, 0.03, 0.06, 0.1, 0.15, 0.25, 0.4, 0.6]):
        child = subprocess.Popen(
            [sys.executable, "-m", "metrosync", "simulate", "--duration", "3000"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        time.sleep(delay)
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=60)
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, (delay, err)
        if child.returncode == -signal.SIGINT:
            assert err == ""  # the interpreter itself was still starting: killed silently
            continue
        assert child.returncode == 130, (delay, err)
        assert err == "metrosync simulate: interrupted: nothing was written\n"
        stopped += 1
    assert stopped >= 5

"""Regenerate the sample light-gate logs of this folder with metrosync's own generator.

    python tests/data/make_sample_logs.py

clean.log  3 metronomes, 192 BPM, σ = 0.5 BPM, 20 s, simulate seed 7, virtual gate at
           offset 0.1 rad, width 0.05 rad, 64 µs ticks, 16-bit counter from 60000
           (so it wraps), no jitter.
messy.log  the same capture, damaged as a terminal capture is (`damage`): a terminal
           banner, CRLF line ends, blank lines, a 0.2 ms glitch, one missed pass,
           inverted polarity (0 = interrupted), and a last line cut in the middle.
"""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).parent
SEED = 7


def clean_text() -> str:
    from metrosync import simulate
    from metrosync.lightgate import LightGate, format_log

    ds = simulate(
        3,
        192.0,
        sigma_bpm=0.5,
        duration=20.0,
        seed=SEED,
        record_every=1,
        trajectories=True,
        progress=False,
    )
    gate = LightGate(offset=0.1, width=0.05, counter_bits=16, start_tick=60000, seed=SEED)
    return format_log(ds.time.values, ds.theta.values[:, 0], ds.theta_dot.values[:, 0], gate)


def damage(text: str) -> str:
    """Make a clean capture messy, deterministically."""
    lines = text.splitlines()
    # Inverted polarity: this logger prints 0 for an interrupted beam.
    lines = [
        "-".join("1" if c == "0" else "0" for c in line.split()[0].split("-"))
        + " "
        + line.split()[1]
        for line in lines
    ]
    # A missed pass on gate 1: the two lines of one interruption lose that gate's change.
    hits = [
        i
        for i in range(1, len(lines))
        if lines[i].split()[0].split("-")[1] != lines[i - 1].split()[0].split("-")[1]
    ]
    for i in hits[40:42]:
        gates = lines[i].split()[0].split("-")
        gates[1] = "1"
        lines[i] = "-".join(gates) + " " + lines[i].split()[1]
    # A glitch on gate 2: 3 ticks (0.19 ms) of interruption while its beam is open.
    j = next(
        i
        for i in range(100, len(lines) - 1)
        if lines[i].split()[0][4] == "1" and lines[i + 1].split()[0][4] == "1"
    )
    t = int(lines[j].split()[1])
    gates = lines[j].split()[0].split("-")
    gates[2] = "0"
    lines.insert(j + 1, "-".join(gates) + f" {t + 1}")
    gates[2] = "1"
    lines.insert(j + 2, "-".join(gates) + f" {t + 4}")
    lines.insert(60, "")
    lines.insert(200, "")
    banner = [
        "",
        "Welcome to minicom 2.7.1",
        "",
        "OPTIONS: I18n",
        "Port /dev/ttyUSB0, 14:02:11",
        "Press CTRL-A Z for help on special keys",
        "",
    ]
    body = "\r\n".join(banner + lines)
    return body[:-3]  # the capture stopped in the middle of the last line


def main() -> None:
    clean = clean_text()
    (HERE / "clean.log").write_text(clean, newline="")
    (HERE / "messy.log").write_text(damage(clean), newline="")
    print(f"wrote {HERE / 'clean.log'} and {HERE / 'messy.log'}")


if __name__ == "__main__":
    main()

"""Frames per second of the playground page in headless Chromium, from its own counter.

For each (N, speed) it writes the page, presses Play, lets it warm up for a second,
then counts the frames the page drew (``window.metrosync.frames``) and the simulated
time it covered over ``--seconds`` of wall time; before that, the time one step of
the simulation takes in the browser (2000 steps, timed by the page). Headless
Chromium draws at most 60 frames a second; software rendering (no GPU) is what a
projector's laptop may have.

    python benchmarks/playground.py                          # N = 7, 100 at 1x, 10x, 50x
    python benchmarks/playground.py --cases 100x10 --seconds 10
    python benchmarks/playground.py --screenshot docs/figures/playground.png

``--screenshot`` instead plays a short lesson at 20x (30 metronomes, the disk held
for 40 s, then let go), pauses at 95 s and saves the page as it looks then. It needs the Debian
package chromium and the test harness in tests/show/cdp.py.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "show"))
from cdp import Browser  # noqa: E402

from metrosync.show.playground import write_playground  # noqa: E402

SIZE = {"width": 1280, "height": 720, "deviceScaleFactor": 1, "mobile": False}  # a projector


def open_page(browser: Browser, path: Path) -> None:
    browser.open_page(path.resolve().as_uri())
    browser.call("Emulation.setDeviceMetricsOverride", SIZE)


def press(browser: Browser, element_id: str) -> None:
    x, y = browser.evaluate(
        f"(() => {{ const r = document.getElementById('{element_id}').getBoundingClientRect();"
        " return [r.x + r.width / 2, r.y + r.height / 2]; })()"
    )
    for kind in ("mousePressed", "mouseReleased"):
        browser.call("Input.dispatchMouseEvent",
                     {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1})  # fmt: skip


def set_control(browser: Browser, element_id: str, value) -> None:
    prop = "checked" if isinstance(value, bool) else "value"
    browser.evaluate(
        f"(() => {{ const e = document.getElementById('{element_id}');"
        f" e.{prop} = {json.dumps(value)}; e.dispatchEvent(new Event('input')); }})()"
    )


def measure(browser: Browser, folder: Path, n: int, speed: int, seconds: float):
    open_page(browser, write_playground(folder / f"play-{n}-{speed}.html", n=n, sigma_bpm=0.5))
    step_us = browser.evaluate(
        "(() => { const t = performance.now(); window.metrosync.session.advance(2000);"
        " return (performance.now() - t) * 1000 / 2000; })()"
    )
    press(browser, "play")
    set_control(browser, "speed", speed)
    browser.pump(1.0)
    probe = "[window.metrosync.frames, window.metrosync.session.t, performance.now()]"
    f0, t0, w0 = browser.evaluate(probe)
    browser.pump(seconds)
    f1, t1, w1 = browser.evaluate(probe)
    wall = (w1 - w0) / 1000
    return (f1 - f0) / wall, (t1 - t0) / wall, step_us


def lesson(browser: Browser, folder: Path, out: Path) -> None:
    open_page(browser, write_playground(folder / "lesson.html", n=30, sigma_bpm=0.3, seed=4))
    set_control(browser, "hold", True)
    press(browser, "play")
    set_control(browser, "speed", 20)
    while browser.evaluate("window.metrosync.session.t") < 40:
        browser.pump(0.1)
    set_control(browser, "hold", False)
    while browser.evaluate("window.metrosync.session.t") < 95:
        browser.pump(0.1)
    press(browser, "play")  # pause, so that the numbers hold still
    browser.pump(0.5)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(
        browser.screenshot({"x": 0, "y": 0, "width": SIZE["width"], "height": SIZE["height"]})
    )
    print(f"wrote {out} (t = {browser.evaluate('window.metrosync.session.t'):.0f} s, "
          f"r = {browser.evaluate('window.metrosync.r'):.2f})")  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--cases", nargs="+", default=["7x1", "100x1", "100x10", "100x50"],
                        help="NxSPEED")  # fmt: skip
    parser.add_argument("--seconds", type=float, default=5.0, help="wall time counted per case")
    parser.add_argument("--screenshot", type=Path, default=None, metavar="FILE.png")
    args = parser.parse_args()
    chromium = shutil.which("chromium")
    if chromium is None:
        print("needs the Debian package chromium (sudo apt-get install chromium)", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "profile").mkdir()
        with Browser(chromium, folder / "profile", timeout=60) as browser:
            if args.screenshot is not None:
                lesson(browser, folder, args.screenshot)
                return 0
            print(f"{'N':>4} {'speed':>6} {'frames/s':>9} {'simulated':>10} {'us/step':>8}   "
                  f"({time.strftime('%Y-%m-%d')}, headless Chromium)")  # fmt: skip
            for case in args.cases:
                n, speed = (int(x) for x in case.lower().split("x"))
                fps, achieved, step_us = measure(browser, folder, n, speed, args.seconds)
                print(f"{n:>4} {speed:>5}x {fps:>9.1f} {achieved:>9.1f}x {step_us:>8.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

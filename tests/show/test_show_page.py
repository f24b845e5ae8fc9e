"""The playback page: self-contained, faithful data, and it plays in a real browser."""

from __future__ import annotations

import json
import os
import re
import time

import numpy as np
import pytest

from metrosync.errors import ParameterError
from metrosync.show.page import page_data, write_page
from metrosync.show.recording import RecordedRun


def embedded_data(text: str) -> dict:
    match = re.search(r'<script type="application/json" id="run-data">(.*?)</script>', text, re.S)
    return json.loads(match.group(1))


def test_page_is_self_contained(recorded_ds, tmp_path):
    text = write_page(recorded_ds, tmp_path / "run.html").read_text(encoding="utf-8")
    assert not re.search(r"(src|href)\s*=", text)  # nothing to fetch
    assert "http://" not in text and "https://" not in text
    assert "fetch(" not in text and "XMLHttpRequest" not in text
    for element in (
        'id="play"',
        'id="seek"',
        'id="speed"',
        'id="disk"',
        'id="wheel"',
        'id="order"',
    ):
        assert element in text


def test_embedded_data_is_the_recorded_run(recorded_ds):
    run = RecordedRun.from_dataset(recorded_ds)
    data = page_data(run, start=2.0, end=8.0, max_rate=20.0)
    assert data["dt"] == pytest.approx(0.05)  # every step is 0.01 s; thinned to 20/s
    assert data["t0"] <= 2.0 and data["t0"] + (data["count"] - 1) * data["dt"] >= 8.0 - 1e-9
    index = np.round((data["t0"] + data["dt"] * np.arange(data["count"])) / 0.01).astype(int)
    np.testing.assert_allclose(np.array(data["theta"]).T, run.theta[index], atol=5e-6)
    np.testing.assert_allclose(data["phi"], run.phi[index], atol=5e-6)
    np.testing.assert_allclose(data["r"], run.r[index], atol=5e-5)


def test_script_closing_tags_in_text_cannot_break_the_page(recorded_ds, tmp_path):
    ds = recorded_ds.copy()
    ds.attrs["bpm"] = "</script><b>"
    text = write_page(ds, tmp_path / "odd.html").read_text(encoding="utf-8")
    assert text.count("</script>") == 2
    assert embedded_data(text)["title"].startswith("N = 7, </script><b> BPM")


def test_bad_max_rate_is_refused(recorded_ds):
    with pytest.raises(ParameterError, match="`max_rate`"):
        page_data(RecordedRun.from_dataset(recorded_ds), max_rate=0)


# -- end to end, in headless Chromium ------------------------------------------------


def wait_for_frames(browser, count: int, *, later_than: float | None = None) -> float:
    """Wait until the page has drawn ``count`` more frames (and, if given, shows a
    simulated time later than ``later_than``); return the time it shows."""
    start = browser.evaluate("window.metrosyncFrame || 0")
    deadline = time.monotonic() + 30
    while True:
        frame, shown = browser.evaluate("[window.metrosyncFrame || 0, window.metrosyncTime]")
        if frame >= start + count and (later_than is None or shown > later_than):
            return shown
        assert time.monotonic() < deadline, f"the page drew {frame - start} frames in 30 s"
        browser.pump(0.02)


def test_page_plays_in_headless_chromium(recorded_ds, tmp_path, browser):
    path = write_page(recorded_ds, tmp_path / "run.html")
    browser.open_page(path.resolve().as_uri())
    rect = browser.evaluate(
        "(() => { const r = document.getElementById('disk').getBoundingClientRect();"
        " return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
    )

    def shot_at(seconds: float) -> bytes:
        """Seek (paused) to ``seconds``; a screenshot once the page has drawn it."""
        browser.evaluate(
            f"(() => {{ const s = document.getElementById('seek'); s.value = {seconds};"
            f" s.dispatchEvent(new Event('input')); }})()"
        )
        deadline = time.monotonic() + 30
        while browser.evaluate("window.metrosyncTime") != seconds:
            assert time.monotonic() < deadline
            browser.pump(0.02)
        wait_for_frames(browser, 2)
        return browser.screenshot(rect)

    paused_at = wait_for_frames(browser, 2)
    before = browser.screenshot(rect)
    assert wait_for_frames(browser, 3) == paused_at  # paused: the time shown stays
    assert browser.screenshot(rect) == before  # and nothing moves by itself
    at_2, at_4, again_2 = shot_at(2.0), shot_at(4.0), shot_at(2.0)
    assert at_2 != at_4  # another time, another picture
    assert at_2 == again_2  # the same time, the same picture
    browser.evaluate("document.getElementById('play').click()")
    assert browser.evaluate("document.getElementById('play').textContent") == "Pause"
    playing = wait_for_frames(browser, 2, later_than=2.0)
    assert wait_for_frames(browser, 2, later_than=playing) > playing  # time runs on
    assert float(browser.evaluate("document.getElementById('seek').value")) > 2.0
    browser.pump(0.1)
    assert browser.console_errors() == []
    # The check can fail: an error logged by the page is seen.
    browser.evaluate("console.error('probe')")
    browser.pump(0.1)
    assert browser.console_errors() == ["probe"]


def test_browser_processes_are_gone_after_close(chromium_executable, tmp_path):
    from cdp import Browser

    profile = tmp_path / "profile"
    profile.mkdir()
    b = Browser(chromium_executable, profile)
    b.call("Browser.getVersion", session=False)
    group = b.process.pid
    assert living_members(group)
    b.close()
    deadline = time.monotonic() + 10
    while living_members(group) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert living_members(group) == []


def living_members(group: int) -> list[int]:
    """Processes of process group ``group`` that are not zombies (from /proc)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == group and fields[0] != "Z":
            found.append(int(entry))
    return found


# -- a board run ---------------------------------------------------------------------


def colour_pixels(png: bytes, rgb: tuple[int, int, int]) -> int:
    """How many pixels of a screenshot have (nearly) the colour ``rgb``."""
    import io

    from PIL import Image

    shot = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    return int(np.count_nonzero(np.abs(shot - rgb).sum(axis=2) < 12))


WOOD, CAN, DISK = (0xE8, 0xD9, 0xBF), (0xD9, 0xDD, 0xE3), (0xEE, 0xEE, 0xEE)  # the drawings'


def test_a_board_run_sends_its_platform_and_mean_motion(board_ds, recorded_ds):
    run = RecordedRun.from_dataset(board_ds)
    data = page_data(run)
    assert run.platform == data["platform"] == "board"
    a, b = data["phi_trend"]
    # The board about its mean motion: what is left has no drift and mean 0.
    left = run.phi - (a + b * run.time)
    assert abs(left.mean()) < 1e-12 and abs(np.polyfit(run.time, left, 1)[0]) < 1e-12
    disk = page_data(RecordedRun.from_dataset(recorded_ds))
    assert disk["platform"] == "disk" and disk["phi_trend"] is None


def test_a_board_run_plays_as_a_board(board_ds, recorded_ds, tmp_path, browser):
    """The board from the side on two cans, moving; a disk run still shows its disk."""
    shots = {}
    for name, ds in (("board", board_ds), ("disk", recorded_ds)):
        path = write_page(ds, tmp_path / f"{name}.html")
        browser.open_page(path.resolve().as_uri())
        rect = browser.evaluate(
            "(() => { const r = document.getElementById('disk').getBoundingClientRect();"
            " return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
        )
        pictures = []
        for seconds in (2.0, 4.0):
            browser.evaluate(
                f"(() => {{ const s = document.getElementById('seek'); s.value = {seconds};"
                f" s.dispatchEvent(new Event('input')); }})()"
            )
            wait_for_frames(browser, 2)
            assert browser.evaluate("window.metrosyncTime") == seconds
            pictures.append(browser.screenshot(rect))
        shots[name] = pictures
        readout = browser.evaluate("document.getElementById('readout').textContent")
        assert (" cm" in readout) == (name == "board") and ("rad" in readout) == (name == "disk")
        assert browser.console_errors() == []
    board, disk = shots["board"][0], shots["disk"][0]
    assert colour_pixels(board, WOOD) > 300 and colour_pixels(board, CAN) > 300
    assert colour_pixels(board, DISK) < 1000 < colour_pixels(disk, DISK)  # edges aside
    assert colour_pixels(disk, WOOD) == 0
    assert shots["board"][0] != shots["board"][1]  # the pendulums swing

"""The playground: a self-contained page whose JavaScript physics is the package's.

The browser tests open the page from file:// with the network switched off through
the DevTools Network domain, and check that the page asks for nothing but itself.
"""

from __future__ import annotations

import json
import math
import re
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import metrosync
from metrosync.capabilities import FEATURES, UnsupportedFeature, features_on, runs
from metrosync.cli import main
from metrosync.errors import ParameterError
from metrosync.model import PRESETS, get_preset
from metrosync.show.playground import SCRIPTS, playground_config, write_playground

MODEL_FEATURES = [name for name, f in FEATURES.items() if f.kind == "model"]
ASSETS = Path(metrosync.show.playground.__file__).parent / "_playground"


def embedded_config(text: str) -> dict:
    match = re.search(r'<script type="application/json" id="config">(.*?)</script>', text, re.S)
    return json.loads(match.group(1))


# -- the file ------------------------------------------------------------------------


def test_page_is_self_contained(tmp_path):
    text = write_playground(tmp_path / "play.html").read_text(encoding="utf-8")
    assert not re.search(r"(src|href)\s*=", text)  # nothing to fetch
    for loader in ("http://", "https://", "fetch(", "XMLHttpRequest", "WebSocket", "EventSource",
                   "sendBeacon", "import(", "<link", "url(", "<iframe", "<img"):  # fmt: skip
        assert loader not in text, loader
    assert text.count("<script") == 2 and "@SCRIPT@" not in text and "@CONFIG@" not in text
    for control in ("play", "restart", "mute", "speed", "preset", "n", "bpm", "sigma", "groups",
                    "offset", "drive", "hold", "inertia", "jlaw", "cphi"):  # fmt: skip
        assert f'id="{control}"' in text, control
    for view in ("disk", "wheel", "side", "order"):
        assert f'<canvas id="{view}"' in text


def test_constants_come_from_the_package():
    config = playground_config()
    for name, params in PRESETS.items():
        sent = config["presets"][name]
        constants = {**vars(params.metronome), **vars(params.platform)}
        constants["l2_bounds"] = list(constants["l2_bounds"])
        # A steady-swing preset (pantaleone2002) also sends its spline, which the
        # steady-swing test below checks.
        sent_constants = {k: v for k, v in sent["constants"].items() if k != "steady_swing"}
        assert sent_constants == constants
        assert ("steady_swing" in sent["constants"]) == (params.metronome.tuning == "steady-swing")
        assert sent["bpm_range"] == list(params.metronome.bpm_range())
    assert config["dt"] == 0.01 and config["overturn_angle"] == math.pi / 2
    # ... and none of them is typed into the scripts.
    scripts = "\n".join((ASSETS / name).read_text(encoding="utf-8") for name in SCRIPTS)
    default = PRESETS["default"]
    for value in {**vars(default.metronome), **vars(default.platform)}.values():
        if isinstance(value, float) and value not in (0.0, 0.5, 1.0, 2.0):
            for text in {repr(value), f"{value:g}", f"{value:.4g}"}:
                assert not re.search(rf"(?<![\w.]){re.escape(text)}(?![\w])", scripts), text


def test_start_settings_and_changes():
    config = playground_config(n=12, bpm=180.0, sigma_bpm=1.5, seed=5,
                               changes={"drive": 1e-4, "inertia": math.inf})  # fmt: skip
    start = config["start"]
    assert start == {"preset": "default+changes", "n": 12, "bpm": 180.0, "sigma_bpm": 1.5,
                     "seed": 5, "hold": True}  # fmt: skip
    custom = config["presets"]["default+changes"]
    assert custom["constants"]["drive"] == 1e-4 and custom["constants"]["inertia"] is None
    assert set(config["presets"]) == {*PRESETS, "default+changes"}


def test_script_closing_tags_in_a_description_cannot_break_the_page(tmp_path):
    odd = replace(PRESETS["default"], name="odd", description="</script><b>")
    text = write_playground(tmp_path / "odd.html", preset=odd).read_text(encoding="utf-8")
    assert text.count("</script>") == 2
    assert embedded_config(text)["presets"]["odd"]["description"] == "</script><b>"


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"n": 0}, "`n` must be a whole number of metronomes in [1, 100], got 0"),
        ({"n": 101}, "got 101"),
        ({"n": 7.5}, "got 7.5"),
        ({"bpm": 300.0}, "`bpm` = 300.0 is outside the tunable range"),
        ({"bpm": math.nan}, "`bpm` = nan"),
        ({"sigma_bpm": -1.0}, "`sigma_bpm` = -1.0 is outside the page's range [0, 10]"),
        ({"sigma_bpm": 11.0}, "`sigma_bpm` = 11.0"),
        ({"dt": 0.2}, "`dt` = 0.2 s is outside [0.001,"),
        ({"dt": 1e-4}, "`dt` = 0.0001 s"),
        ({"seed": -1}, "`seed` must be an integer in [0, 2**32), got -1"),
        ({"preset": "nope"}, "unknown preset 'nope'"),
        ({"changes": {"drive": 1.0}}, "`drive` = 1.0 is outside the playground's slider range"),
        ({"changes": {"inertia": 1e6}}, "`inertia` = 1000000.0"),
        ({"changes": {"w2": 0.0}}, "`w2` = 0"),
        ({"changes": {"spin": 1.0}}, "unknown model parameter(s) ['spin']"),
        # The board's parameters have slider ranges too; the disk's are not the board's.
        (
            {"preset": "pantaleone2002", "changes": {"board_mass": 1e3}},
            "`board_mass` = 1000.0 is outside the playground's slider range [0.001, 100];",
        ),
        (
            {"preset": "pantaleone2002", "changes": {"board_damping": 1e3}},
            "`board_damping` = 1000.0 is outside the playground's slider range [0.0001, 100] (or",
        ),
        (
            {"preset": "pantaleone2002", "changes": {"c_phi": 1e-4}},
            "`c_phi` = 0.0001 is a parameter of the disk, but `platform` is 'board'",
        ),
        ({"changes": {"board_mass": 0.5}}, "`board_mass` = 0.5 is a parameter of the board"),
        # A wet table's damping needs a finer step than the page's default.
        (
            {"preset": "pantaleone2002", "changes": {"board_damping": 100.0}, "n": 2, "bpm": 208.0},
            "`board_damping` = 100.0 kg/s damps the board at 416 /s, too fast for the step `dt` "
            "= 0.01 s (the page's step needs rate x dt <= 1, or it diverges): lower it to at "
            "most 24 kg/s, or give `dt` <= 0.0024 s.",
        ),
    ],
)
def test_bad_starting_points_are_refused(options, message):
    with pytest.raises(ParameterError) as error:
        playground_config(**options)
    assert message in str(error.value)


def test_a_wet_table_runs_at_the_step_it_needs():
    """The damping check's advice works: at dt = 0.001 s the wet table is accepted, and
    its rate is the one the message gave."""
    from metrosync.show.playground import damping_rate

    wet = {"board_damping": 100.0}
    config = playground_config(preset="pantaleone2002", changes=wet, n=2, bpm=208.0, dt=0.001)
    assert config["max_damping_per_step"] == 1.0
    params = PRESETS["pantaleone2002"].with_changes(**wet)
    assert damping_rate(params, 2, 208.0) == pytest.approx(416.3, abs=0.1)


def test_an_overturning_preset_warns():
    with pytest.warns(metrosync.OverturnWarning, match="boda2013"):
        playground_config(preset="boda2013")


# -- the command ---------------------------------------------------------------------


def test_cli_writes_the_page(tmp_path, capsys):
    out = tmp_path / "sub" / "play.html"
    assert main(["playground", "--n", "20", "--sigma", "0.5", "--set", "c_phi=2e-5",
                 "--out", str(out)]) == 0  # fmt: skip
    assert "open it in a browser" in capsys.readouterr().out
    config = embedded_config(out.read_text(encoding="utf-8"))
    assert config["start"]["n"] == 20 and config["start"]["sigma_bpm"] == 0.5
    assert config["presets"]["default+changes"]["constants"]["c_phi"] == 2e-5


def test_cli_writes_a_board_page(tmp_path):
    out = tmp_path / "board.html"
    assert main(["playground", "--platform", "board", "--n", "2", "--out", str(out)]) == 0
    config = embedded_config(out.read_text(encoding="utf-8"))
    assert config["presets"]["default+changes"]["constants"]["platform"] == "board"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--out", "play.txt"], "`--out` 'play.txt' must end in .html, .htm"),
        (["--out", "{tmp}"], "is a directory"),
        (["--n", "0"], "`n` must be a whole number"),
        (["--sigma", "-2"], "`sigma_bpm` (--sigma) = -2.0"),
        (["--bpm", "500"], "`bpm` = 500.0"),
        (["--set", "drive"], "`--set` expects NAME=VALUE"),
        (["--platform", "board", "--set", "c_phi=1e-4"], "`c_phi` = 0.0001 is a parameter of"),
    ],
)
def test_cli_errors_name_the_option(tmp_path, capsys, argv, message):
    argv = [a.format(tmp=tmp_path) for a in argv]
    if "--out" not in argv:
        argv += ["--out", str(tmp_path / "x.html")]
    assert main(["playground", *argv]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x.html").exists()


# -- in headless Chromium, offline ---------------------------------------------------


def open_offline(browser, path: Path) -> str:
    """Open ``path`` from file:// with the network off; returns its URL."""
    url = path.resolve().as_uri()
    target = browser.call("Target.createTarget", {"url": "about:blank"}, session=False)
    browser.session = browser.call(
        "Target.attachToTarget", {"targetId": target["targetId"], "flatten": True}, session=False
    )["sessionId"]
    for domain in ("Runtime", "Log", "Page", "Network"):
        browser.call(f"{domain}.enable")
    browser.call("Network.emulateNetworkConditions", {
        "offline": True, "latency": 0, "downloadThroughput": -1, "uploadThroughput": -1,
    })  # fmt: skip
    browser.call("Emulation.setDeviceMetricsOverride", {
        "width": 1340, "height": 720, "deviceScaleFactor": 1, "mobile": False,
    })  # fmt: skip
    browser.call("Page.navigate", {"url": url})
    deadline = time.monotonic() + 30
    while browser.evaluate("document.readyState") != "complete":
        assert time.monotonic() < deadline, "the page did not load"
        time.sleep(0.05)
    return url


def requested(browser) -> list[str]:
    return [e["params"]["request"]["url"] for e in browser.events
            if e.get("method") == "Network.requestWillBeSent"]  # fmt: skip


def click(browser, element_id: str) -> None:
    """A real mouse click (a user gesture, which audio needs)."""
    x, y = browser.evaluate(
        f"(() => {{ const r = document.getElementById('{element_id}').getBoundingClientRect();"
        " return [r.x + r.width / 2, r.y + r.height / 2]; })()"
    )
    for kind in ("mousePressed", "mouseReleased"):
        browser.call("Input.dispatchMouseEvent",
                     {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1})  # fmt: skip


def set_control(browser, element_id: str, value) -> None:
    """Move a slider (or tick a box) as a user would: the page hears an input event."""
    prop = "checked" if isinstance(value, bool) else "value"
    browser.evaluate(
        f"(() => {{ const e = document.getElementById('{element_id}');"
        f" e.{prop} = {json.dumps(value)}; e.dispatchEvent(new Event('input')); }})()"
    )


def wait_for(browser, expression: str, timeout: float = 60.0):
    deadline = time.monotonic() + timeout
    while not browser.evaluate(expression):
        assert time.monotonic() < deadline, f"timed out waiting for {expression}"
        browser.pump(0.2)


def canvas_rect(browser, element_id: str) -> dict:
    return browser.evaluate(
        f"(() => {{ const r = document.getElementById('{element_id}').getBoundingClientRect();"
        " return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
    )


CASES = {
    # Nine metronomes with spread, a changed drive and disk friction, the disk free.
    "free": dict(
        frequencies_bpm=[190.0, 192.5, 193.1, 188.7, 195.0, 191.2, 192.0, 189.9, 194.4],
        theta0=[0.3, -0.5, 0.7, 0.1, -0.2, 0.0, 0.6, -0.7, 0.25],
        theta_dot0=[0.0, 1.0, -2.0, 3.0, 0.5, -4.0, 0.0, 1.5, -1.0],
        changes={"drive": 8e-5, "c_phi": 2e-5},
    ),
    # Five on a held disk (J = ∞).
    "held": dict(
        frequencies_bpm=[180.0, 200.0, 192.0, 186.0, 210.0],
        theta0=[0.5, -0.4, 0.0, 0.2, -0.6],
        theta_dot0=[1.0, 0.0, 3.0, -2.0, 0.0],
        hold=True,
    ),
    # The same nine on the board (the page's own preset switched by `changes`), damped.
    "board": dict(
        frequencies_bpm=[190.0, 192.5, 193.1, 188.7, 195.0, 191.2, 192.0, 189.9, 194.4],
        theta0=[0.3, -0.5, 0.7, 0.1, -0.2, 0.0, 0.6, -0.7, 0.25],
        theta_dot0=[0.0, 1.0, -2.0, 3.0, 0.5, -4.0, 0.0, 1.5, -1.0],
        changes={"platform": "board", "drive": 8e-5, "board_damping": 0.05},
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_browser_physics_is_the_numpy_reference(browser, tmp_path, case):
    """10 000 steps in the browser against `simulate(..., backend="numpy")`: 1e-9."""
    params = CASES[case]
    open_offline(browser, write_playground(tmp_path / "play.html"))
    out = browser.evaluate(f"window.metrosync.run({json.dumps(params)}, 10000)")
    changes = dict(params.get("changes", {}))
    if params.get("hold"):
        changes["inertia"] = math.inf
    ds = metrosync.simulate(
        None, None, frequencies_bpm=params["frequencies_bpm"], theta0=params["theta0"],
        theta_dot0=params["theta_dot0"], duration=100.0, dt=0.01, record_every=1,
        trajectories=True, backend="numpy", changes=changes or None,
    ).isel(run=0)  # fmt: skip
    assert len(out["theta"]) == ds.sizes["time"] == 10001
    for name in ("theta", "theta_dot", "phi", "phi_dot", "r"):
        np.testing.assert_allclose(np.array(out[name]), ds[name].values, rtol=0, atol=1e-9,
                                   err_msg=name)  # fmt: skip


def test_the_page_tunes_by_the_steady_swing_as_the_package_does(browser, tmp_path):
    """L2 from a BPM under ``tuning="steady-swing"``: the page's inversion of the
    package's spline against `l2_for_bpm`, over the tunable range."""
    from metrosync.model.tuning import l2_for_bpm

    config = playground_config(changes={"tuning": "steady-swing"}, bpm=180.0)
    design = PRESETS["default"].metronome
    low, high = config["presets"]["default+changes"]["bpm_range"]
    bpms = np.linspace(low, high, 41)
    page = write_playground(tmp_path / "play.html", changes={"tuning": "steady-swing"}, bpm=180.0)
    open_offline(browser, page)
    got = browser.evaluate(
        "(() => { const c = window.metrosync.config.presets['default+changes'].constants;"
        f" return {json.dumps(bpms.tolist())}.map((b) => Physics.l2ForBpm(c, b)); }})()"
    )
    expected = l2_for_bpm(design, bpms, tuning="steady-swing")
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)


#: Every model feature of the capability table, and all of them together; the dry
#: friction also strong enough to hold the disk between kicks. The board is the other
#: platform, so "all" is every feature on the disk, and "board-all" every feature the
#: board has (the disk's friction and reaction switch are not the board's).
FEATURE_CASES = {name: dict(f.example) for name, f in FEATURES.items() if f.kind == "model"}
FEATURE_CASES["dry-friction-held"] = {"disk_dry_friction": 2e-2}
FEATURE_CASES["all"] = {
    k: v for name in MODEL_FEATURES if name != "board" for k, v in FEATURES[name].example.items()
}
FEATURE_CASES["board-all"] = {
    "platform": "board", "forcing_amplitude": 0.02, "forcing_bpm": 189.0,
    "escapement_offset": 0.07, "board_dry_friction": 0.02, "tuning": "steady-swing",
}  # fmt: skip
#: The disk's friction c_φ is not the board's: on the board the base changes damp it.
BOARD_BASE = {"drive": 8e-5, "board_damping": 0.05}
DRY = {"disk_dry_friction", "board_dry_friction"}


def compare_with_numpy(browser, params: dict, **simulate_options):
    """The open page's ``run(params, 10000)`` against `simulate(..., backend="numpy")`
    with the same start: every trajectory to 1e-9; returns both."""
    out = browser.evaluate(f"window.metrosync.run({json.dumps(params)}, 10000)")
    run = {k: v for k, v in params.items() if k not in ("changes", "preset")}
    ds = metrosync.simulate(
        None, None, **run, duration=100.0, dt=0.01, record_every=1, trajectories=True,
        backend="numpy", **simulate_options,
    ).isel(run=0)  # fmt: skip
    assert out["status"] == int(ds.status) == 0
    for name in ("theta", "theta_dot", "phi", "phi_dot", "r"):
        np.testing.assert_allclose(np.array(out[name]), ds[name].values, rtol=0, atol=1e-9,
                                   err_msg=name)  # fmt: skip
    np.testing.assert_allclose(out["l2"], ds["l2"].values, rtol=0, atol=1e-12)
    assert np.ptp(ds["theta"].values) > 1.0  # it moved: the comparison is not of two constants
    assert np.ptp(ds["phi"].values) > 0  # and so did the platform
    assert requested(browser) == [browser.evaluate("location.href")]
    return out, ds


@pytest.mark.parametrize("case", sorted(FEATURE_CASES))
def test_the_page_runs_each_model_feature_or_refuses_it_by_name(request, tmp_path, case):
    """Each feature of the capability table: refused by name, or the page's physics is
    `simulate(..., backend="numpy")`'s to 1e-9 over 10 000 steps with it on."""
    changes = FEATURE_CASES[case]
    # The features these changes switch on (two features may share a parameter).
    named = [f for f, _ in features_on(get_preset("default").with_changes(**changes))]
    if not all(runs("playground", f.name) for f in named):
        with pytest.raises(UnsupportedFeature) as refused:
            playground_config(changes=changes)
        assert refused.value.feature in {f.name for f in named}
        assert f"`{FEATURES[refused.value.feature].parameters[0]}` = " in str(refused.value)
        assert "the playground has no" in str(refused.value)
        return
    browser = request.getfixturevalue("browser")  # skips, naming the package, without one
    params = {k: v for k, v in CASES["free"].items() if k != "changes"}
    base = BOARD_BASE if changes.get("platform") == "board" else CASES["free"]["changes"]
    page = write_playground(tmp_path / "play.html", changes={**base, **changes})
    open_offline(browser, page)
    # The page says which terms beyond the paper it runs.
    wait_for(browser, "document.getElementById('status').textContent.includes('Beyond the paper')")
    out, _ = compare_with_numpy(browser, params, changes={**base, **changes})
    if DRY & set(changes):
        held = np.count_nonzero(np.array(out["phi_dot"][1:]) == 0.0)  # after the start
        assert held > 0, "the platform never stuck"


#: Pantaleone's board (preset pantaleone2002, its steady-swing tuning) alone and with
#: each feature the board has, then all of them: forcing (N), the escapement's offset,
#: the board's dry friction (strong enough to stick at times) and its damping.
BOARD_CASES = {
    "preset": {},
    "forcing": {"forcing_amplitude": 0.02, "forcing_bpm": 208.0},
    "escapement-offset": {"escapement_offset": 0.07},
    "dry-friction": {"board_dry_friction": 0.02},
    "damped": {"board_damping": 2.0},
}
BOARD_CASES["all"] = {k: v for case in BOARD_CASES.values() for k, v in case.items()}


@pytest.mark.parametrize("case", sorted(BOARD_CASES))
def test_the_board_preset_runs_in_the_page_as_in_numpy(browser, tmp_path, case):
    """Six metronomes on preset pantaleone2002's board: the page's physics is
    `simulate(..., backend="numpy")`'s to 1e-9 over 10 000 steps, the board's constants
    are the model's, and the page says it runs the board."""

    changes = BOARD_CASES[case]
    page = write_playground(tmp_path / "play.html", preset="pantaleone2002", n=2, bpm=208.0,
                            changes=changes or None)  # fmt: skip
    name = "pantaleone2002+changes" if changes else "pantaleone2002"
    params = {
        "preset": name,
        "frequencies_bpm": [206.0, 208.5, 207.1, 209.7, 205.0, 208.0],
        "theta0": [0.3, -0.35, 0.39, 0.1, -0.2, 0.0],
        "theta_dot0": [0.0, 2.0, -1.0, 3.0, 0.5, -4.0],
    }
    open_offline(browser, page)
    out, ds = compare_with_numpy(browser, params, preset="pantaleone2002",
                                 changes=changes or None)  # fmt: skip
    assert ds.attrs["platform"] == "board" and ds.phi.attrs["units"] == "m"
    if DRY & set(changes):
        assert np.count_nonzero(np.array(out["phi_dot"][1:]) == 0.0) > 0, "the board never stuck"
    model = get_preset("pantaleone2002", warn=False).with_changes(**changes).platform.terms(6)
    system = browser.evaluate(
        f"(() => {{ const c = window.metrosync.config.presets[{json.dumps(name)}].constants;"
        " const s = Physics.buildSystem(c, [206, 208, 207, 209, 205, 208], false);"
        " return [s.lever, s.ownInertia, s.cPhi, s.dryFriction, s.reaction]; })()"
    )
    assert system == [model.lever, model.own_inertia, model.damping, model.dry_friction, 0.0]
    status = browser.evaluate("document.getElementById('status').textContent")
    assert "the board on rollers" in status
    assert browser.console_errors() == []


def test_playground_smoke(browser, tmp_path):
    """Load offline, play, the canvas moves, r rises on a free disk and not on a held one."""
    url = open_offline(browser, write_playground(tmp_path / "play.html", n=7, sigma_bpm=0.0))
    disk = canvas_rect(browser, "disk")
    wait_for(browser, "window.metrosync.frames > 5")
    assert browser.screenshot(disk) == browser.screenshot(disk)  # paused: nothing moves
    click(browser, "play")
    assert browser.evaluate("document.getElementById('play').textContent") == "Pause"
    set_control(browser, "speed", 50)
    first = browser.screenshot(disk)
    browser.pump(0.3)
    assert browser.screenshot(disk) != first
    # Identical metronomes on a free disk fall into step.
    r_start = browser.evaluate("window.metrosync.session.history[0][1]")
    wait_for(browser, "window.metrosync.session.t > 90")
    r_free = browser.evaluate("window.metrosync.r")
    assert r_start < 0.7 and r_free > 0.95, (r_start, r_free)
    # Every tick is a click (the audio starts with the press of Play, before any tick).
    ticks, heard = browser.evaluate(
        "[window.metrosync.session.tickCount, window.metrosync.clicks.scheduled]"
    )
    assert ticks > 7 * 2 * 90 and heard == ticks
    set_control(browser, "mute", True)
    heard = browser.evaluate("window.metrosync.clicks.scheduled")
    browser.pump(0.3)
    assert browser.evaluate("window.metrosync.clicks.scheduled") == heard
    set_control(browser, "mute", False)
    # Held, from new random phases: no coupling, so r stays where it starts. (It wobbles
    # as the swings settle from the small-angle start amplitude: in 200 runs of
    # `simulate` with the disk held, by 0.056 at most.)
    set_control(browser, "hold", True)
    click(browser, "restart")
    r_held_start = browser.evaluate("window.metrosync.session.history[0][1]")
    wait_for(browser, "window.metrosync.session.t > 90")
    history = np.array(browser.evaluate("window.metrosync.session.history"))[:, 1]
    assert np.max(np.abs(history - r_held_start)) < 0.1, (r_held_start, history)
    assert r_held_start < 0.9 and history[-1] < 0.95
    numbers = browser.evaluate("document.getElementById('numbers').textContent")
    assert "tick rate" in numbers and "/min" in numbers
    assert browser.console_errors() == []
    assert requested(browser) == [url]
    # The checks can fail: a request or an error made by the page is seen.
    browser.evaluate("fetch('https://example.org/').catch(() => console.error('offline'))")
    browser.pump(0.3)
    assert requested(browser) == [url, "https://example.org/"]
    assert "offline" in browser.console_errors()


def colour_pixels(png: bytes, rgb: tuple[int, int, int]) -> int:
    """How many pixels of a screenshot have (nearly) the colour ``rgb``."""
    import io

    from PIL import Image

    shot = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    return int(np.count_nonzero(np.abs(shot - rgb).sum(axis=2) < 12))


BOARD_WOOD, ROLLER = (0xE8, 0xD9, 0xBF), (0xD9, 0xDD, 0xE3)  # view.js's board and cans


def test_the_board_is_offered_drawn_and_locks(browser, tmp_path):
    """Pantaleone's two metronomes: the page opens on the board with the board's
    controls, draws a board on two rollers that moves, and the pair locks in phase;
    the platform choice switches to the disk and back, the platform starting at rest."""
    page = write_playground(tmp_path / "play.html", preset="pantaleone2002", n=2, bpm=208.0)
    url = open_offline(browser, page)
    session = "window.metrosync.session"
    shown = "(id) => !document.getElementById(id).hidden"
    assert browser.evaluate(f"[document.getElementById('platform').value, {session}.system.lever,"
                            f" ({shown})('board-controls'), ({shown})('disk-controls'),"
                            " document.getElementById('platform-name').textContent]") == [
        "board", 1.0, True, False, "a board on rollers"]  # fmt: skip
    wait_for(browser, "window.metrosync.frames > 5")
    platform = canvas_rect(browser, "disk")
    first = browser.screenshot(platform)
    assert colour_pixels(first, BOARD_WOOD) > 500 and colour_pixels(first, ROLLER) > 200
    click(browser, "play")
    set_control(browser, "speed", 50)
    browser.pump(0.3)
    assert browser.screenshot(platform) != first
    wait_for(browser, f"{session}.t > 120")
    # In phase (Pantaleone's Fig. 2), and the board moved.
    assert browser.evaluate("window.metrosync.r") > 0.95
    assert browser.evaluate(f"{session}.boardCentre") is not None
    click(browser, "play")  # pause
    set_control(browser, "boarddamping", 800)
    set_control(browser, "boardmass", 500)
    damping, mass = browser.evaluate(f"[{session}.system.cPhi, {session}.settings.boardMass]")
    assert 1.0 < damping < 100.0 and 0.1 < mass < 1.0  # log sliders over their LIMITS
    # A damping the page's step cannot follow is said, with the fix, as the start's is.
    set_control(browser, "boarddamping", 1000)
    status = "document.getElementById('status').textContent"
    wait_for(browser, f"{status}.includes('too fast for the step 0.01 s')")
    assert "The board's damping 1.0e+2 damps it at" in browser.evaluate(status)
    set_control(browser, "boarddamping", 800)
    wait_for(browser, f"!{status}.includes('too fast')")
    own = browser.evaluate(f"{session}.system.ownInertia")
    assert own == pytest.approx(mass + 2 * PRESETS["pantaleone2002"].platform.box_mass, rel=1e-12)
    set_control(browser, "platform", "disk")
    disk = PRESETS["pantaleone2002"].platform.radius
    assert browser.evaluate(f"[{session}.system.lever, {session}.state.phi, {session}.state.phiDot,"
                            f" ({shown})('disk-controls'), ({shown})('board-controls')]") == [
        disk, 0.0, 0.0, True, False]  # fmt: skip
    set_control(browser, "platform", "board")
    assert browser.evaluate(f"{session}.markers.map((m) => m[1])")[-2:] == ["disk", "board"]
    assert browser.evaluate(f"{session}.system.lever") == 1.0
    assert browser.console_errors() == []
    assert requested(browser) == [url]
    (tmp_path / "board.png").write_bytes(browser.screenshot(platform))


def test_controls_take_effect_and_continue_from_the_state(browser, tmp_path):
    open_offline(browser, write_playground(tmp_path / "play.html", n=5, seed=3))
    before = browser.evaluate("Array.from(window.metrosync.session.state.theta)")
    set_control(browser, "n", 8)
    session = "window.metrosync.session"
    assert browser.evaluate(f"{session}.state.n") == 8
    assert browser.evaluate(f"Array.from({session}.state.theta).slice(0, 5)") == before
    set_control(browser, "sigma", 2.0)
    spread = browser.evaluate(f"{session}.naturalSpread()")
    assert 0.5 < spread < 5.0
    set_control(browser, "groups", True)
    set_control(browser, "offset", 10)
    freqs = browser.evaluate(f"Array.from({session}.system.omega, (w) => 60 * w / Math.PI)")
    assert np.mean(freqs[1::2]) - np.mean(freqs[0::2]) > 6.0
    set_control(browser, "hold", True)
    assert browser.evaluate(f"{session}.system.totalInertia") is None  # Infinity -> null in JSON
    assert browser.evaluate(f"{session}.markers.map((m) => m[1])") == [
        "N=8", "σ=2.00", "2 groups", "Δ=10.0", "held"]  # fmt: skip
    assert browser.console_errors() == []


def viewport_shot(browser, width: int, height: int, path: Path):
    """Set the window to ``width`` × ``height``, let the page draw, save a screenshot of
    what shows; returns it as an RGB array (height, width, 3)."""
    import io

    from PIL import Image

    browser.call("Emulation.setDeviceMetricsOverride", {
        "width": width, "height": height, "deviceScaleFactor": 1, "mobile": False,
    })  # fmt: skip
    frames = browser.evaluate("window.metrosync.frames")
    wait_for(browser, f"window.metrosync.frames > {frames + 3}")
    png = browser.screenshot()
    path.write_bytes(png)
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def inside(rect: dict, width: int, height: int) -> bool:
    return (rect["x"] >= 0 and rect["y"] >= 0 and rect["x"] + rect["width"] <= width
            and rect["y"] + rect["height"] <= height)  # fmt: skip


@pytest.mark.parametrize(("width", "height"), [(1280, 720), (1920, 1080)])
def test_disk_r_and_its_chart_show_together_on_one_screen(browser, tmp_path, width, height):
    """A projector's 1280 × 720 and a 1920 × 1080 screen: the disk, the r readout and
    the r(t) chart are all inside the window, unscrolled, and drawn at the size they
    show at; the explanation is one click away."""
    open_offline(browser, write_playground(tmp_path / "play.html", n=7, sigma_bpm=0.0))
    click(browser, "play")
    set_control(browser, "speed", 50)
    wait_for(browser, "window.metrosync.session.t > 45")
    click(browser, "play")  # pause, so that the screenshot and the numbers agree
    set_control(browser, "speed", 1)  # the chart then spans the last 60 s
    shot = viewport_shot(browser, width, height, tmp_path / f"playground-{width}x{height}.png")
    assert shot.shape == (height, width, 3)
    assert browser.evaluate("[window.scrollX, window.scrollY]") == [0, 0]
    rects = {name: canvas_rect(browser, name) for name in ("disk", "r-value", "order", "wheel")}
    for name, rect in rects.items():
        assert inside(rect, width, height), (name, rect, (width, height))
    assert min(rects["disk"]["width"], rects["disk"]["height"]) >= 0.55 * height
    assert rects["order"]["width"] >= 0.3 * width and rects["order"]["height"] >= 0.3 * height
    # The canvas draws at the size it shows at: the r(t) curve (its colour, #1f77b4)
    # spans most of the chart's width in the screenshot.
    o = {k: round(v) for k, v in rects["order"].items()}
    chart = shot[o["y"] : o["y"] + o["height"], o["x"] : o["x"] + o["width"]].astype(int)
    curve = np.abs(chart - [0x1F, 0x77, 0xB4]).sum(axis=2) < 60
    columns = np.flatnonzero(curve.any(axis=0))
    assert columns.size and columns[-1] - columns[0] > 0.5 * o["width"], columns
    r_shown = float(browser.evaluate("document.getElementById('r-value').textContent"))
    assert r_shown == pytest.approx(browser.evaluate("window.metrosync.r"), abs=5e-4)
    # The explanation: hidden, then shown (and on screen) after one click.
    note = "document.querySelector('#about .note')"
    assert not browser.evaluate(f"{note}.checkVisibility()")
    click(browser, "about-toggle")
    assert browser.evaluate(f"{note}.checkVisibility()")
    about = browser.evaluate(
        f"(() => {{ const r = {note}.getBoundingClientRect();"
        " return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
    )
    assert inside(about, width, height) and "phase wheel" in browser.evaluate(f"{note}.textContent")
    assert browser.console_errors() == []


def test_locked_metronomes_tick_at_one_rate(browser, tmp_path):
    """σ = 0.5 BPM, N = 7: once locked, the measured tick rates agree far better than
    the natural frequencies do; on a held disk they keep their spread."""
    open_offline(browser, write_playground(tmp_path / "play.html", n=7, sigma_bpm=0.5, seed=1))
    session = "window.metrosync.session"
    spreads = {}
    for held in (False, True):
        set_control(browser, "hold", held)
        browser.evaluate(f"{session}.restart(7)")
        browser.evaluate(f"{session}.advance(20000)")  # 200 s
        rates = browser.evaluate(f"{session}.tickRates()")
        assert rates["count"] == 7 and 170 < rates["mean"] < 200
        spreads[held] = rates["spread"] / browser.evaluate(f"{session}.naturalSpread()")
    assert spreads[False] < 0.5 and spreads[True] > 0.7, spreads


def test_frame_rate_with_100_metronomes_at_10x(browser, tmp_path, record_property, capsys):
    """The page's own frame counter at N = 100, 10× real time (a figure, not a pass/fail)."""
    open_offline(browser, write_playground(tmp_path / "play.html", n=100, sigma_bpm=0.5))
    click(browser, "play")
    set_control(browser, "speed", 10)
    browser.pump(1.0)
    frames0, t0, wall0 = browser.evaluate(
        "[window.metrosync.frames, window.metrosync.session.t, performance.now()]"
    )
    browser.pump(4.0)
    frames1, t1, wall1 = browser.evaluate(
        "[window.metrosync.frames, window.metrosync.session.t, performance.now()]"
    )
    seconds = (wall1 - wall0) / 1000
    fps, speed = (frames1 - frames0) / seconds, (t1 - t0) / seconds
    record_property("playground_fps_n100_10x", fps)
    with capsys.disabled():
        print(f"\nplayground, N = 100 at 10x: {fps:.1f} frames/s, simulated {speed:.1f}x real time")
    assert frames1 > frames0 and t1 > t0
    assert browser.console_errors() == []


def test_every_asset_ships_in_the_wheel():
    """The page is assembled from package data: pyproject must list every file."""
    import fnmatch
    import tomllib

    root = Path(__file__).parents[2]
    if not (root / "pyproject.toml").is_file():
        pytest.skip("runs from a source checkout")
    setup = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["tool"]
    globs = setup["setuptools"]["package-data"]["metrosync.show"]
    files = [f"_playground/{p.name}" for p in ASSETS.iterdir() if p.is_file()]
    assert {*SCRIPTS, "page.html"} <= {p.name for p in ASSETS.iterdir()}
    for name in files:
        assert any(fnmatch.fnmatch(name, g) for g in globs), name


# -- what the classroom page's "In the classroom" promises, in the model the page runs --------


def test_raising_sigma_breaks_the_synchrony():
    """N = 7 at 192 BPM: r_eq ≈ 0.95 at σ = 0.5 BPM, below 0.6 at σ = 2 BPM."""
    runs = {s: metrosync.simulate(7, 192.0, sigma_bpm=s, runs=20, duration=300.0, seed=1)
            for s in (0.5, 2.0)}  # fmt: skip
    r_eq = {s: float(ds.r_eq.mean()) for s, ds in runs.items()}
    assert r_eq[0.5] > 0.9 and r_eq[2.0] < 0.6, r_eq


@pytest.mark.parametrize(("offset", "together"), [(1.0, True), (8.0, False)])
def test_two_groups_lock_within_and_together_only_when_close(offset, together):
    """Every other metronome `offset` BPM higher (the page's "2 groups"): each group
    falls into step; the two lock together at 1 BPM apart but not at 8."""
    freqs = 192.0 + offset * (np.arange(10) % 2)
    ds = metrosync.simulate(None, None, frequencies_bpm=freqs, duration=300.0, seed=2,
                            record_every=10, trajectories=True).isel(run=0)  # fmt: skip
    last = slice(-500, None)  # the final 50 s
    theta, theta_dot = ds.theta.values[last], ds.theta_dot.values[last]
    unit = np.exp(1j * np.arctan2(-theta_dot / (np.pi * freqs / 60), theta))
    within = [np.abs(unit[:, g::2].mean(axis=1)).min() for g in (0, 1)]
    overall = np.abs(unit.mean(axis=1))
    assert min(within) > 0.98, within
    if together:
        assert overall.min() > 0.9
    else:  # the groups drift past each other: r swings between them
        assert overall.min() < 0.3 and overall.max() > 0.9

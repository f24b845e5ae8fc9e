"""The documentation site, built once for this module as `make docs` builds it: no
warning, every gallery example runs and shows its figure, every public name has its
entry in the API reference, and every page opens in headless Chromium without a
console error and with nothing fetched from outside the site.

The build runs on a copy of docs/ and examples/, so the checkout stays clean. It needs
the `docs` extra (`make test` installs it); without it the tests skip and say so.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

import metrosync
from system_packages import require

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))
DOCS_TOOLS = ("sphinx", "myst_parser", "sphinx_gallery", "pydata_sphinx_theme")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    missing = [name for name in DOCS_TOOLS if importlib.util.find_spec(name) is None]
    if missing:
        pytest.skip(f"needs the docs extra ({', '.join(missing)} missing): "
                    "`pip install -e '.[docs]'`, which `make test` does")  # fmt: skip
    work = tmp_path_factory.mktemp("site")
    shutil.copytree(
        ROOT / "docs",
        work / "docs",
        ignore=shutil.ignore_patterns("_build", "gallery", "sg_execution_times.rst"),
    )
    shutil.copytree(ROOT / "examples", work / "examples")
    shutil.copy(ROOT / "CHANGELOG.md", work / "CHANGELOG.md")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "MPLBACKEND": "Agg"}
    started = time.monotonic()
    built = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(work / "doctrees"), str(work / "docs"), str(work / "html")],
        capture_output=True, text=True, env=env, timeout=900,
    )  # fmt: skip
    return {"html": work / "html", "src": work / "docs", "result": built,
            "seconds": time.monotonic() - started}  # fmt: skip


def test_the_site_builds_with_no_warning(site):
    built = site["result"]
    assert built.returncode == 0, built.stderr[-4000:]
    # A cold kernel cache says that it compiles them, once: a notice, not a warning.
    said = [line for line in built.stderr.splitlines() if line.strip()]
    assert not [line for line in said if "compiling kernels, once" not in line], built.stderr


def test_the_gallery_has_at_least_twelve_questions_each_run_with_its_figure(site):
    assert len(EXAMPLES) >= 12
    for script in EXAMPLES:
        title = script.read_text().split('"""')[1].strip().splitlines()[0]
        assert title.endswith("?"), f"{script.name}: its title is not a question: {title!r}"
        page = (site["html"] / "gallery" / f"{script.stem}.html").read_text()
        assert f"sphx_glr_{script.stem}_001.png" in page, f"{script.name} shows no figure"
        assert (site["html"] / "_images" / f"sphx_glr_{script.stem}_001.png").is_file()


def test_each_example_runs_in_under_30_s(site):
    """The gallery's own timing of each script (docs/conf.py compiles the kernels first)."""
    seconds = {}
    for script in EXAMPLES:
        text = (site["src"] / "gallery" / f"{script.stem}.rst").read_text()
        minutes, secs = re.search(
            r"running time of the script:\*\* \((\d+) minutes ([\d.]+) seconds\)", text
        ).groups()
        seconds[script.stem] = 60 * int(minutes) + float(secs)
    slow = {name: s for name, s in seconds.items() if s > 30.0}
    assert not slow, slow
    # Each ran: a script the gallery did not execute is timed at zero. A sum would be a
    # guess at the machine's speed (a fast one ran all fourteen in 4.6 s).
    idle = {name: s for name, s in seconds.items() if s <= 0.0}
    assert not idle, idle


def test_the_api_reference_documents_every_public_name(site):
    page = (site["html"] / "api.html").read_text()
    missing = [name for name in metrosync.__all__ if f'id="metrosync.{name}"' not in page]
    assert missing == []


def test_the_model_page_renders_its_equations_with_the_bundled_mathjax(site):
    page = (site["html"] / "model.html").read_text()
    assert page.count('class="math') >= 5
    assert 'src="_static/mathjax/tex-chtml.js' in page
    assert (site["html"] / "_static" / "mathjax" / "tex-chtml.js").is_file()


# -- in a browser ---------------------------------------------------------------------


@pytest.fixture
def browser(tmp_path):
    require("chromium")
    from show.cdp import Browser

    profile = tmp_path / "profile"
    profile.mkdir()
    with Browser(shutil.which("chromium"), profile) as b:
        yield b


def pages(html: Path) -> list[Path]:
    skip = {"_static", "_sources", "_images", "_downloads", "_modules"}
    return sorted(p for p in html.rglob("*.html") if not skip & set(p.relative_to(html).parts))


def visit(browser, url: str, *, ready: str = "true") -> tuple[list[str], list[str]]:
    """Open ``url`` in a new tab with the network watched, wait until it has loaded and
    ``ready`` holds, close the tab; return its console errors and the URLs it requested
    from outside the site."""
    browser.events.clear()
    target = browser.call("Target.createTarget", {"url": "about:blank"}, session=False)
    attached = browser.call(
        "Target.attachToTarget", {"targetId": target["targetId"], "flatten": True}, session=False
    )
    browser.session = attached["sessionId"]
    for domain in ("Runtime", "Log", "Page", "Network"):
        browser.call(f"{domain}.enable")
    browser.call("Page.navigate", {"url": url})
    deadline = time.monotonic() + 30
    while not browser.evaluate(f"document.readyState === 'complete' && Boolean({ready})"):
        assert time.monotonic() < deadline, f"{url}: not ready ({ready})"
        browser.pump(0.1)
    browser.pump(0.2)
    requested = [e["params"]["request"]["url"] for e in browser.events
                 if e.get("method") == "Network.requestWillBeSent"]  # fmt: skip
    browser.call("Target.closeTarget", {"targetId": target["targetId"]}, session=False)
    outside = [u for u in requested if not u.startswith(("file:", "data:", "blob:"))]
    return browser.console_errors(), outside


def test_every_page_opens_without_a_console_error_and_fetches_nothing_outside(site, browser):
    html = site["html"]
    found = pages(html)
    assert len(found) >= 12 + len(EXAMPLES), [p.name for p in found]
    problems = {}
    for page in found:
        # MathJax typesets after the load event: wait for its equations on the model page.
        ready = "document.querySelector('mjx-container')" if page.name == "model.html" else "true"
        errors, outside = visit(browser, page.as_uri(), ready=ready)
        if errors or outside:
            problems[str(page.relative_to(html))] = errors + outside
    assert problems == {}


def test_the_page_check_sees_an_error_and_an_outside_request(site, browser):
    page = site["html"] / "index.html"
    errors, outside = visit(browser, page.as_uri(), ready="true")
    assert (errors, outside) == ([], [])
    probe = "(console.error('probe'), fetch('https://example.org/').catch(() => 0), true)"
    errors, outside = visit(browser, page.as_uri(), ready=probe)
    assert "probe" in errors and outside == ["https://example.org/"]

"""Sphinx configuration of the metrosync documentation site (`make docs`)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
if (ROOT / "src" / "metrosync").is_dir():  # the checkout's sources, installed or not
    sys.path.insert(0, str(ROOT / "src"))

import metrosync  # noqa: E402
from metrosync.integrators.warm_up import compile_kernels  # noqa: E402

project = "metrosync"
author = "the metrosync authors"
copyright = "metrosync authors, MIT licence"  # noqa: A001
version = release = metrosync.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.napoleon",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "sphinx-mathjax-offline",  # MathJax from the package, not a network: the site works offline
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "figures/*.py", "arnold_tongue.py", "**.ipynb_checkpoints"]
# These pages are the site's; the sources' own notes (README.md at the root) are not.
suppress_warnings: list[str] = []

# -- Markdown ---------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "deflist", "colon_fence"]
myst_heading_anchors = 3

# -- API reference ----------------------------------------------------------------
autodoc_default_options = {"members": False}
autodoc_typehints = "none"  # the docstrings' Parameters sections say what each takes
autoclass_content = "class"
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
intersphinx_mapping: dict[str, tuple[str, str | None]] = {}  # offline: link nothing outside

# -- Gallery ----------------------------------------------------------------------
# METROSYNC_DOCS_GALLERY=0 builds the pages without running the examples (the tests do that).
run_gallery = os.environ.get("METROSYNC_DOCS_GALLERY", "1") != "0"
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "plot_gallery": run_gallery,
    "download_all_examples": False,
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "capture_repr": (),
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "min_reported_time": 0,
    "show_memory": False,
    "show_signature": False,
    # Its computation-times page loads scripts from the web; each example shows its own time.
    "write_computation_times": False,
}

# -- HTML -------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"metrosync {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
# A first visit has no stored colour mode: start from the system's, not from none.
html_context = {"default_mode": "auto"}
html_sidebars = {"**": ["sidebar-nav-bs"]}
html_show_sourcelink = False
html_copy_source = False


# -- The model's docstrings -------------------------------------------------------
# The parameter classes list their fields as ``name : meaning`` lines and their units
# as a plain table under a heading of its own. Before napoleon reads them, the list
# gets the numpy-style "Parameters" heading and the table becomes a literal block, so that
# the page shows them as written.
def _tidy_field_docstrings(app, what, name, obj, options, lines):
    if what not in {"class", "exception"}:
        return
    out: list[str] = []
    i = 0
    has_parameters = False
    while i < len(lines):
        line = lines[i]
        underline = lines[i + 1] if i + 1 < len(lines) else ""
        if line.startswith("Parameters") and set(underline) == {"-"}:
            has_parameters = True
            extra = line[len("Parameters") :].strip(" ()")
            out += ["Parameters", "----------"]
            if extra:
                out.insert(len(out) - 2, f"({extra}.)")
                out.insert(len(out) - 2, "")
            i += 2
            continue
        if line.startswith("Units and bounds") and set(underline) == {"-"}:
            out += [f"**{line.strip()}**::", ""]
            i += 2
            while i < len(lines) and lines[i].strip():
                out.append("    " + lines[i])
                i += 1
            out.append("")
            continue
        if (
            not has_parameters
            and out
            and not out[-1].strip()
            and " : " in line
            and line.split(" : ")[0].replace(",", "").replace("_", "").replace(" ", "").isalnum()
            and not line.startswith(" ")
        ):
            out += ["Parameters", "----------"]
            has_parameters = True
        out.append(line)
        i += 1
    lines[:] = out


# -- Compiled kernels before the gallery ----------------------------------------------
# A first build on a machine compiles the numba kernels (1-4 min on the 2-core machine,
# once; they are kept on disk). Compiling them here, before the gallery runs, keeps that
# out of the examples' own times, which the gallery prints under each of them.
def _compile_kernels(app, config):
    if run_gallery:
        compile_kernels()


def setup(app):
    app.connect("autodoc-process-docstring", _tidy_field_docstrings, priority=100)
    app.connect("config-inited", _compile_kernels)

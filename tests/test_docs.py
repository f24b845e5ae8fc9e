"""The README and the site's pages (docs/*.md): links resolve, every public name has its
entry in the API reference, and the model page's numbers are the code's."""

import re
from pathlib import Path

from metrosync.model import PRESETS
from metrosync.paper import paper_sigma_to_bpm

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "docs" / "model.md"
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def test_every_relative_link_resolves():
    local = [
        (page, link)
        for page in DOCS
        for link in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text())
        if "://" not in link
    ]
    assert len(local) > 5, "hardly any relative links found: the pattern is wrong"
    assert not [link for page, link in local if not (page.parent / link).exists()]


def test_the_api_page_names_every_public_name():
    import metrosync

    text = (ROOT / "docs" / "api.md").read_text()
    documented = set(
        re.findall(r"^\.\. (?:autofunction|autoclass|autoexception|py:data):: (\w+)", text, re.M)
    )
    assert set(metrosync.__all__) <= documented, set(metrosync.__all__) - documented


def test_every_page_is_in_the_site_s_table_of_contents():
    index = (ROOT / "docs" / "index.md").read_text()
    pages = {p.stem for p in (ROOT / "docs").glob("*.md")} - {"index"}
    assert not [page for page in pages if f"\n{page}\n" not in index]


def test_the_readme_links_the_model_page_and_no_missing_notes():
    readme = (ROOT / "README.md").read_text()
    assert "](docs/model.md)" in readme
    assert "MODEL-NOTES" not in readme


def test_the_model_page_names_every_equation_the_code_cites():
    label = r"\((eqm[\w-]*|metron2a?|lagrange|excitation|op)\)"
    cited = set()
    for path in (ROOT / "src" / "metrosync").rglob("*.py"):
        cited |= set(re.findall(label, path.read_text()))
    assert {"eqm1", "eqm2", "metron2a", "metron2"} <= cited
    text = MODEL.read_text()
    assert not [label for label in cited if f"({label})" not in text]


def test_the_model_page_quotes_the_code_s_numbers():
    text = " ".join(MODEL.read_text().split())
    default, published = PRESETS["default"], PRESETS["boda2013"]
    design, platform = default.metronome, default.platform
    assert f"{default.balance_amplitude:.2f} rad" in text
    assert f"{published.balance_amplitude:.1f} rad" in text
    assert f"about {design.with_l2(0.019).natural_bpm:.0f} BPM (L₂ = 0.019 m)" in text
    assert f"down to {design.with_l2(0.049).natural_bpm:.0f} BPM (L₂ = 0.049 m)" in text
    low, high = design.bpm_range()
    assert f"{low:.0f}–{high:.0f} BPM" in text
    assert f"{design.l2_for_bpm(160.0):.3f} m at 160 BPM" in text
    assert f"8 → {paper_sigma_to_bpm(8.0):.2f} BPM" in text
    for n in (2, 7, 64, 256):
        value = platform.disk_inertia(n)
        assert f"J({n}) = {value:.3g}" in text, n
    assert f"N × {platform.j_per_metronome:.6f} kg m²" in text


def test_the_citation_file_cites_the_software_and_the_paper():
    import yaml  # dask's dependency

    import metrosync

    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["type"] == "software" and cff["version"] == metrosync.__version__
    (paper,) = cff["references"]
    assert paper["title"] == "The rhythm of coupled metronomes" and paper["year"] == 2013
    assert [a["family-names"] for a in paper["authors"]] == ["Boda", "Néda", "Tyukodi", "Tunyagi"]
    assert paper["identifiers"][0]["value"] == "arXiv:1210.3175"

"""The project cites its own account of the model (docs/model.md), never outside notes."""

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_sources_and_docs_cite_the_projects_own_model_page():
    cited = [
        str(path.relative_to(ROOT))
        for folder in ("src", "docs", "benchmarks")
        for path in (ROOT / folder).rglob("*")
        if path.suffix in {".py", ".md", ".js", ".html", ".c", ".h"}
        and "MODEL-NOTES" in path.read_text(encoding="utf-8", errors="replace")
    ]
    assert cited == [], f"cite docs/model.md instead of MODEL-NOTES in: {cited}"

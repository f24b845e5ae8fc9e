"""The synthetic data stay apart from the analysis they test: the analysis imports none
of the generator, so what it assumes about a tick is its own."""

from __future__ import annotations

import ast
from pathlib import Path

import metrosync

ANALYSIS = Path(metrosync.__file__).parent / "audio"


def imported_modules(path: Path) -> set[str]:
    """The modules ``path`` imports, absolute (a relative import resolved against
    ``metrosync.audio``)."""
    package = ["metrosync", "audio"]
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) + 1 - node.level] if node.level else []
            module = ".".join([*base, node.module] if node.module else base)
            names.add(module)
            names |= {f"{module}.{alias.name}" for alias in node.names}
    return names


def test_the_analysis_imports_nothing_of_the_generator():
    modules = sorted(ANALYSIS.glob("*.py"))
    assert len(modules) > 10
    offenders = {
        path.name: sorted(m for m in imported_modules(path) if m.startswith("metrosync.synthetic"))
        for path in modules
    }
    assert {name: found for name, found in offenders.items() if found} == {}


def test_the_check_sees_a_relative_import_of_the_generator(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("from ..synthetic.ticks import SUB_DELAY_RANGE\n", encoding="utf-8")
    assert "metrosync.synthetic.ticks.SUB_DELAY_RANGE" in imported_modules(probe)

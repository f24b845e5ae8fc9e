"""Where the test suite's time goes, per test folder, from the JUnit XML `make test` writes.

    python benchmarks/suite_times.py build/test-times.xml [--top 15]

Each test's time is what its worker spent on it (set-up, call and tear-down), so with
pytest-xdist the folders' times add up to about the cores times the wall time. Module-
and session-scoped fixtures are charged to the first test that asks for them.
"""

from __future__ import annotations

import argparse
import sys
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path


def _folder(classname: str) -> str:
    # JUnit class names are dotted module paths: tests.audio.test_x.TestY -> tests/audio
    parts = classname.split(".")
    modules = [i for i, part in enumerate(parts) if part.startswith("test_")]
    cut = modules[0] if modules else len(parts) - 1
    return "/".join(parts[:cut]) or "(top)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("xml", type=Path, help="JUnit XML from pytest --junitxml")
    parser.add_argument("--top", type=int, default=15, help="slowest tests to list (default 15)")
    args = parser.parse_args(argv)
    if not args.xml.is_file():
        parser.error(f"{args.xml}: no such file; `make test` writes build/test-times.xml")
    root = ET.parse(args.xml).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    wall = sum(float(s.get("time", 0.0)) for s in suites)
    per_folder: dict[str, list[float]] = defaultdict(list)
    tests: list[tuple[float, str]] = []
    for case in root.iter("testcase"):
        seconds = float(case.get("time", 0.0))
        classname = case.get("classname", "")
        per_folder[_folder(classname)].append(seconds)
        tests.append((seconds, f"{classname}::{case.get('name', '')}"))
    total = sum(sum(times) for times in per_folder.values())
    print(f"{len(tests)} tests, wall {wall:.0f} s, worker time {total:.0f} s")
    print(f"{'folder':<28} {'tests':>6} {'seconds':>9} {'share':>6}")
    for folder, times in sorted(per_folder.items(), key=lambda kv: -sum(kv[1])):
        print(f"{folder:<28} {len(times):>6} {sum(times):>9.0f} {sum(times) / total:>6.1%}")
    print(f"\nslowest {args.top}:")
    for seconds, name in sorted(tests, reverse=True)[: args.top]:
        print(f"{seconds:8.1f} s  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

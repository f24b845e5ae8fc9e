"""Every Python block of the README and of the documentation site's pages (docs/*.md)
runs on its own, as a reader pastes it into a fresh interpreter, and gives the values
its comments quote. (The gallery's scripts, examples/, run at every `make docs` and in
tests/test_docs_site.py.)

A block is run statement by statement in an empty namespace, in an empty folder.
An expression statement whose comment quotes a result (``# ≈ 0.92, 0.99`` or
``# True: ...``) is evaluated and compared with it: numbers to the quoted decimals
(one unit of the last digit either way), booleans exactly. The blocks run at the
sizes printed; all of them together simulate about 3×10⁷ oscillator-steps. A block
that appears on several pages runs once.
"""

import ast
import re
from pathlib import Path

import matplotlib
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]
PYTHON_BLOCK = re.compile(r"^```python\n(.*?)^```", flags=re.S | re.M)
LOCATED: dict[str, str] = {}  # block -> "page:line" of its first appearance
for _page in PAGES:
    _text = _page.read_text()
    for _match in PYTHON_BLOCK.finditer(_text):
        _where = f"{_page.relative_to(ROOT)}:{_text[: _match.start()].count(chr(10)) + 2}"
        LOCATED.setdefault(_match.group(1), _where)
BLOCKS = list(LOCATED)
QUOTED_NUMBERS = re.compile(r"#.*?≈\s*((?:-?\d+\.\d+(?:,\s*)?)+)")
QUOTED_BOOL = re.compile(r"#\s*(True|False)\b")


def block_id(block: str) -> str:
    return LOCATED[block]


def quoted(source: str):
    """What the comment on ``source`` (one statement's lines) quotes: a list of numbers
    as strings, a bool, or None."""
    numbers = QUOTED_NUMBERS.search(source)
    if numbers:
        return [x.strip() for x in numbers.group(1).split(",") if x.strip()]
    flag = QUOTED_BOOL.search(source)
    return None if flag is None else flag.group(1) == "True"


def check_quote(value, quote, where: str) -> None:
    if isinstance(quote, bool):
        assert bool(value) is quote, f"{where}: got {value!r}, the page says {quote}"
        return
    got = np.ravel(np.asarray(value, dtype=float))
    assert got.size == len(quote), f"{where}: got {got}, the page quotes {quote}"
    for x, text in zip(got, quote, strict=True):
        decimals = len(text.split(".")[1])
        assert abs(x - float(text)) <= 10.0**-decimals, f"{where}: got {got}, the page: {quote}"


def run_block(block: str, where: str) -> int:
    """Run ``block`` in a fresh namespace; return how many quoted values it checked."""
    lines = block.splitlines()
    namespace: dict = {"__name__": "__readme__"}
    checked = 0
    for statement in ast.parse(block).body:
        source = "\n".join(lines[statement.lineno - 1 : statement.end_lineno])
        quote = quoted(source)
        if isinstance(statement, ast.Expr):
            code = compile(ast.Expression(statement.value), where, "eval")
            value = eval(code, namespace)  # noqa: S307 - the page's own code
            if quote is not None:
                check_quote(value, quote, f"{where}+{statement.lineno - 1}")
                checked += 1
        else:
            assert quote is None, f"{where}: a quoted result on a statement that is no expression"
            exec(compile(ast.Module([statement], []), where, "exec"), namespace)  # noqa: S102
    return checked


def test_the_pages_have_the_blocks_this_file_expects():
    assert len(BLOCKS) >= 4, "the pattern for ```python blocks found too few"
    assert any(where.startswith("docs/") for where in LOCATED.values())
    assert any(where.startswith("README.md") for where in LOCATED.values())
    assert sum(quoted(line) is not None for b in BLOCKS for line in b.splitlines()) >= 3


@pytest.mark.parametrize("block", BLOCKS, ids=block_id)
def test_each_python_block_runs_on_its_own(block, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    try:
        run_block(block, block_id(block))
    finally:
        plt.close("all")


def test_a_wrong_quote_is_caught():
    with pytest.raises(AssertionError, match="the page"):
        run_block("x = 0.5\nx + 0.1   # ≈ 0.50\n", "example")
    with pytest.raises(AssertionError, match="the page says True"):
        run_block("1 > 2   # True: of course not\n", "example")
    with pytest.raises(NameError):
        run_block("ms.simulate\n", "example")  # a name only an earlier block defines
    assert run_block("x = [0.921, 0.99]\nx   # ≈ 0.92, 0.99\n", "example") == 1

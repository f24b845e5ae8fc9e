"""Another revision of metrosync beside this tree's, for benchmarks that compare the two
in one run (`--baseline REV`): the revision is checked out into a temporary git
worktree and run from its source with this environment's installed dependencies."""

from __future__ import annotations

import contextlib
import os
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@contextlib.contextmanager
def checkout(rev: str) -> Iterator[Path]:
    """The root of a temporary worktree of revision ``rev`` (a commit, tag or branch),
    removed afterwards; exits with a one-line message where git does not know ``rev``."""
    known = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet",
                            f"{rev}^{{commit}}"], capture_output=True, text=True)  # fmt: skip
    if known.returncode:
        raise SystemExit(f"--baseline {rev!r}: not a revision of this repository "
                         f"(try a commit such as HEAD~3, or a tag)")  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="baseline-") as tmp:
        where = Path(tmp) / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "--quiet",
                        str(where), known.stdout.strip()], check=True)  # fmt: skip
        try:
            yield where
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(where)],
                           check=False)  # fmt: skip


def environment(root: Path | None) -> dict[str, str]:
    """This process's environment, with the package imported from ``root``'s source
    (None: as installed, this tree)."""
    env = dict(os.environ)
    if root is not None:
        env["PYTHONPATH"] = os.pathsep.join(
            [str(root / "src"), *filter(None, [env.get("PYTHONPATH")])]
        )
    return env

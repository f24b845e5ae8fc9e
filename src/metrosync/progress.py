"""Progress bars for long work (tqdm on stderr), or a silent stand-in."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from tqdm import tqdm


class _Silent:
    def update(self, n: float = 1) -> None:
        del n


@contextlib.contextmanager
def progress_bar(*, total: float, unit: str, enabled: bool, desc: str | None = None) -> Iterator:
    if not enabled:
        yield _Silent()
        return
    with tqdm(total=total, unit=unit, desc=desc, dynamic_ncols=True, leave=False) as bar:
        yield bar

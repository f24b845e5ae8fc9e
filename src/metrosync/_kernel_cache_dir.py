"""Where numba keeps the compiled kernels: a per-user folder that outlives a reinstall.

Chosen when ``metrosync`` is imported, before numba is, so this module imports only
``os`` and ``sys``: ``python -m metrosync`` imports the package before its Ctrl-C
handling is installed, and nothing slow may run there.
"""

from __future__ import annotations

import os
import sys


def user_cache_dir() -> str:
    """``$XDG_CACHE_HOME/metrosync/numba`` (``~/.cache/metrosync/numba``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "metrosync", "numba")


def use_user_cache() -> str | None:
    """Point numba's compile cache at `user_cache_dir` unless ``NUMBA_CACHE_DIR`` is
    set; return the cache root in use (None: numba's default, beside the sources,
    because the user folder cannot be written)."""
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if not chosen:
        folder = user_cache_dir()
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError:  # a read-only home: keep numba's default
            return None
        if not os.access(folder, os.W_OK | os.X_OK):
            return None
        chosen = os.environ["NUMBA_CACHE_DIR"] = folder
    if "numba" in sys.modules:  # imported before metrosync: have it read the variable
        sys.modules["numba"].config.reload_config()
    return chosen

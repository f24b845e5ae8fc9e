"""Compile the fixed-step kernels ahead of the work that needs them.

Each kernel compiles on first use, tens of seconds (`_cache.COMPILE_SECONDS`), and is
then kept on disk. Work that starts many processes at once (the documentation's
gallery, the test suite on every core) would otherwise compile the same kernel in
several of them side by side. `compile_kernels` compiles both memory layouts of the
schemes it is given by running each once on a tiny ensemble; with the cache warm it
only loads them (about a second).

    python -m metrosync.integrators.warm_up [verlet] [located]
"""

from __future__ import annotations

import sys

SCHEMES = ("verlet", "located")
#: (metronomes, runs) that pick each memory layout: runs innermost, metronomes innermost.
LAYOUT_SIZES = ((3, 16), (12, 2))


def compile_kernels(schemes=SCHEMES) -> None:
    from ..simulate import simulate

    for scheme in schemes:
        for n, runs in LAYOUT_SIZES:
            simulate(n, 192.0, runs=runs, duration=0.2, integrator=scheme, progress=False)


def main(argv: list[str] | None = None) -> int:
    schemes = sys.argv[1:] if argv is None else argv
    unknown = sorted(set(schemes) - set(SCHEMES))
    if unknown:
        print(f"unknown scheme {unknown[0]!r}: choose from {', '.join(SCHEMES)}", file=sys.stderr)
        return 2
    try:
        compile_kernels(schemes or SCHEMES)
    except KeyboardInterrupt:  # what is compiled is on disk; the rest compiles on use
        print("interrupted: the kernels not yet compiled compile when first used", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())

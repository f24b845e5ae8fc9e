"""Which studies the paper has: `STUDIES`, in report order, and `get_studies`.

The kinds of study and the paper's instances of them are declared in
`metrosync.paper.studies` (Figs. 8, 10, 11, the z-study, the estimation),
`metrosync.paper.sigma_map` and `metrosync.paper.claims_map`; this module only lists them.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import ParameterError
from .claims_map import CLAIMS_MAP
from .runner import Study
from .sigma_map import SIGMA_MAP
from .studies import ESTIMATION, FIG8_BOTTOM, FIG8_TOP, FIG10, FIG11, Z_STUDY

#: Every study `metrosync reproduce` runs, in report order.
STUDIES: tuple[Study, ...] = (
    FIG8_TOP, FIG8_BOTTOM, FIG10, FIG11, Z_STUDY, ESTIMATION, SIGMA_MAP, CLAIMS_MAP,
)  # fmt: skip


def get_studies(names: Sequence[str] | None = None) -> tuple[Study, ...]:
    """The studies called ``names`` (all of `STUDIES` when None), in report order."""
    if names is None:
        return STUDIES
    known = {s.name: s for s in STUDIES}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ParameterError(f"unknown study {unknown}; choose from {list(known)}.")
    return tuple(s for s in STUDIES if s.name in set(names))

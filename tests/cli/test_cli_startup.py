"""The command line starts light: a typo is refused before scipy or numba load."""

import subprocess
import sys

from metrosync.paper.catalogue import STUDIES
from metrosync.paper.names import STUDY_NAMES


def test_the_parser_needs_neither_scipy_nor_numba():
    # every command builds every subcommand's parser: an import there is paid by all (the
    # paper's catalogue once cost each command 3.5 s before it could refuse a typo)
    code = (
        "import sys\n"
        "from metrosync.cli import build_parser\n"
        "build_parser()\n"
        "heavy = sorted(m for m in ('scipy', 'numba', 'matplotlib') if m in sys.modules)\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_the_light_list_of_studies_is_the_catalogue():
    assert STUDY_NAMES == tuple(s.name for s in STUDIES)

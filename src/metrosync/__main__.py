"""``python -m metrosync``: the command line, as the ``metrosync`` script runs it."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())

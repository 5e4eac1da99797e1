"""``python -m msslib``: see :mod:`msslib.cli`."""

import sys

from msslib.cli import main

if __name__ == "__main__":
    sys.exit(main())

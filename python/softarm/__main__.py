"""``python -m softarm``: the ``softarm`` command line."""

import sys

from softarm.cli import main

if __name__ == "__main__":
    sys.exit(main())

"""``python -m shaped_es ...``: the same command line as ``shaped-es ...``."""

import sys

from shaped_es.cli.commands import main

if __name__ == "__main__":
    sys.exit(main())

"""Allow ``python -m pneumorph``."""

import sys

from pneumorph.cli import main

if __name__ == "__main__":
    sys.exit(main())

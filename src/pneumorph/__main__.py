"""Allow ``python -m pneumorph``."""

import sys

from pneumorph.cli import main

sys.exit(main())

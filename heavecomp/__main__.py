"""``python -m heavecomp``: the same command line as ``heavecomp``."""

import sys

from heavecomp.cli import main

sys.exit(main())

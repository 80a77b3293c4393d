"""``python -m fibril_hpc.cli``: the same as ``fibril-run``."""

import sys

from .entry import fibril_run

sys.exit(fibril_run())

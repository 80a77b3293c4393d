"""``python -m fibril_hpc.cli``: the same as ``fibril-run``."""

import sys

from .run import main

sys.exit(main())

"""``python -m benchmarks.fibril_bench``."""

import sys

from .cli import main

sys.exit(main())

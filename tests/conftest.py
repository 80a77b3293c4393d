import os

import pytest

os.environ.setdefault("NUMBA_CACHE_DIR", os.path.join(os.path.dirname(__file__), "..", ".numba_cache"))

from fibril_hpc.scene import SolverOptions  # noqa: E402


@pytest.fixture
def opts():
    """Single-threaded, estimate-planned options (tests never pay expensive planning)."""
    return SolverOptions(fft_threads=1, fft_planner="estimate")

"""Element-wise work of the solver: numba kernels (``compiled``) and NumPy float64 twins
(``reference``) with identical signatures and semantics. The solver uses ``compiled``; the tests
check every compiled kernel against its twin.

Conventions shared by all kernels: vectors are float64 arrays over the *active* elements (those
that can ever touch), grouped contiguously by pillar (``starts``); ``att`` is a uint8 mask of the
attached set S; outputs are caller-provided arrays; nothing is allocated per call except scalars.
"""

from . import compiled, reference

__all__ = ["compiled", "reference"]

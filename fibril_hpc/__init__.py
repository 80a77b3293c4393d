"""fibril-hpc: FFT-BEM simulation of the adhesive pull-off of rough, spring-backed pillar arrays.

Public API::

    from fibril_hpc import Scene, SolverOptions, simulate
    result = simulate(Scene(k_tilde=0.01, sigma_tilde=0.5, F_P=4.0, seed=0))
    result.main.F_A, result.main.unloading.F_tilde
"""

__version__ = "0.1.0"

from .errors import ConfigError, FibrilError, NoConvergenceError, StoreError  # noqa: E402
from .scene import Scene, SolverOptions, scene_from_dict  # noqa: E402
from .api import simulate  # noqa: E402
from .campaign.data import load_campaign  # noqa: E402

__all__ = ["Scene", "SolverOptions", "scene_from_dict", "simulate", "ConfigError",
           "FibrilError", "NoConvergenceError", "StoreError", "load_campaign", "__version__"]

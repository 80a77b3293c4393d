"""fibril-hpc: FFT-BEM simulation of the adhesive pull-off of rough, spring-backed pillar arrays.

Public API::

    from fibril_hpc import Scene, SolverOptions, simulate
    result = simulate(Scene(k_tilde=0.01, sigma_tilde=0.5, F_P=4.0, seed=0))
    result.main.F_A, result.main.unloading.F_tilde
    read_result_file("curve.h5")          # a file written by fibril-run --out
    load_campaign("results.h5")           # a campaign file (fibril-campaign)

Layers, lowest first (each subpackage's docstring says what it owns; ``lint-imports`` checks that
nothing imports upwards): :mod:`.errors`; :mod:`.geometry` and :mod:`.kernels`; :mod:`.elastic`;
:mod:`.solve`; :mod:`.path`; :mod:`.inputs`; :mod:`.io` and :mod:`.model`; :mod:`.api`;
:mod:`.campaign` and :mod:`.accuracy`; :mod:`.cli`.
"""

from ._version import __version__
from .api import simulate
from .campaign.analysis.data import load_campaign
from .errors import ConfigError, FibrilError, NoConvergenceError, StoreError
from .inputs.options import SolverOptions
from .inputs.scene import Scene, scene_from_dict
from .io.store import read_result_file

__all__ = ["Scene", "SolverOptions", "scene_from_dict", "simulate", "ConfigError",
           "FibrilError", "NoConvergenceError", "StoreError", "load_campaign", "read_result_file",
           "__version__"]

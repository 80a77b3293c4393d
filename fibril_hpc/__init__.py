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

The public names load on first use (PEP 562): importing the package, or one of its light
modules (the console scripts' :mod:`.cli.entry`, :mod:`.errors`), does not import numba, h5py
or pyFFTW, so that a command answers Ctrl-C from its first instant.
"""

from __future__ import annotations

from ._version import __version__
from .errors import ConfigError, FibrilError, NoConvergenceError, StoreError

#: public name -> the module that defines it (imported on first access)
_LAZY = {"simulate": ".api", "load_campaign": ".campaign.analysis.data",
         "SolverOptions": ".inputs.options", "Scene": ".inputs.scene",
         "scene_from_dict": ".inputs.scene", "read_result_file": ".io.store"}

TYPE_CHECKING = False                  # typing.TYPE_CHECKING without importing typing (slow)
if TYPE_CHECKING:                      # for type checkers and documentation tools
    from .api import simulate
    from .campaign.analysis.data import load_campaign
    from .inputs.options import SolverOptions
    from .inputs.scene import Scene, scene_from_dict
    from .io.store import read_result_file

__all__ = ["Scene", "SolverOptions", "scene_from_dict", "simulate", "ConfigError",
           "FibrilError", "NoConvergenceError", "StoreError", "load_campaign", "read_result_file",
           "__version__"]


def __getattr__(name: str):
    """The public names of :data:`_LAZY`, imported when first asked for."""
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))

"""Accuracy presets: named sets of resolution and solver knobs, chosen from the measured
accuracy/time trade-off (``fibril-accuracy``; README, "Accuracy and presets").

A scene picks one with ``preset: fast | default | accurate`` (YAML) or ``Scene(preset=...)``.
The preset fills only what the scene does not give:

* ``elements_per_diameter`` when it is not given (``None``);
* the solver knobs when ``solver`` is not given, or is a mapping of the knobs to change (YAML
  ``solver: {fft_threads: 1}``; the mapping's keys override the preset's values, exactly).
  A :class:`~fibril_hpc.scene.SolverOptions` object is a complete set of knobs and is used as
  given; :func:`solver_options` builds one from a preset with overrides.

The resolved values (and the preset's name) are stored in every result (``Scene.to_dict``), so a
reader of an output file knows its accuracy class.
"""

from __future__ import annotations

#: Preset name used when a scene names none: the package defaults.
DEFAULT_PRESET = "default"

#: name -> (elements_per_diameter, solver knobs). Only accuracy knobs; FFT settings stay free.
PRESETS = {
    # 6 elements per diameter; loose tolerances and coarse event batching, which the study
    # measured to change F~_A by < 0.3 % (the resolution error, 2-7 %, dominates)
    "fast": {
        "elements_per_diameter": 6,
        "solver": {"cg_tol": 1e-6, "relax_tol": 1e-3, "event_merge": 1e-2,
                   "load_event_merge": 1e-1, "detach_policy": "all"},
    },
    # the package defaults (SolverOptions and Scene), 8 elements per diameter
    "default": {
        "elements_per_diameter": 8,
        "solver": {"cg_tol": 1e-8, "relax_tol": 1e-5, "event_merge": 1e-4,
                   "load_event_merge": 1e-2, "detach_policy": "all"},
    },
    # 16 elements per diameter (within ~0.5 % of the finest measured brush grids); tolerances
    # tighter than the default, merging as the default (measured not to move F~_A)
    "accurate": {
        "elements_per_diameter": 16,
        "solver": {"cg_tol": 1e-10, "relax_tol": 1e-6, "event_merge": 1e-4,
                   "load_event_merge": 1e-2, "detach_policy": "all"},
    },
}

PRESET_NAMES = tuple(PRESETS)


def check_name(name, field: str = "preset") -> str:
    """Return ``name`` if it is a known preset, else raise a one-line ConfigError."""
    from .errors import ConfigError

    if not isinstance(name, str) or name not in PRESETS:
        raise ConfigError(field, name, "one of " + ", ".join(PRESET_NAMES))
    return name


def preset_values(name: str) -> dict:
    """A copy of a preset's values: ``{"elements_per_diameter": ..., "solver": {...}}``."""
    p = PRESETS[check_name(name)]
    return {"elements_per_diameter": p["elements_per_diameter"], "solver": dict(p["solver"])}


def solver_options(name: str = DEFAULT_PRESET, **overrides):
    """:class:`~fibril_hpc.scene.SolverOptions` of a preset with explicit overrides."""
    from .scene import SolverOptions

    return SolverOptions(**{**preset_values(name)["solver"], **overrides})

"""Accuracy presets: named sets of resolution and solver knobs, chosen from the measured
accuracy/time trade-off (``fibril-accuracy``; docs/accuracy.md).

A scene picks one with ``preset: fast | default | accurate`` (YAML) or ``Scene(preset=...)``.
The preset fills only what the scene does not give:

* ``elements_per_diameter`` when it is not given (``None``);
* the solver knobs when ``solver`` is not given, or is a mapping of the knobs to change (YAML
  ``solver: {fft_threads: 1}``; the mapping's keys override the preset's values, exactly).
  A :class:`~fibril_hpc.inputs.options.SolverOptions` object is a complete set of knobs and is used as
  given; ``SolverOptions.from_preset`` builds one from a preset with overrides.

Presets set only ``accuracy`` options (``SolverOptions.of_kind("accuracy")``); resource and
backend options (FFT threads, planner, caps) stay free. Model and presets: docs/model.md §7.
This module holds data only and imports nothing of the package.

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


def preset_values(name: str) -> dict:
    """A copy of a preset's values: ``{"elements_per_diameter": ..., "solver": {...}}``.

    ``name`` must be one of :data:`PRESET_NAMES` (``Scene`` validates the user's choice).
    """
    p = PRESETS[name]
    return {"elements_per_diameter": p["elements_per_diameter"], "solver": dict(p["solver"])}

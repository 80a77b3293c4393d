"""The ``sweep:`` mapping of a campaign grid: the scene fields swept beside the grid's axes.

A grid may sweep the brush size ``n_side`` (a finite-size study) and the lab fields of
:class:`~fibril_hpc.inputs.scene.Scene` (lattice, heights, k_law, tip, k_machine, ...), each as
a value or a non-empty list of distinct values. Every combination with the axes (k~, sigma~,
preload, seed) is one job, keyed like any job by its resolved single-preload scene: a job of a
grid sweeping ``n_side`` at n_side = N has the key the same job has in a grid with
``scene: {n_side: N}``.

``n_side`` values are checked here, exactly as the scene checks ``n_side`` (integers in
[1, 1000]). What depends on the pillar count cannot be swept with it, and is one line naming the
field: a fixed ``scene.n_side``/``n_pillars`` (the side is swept), measured lengths or
stiffnesses (a file or list holds one value per pillar of one brush size), and pillar springs or
length spreads given in SI units (k~ = k/(E* L) and sigma~ = sigma/d_c depend on the brush side
L, so one physical value is a different k~ or sigma~ at every n_side; give k_tilde and
sigma_tilde). A ``physical:`` unit system alone (E*, dgamma, diameter or pitch) is fine: each
job's newtons and metres follow from its own lattice.
"""

from __future__ import annotations

import os
from dataclasses import fields

from ...errors import ConfigError, unknown_key
from ...inputs.heights import is_file as is_height_file
from ...inputs.heights import read_file as read_height_file
from ...inputs.ranges import range_of
from ...inputs.scene import Scene

#: lab fields of :class:`Scene` (swept like the axes; stored only off their default)
LAB_FIELDS = tuple(f.name for f in fields(Scene) if f.metadata.get("extra") and f.metadata["key"])
#: scene fields a grid may sweep under ``sweep:``: the brush size and the lab fields
SWEEPABLE = ("n_side",) + LAB_FIELDS
#: lab fields whose value may be a measured file, and the field that records its name and hash
FILE_FIELDS = {"heights": "heights_source", "k_law": "k_source"}
#: the ``physical:`` keys (and top-level SI lists) that set k~ or sigma~ from SI values
SI_SETTERS = {"k": "k_tilde", "pillar_length": "k_tilde", "pillar_modulus": "k_tilde",
              "sigma": "sigma_tilde"}


def _n_side_values(values) -> tuple:
    """The swept brush sizes: integers in the range of ``Scene.n_side``, distinct, non-empty."""
    rng = range_of(Scene, "n_side")
    allowed = rng.allowed(plural=True) + ", a value or a non-empty list of distinct ones"
    items = list(values) if isinstance(values, list) else [values]
    if not items:
        raise ConfigError("sweep.n_side", values, allowed)
    out = []
    for item in items:
        try:
            out.append(rng.check("sweep.n_side", item))
        except ConfigError:
            raise ConfigError("sweep.n_side", item, allowed) from None
    if len(set(out)) != len(out):
        raise ConfigError("sweep.n_side", values, allowed + " (no duplicates)")
    return tuple(out)


def parse_sweep(v) -> dict:
    """The ``sweep:`` mapping: field -> non-empty tuple of distinct values (``n_side`` checked
    here; a lab field's values are checked when the jobs' scenes are built)."""
    if v is None:
        return {}
    if not isinstance(v, dict):
        raise ConfigError("sweep", v, "a mapping of " + ", ".join(SWEEPABLE) + " to lists")
    out = {}
    for name, values in v.items():
        if name not in SWEEPABLE:
            raise unknown_key(f"sweep.{name}", values, SWEEPABLE, "a sweepable field")
        if name == "n_side":
            out[name] = _n_side_values(values)
            continue
        items = list(values) if isinstance(values, list) else [values]
        if not items or len({repr(x) for x in items}) != len(items):
            raise ConfigError(f"sweep.{name}", values, "a value or a non-empty list of distinct "
                              "values")
        out[name] = tuple(items)
    return out


def _per_pillar(v) -> bool:
    """Whether a heights/k_law value holds one value per pillar (a file or a list)."""
    return isinstance(v, (list, tuple)) or is_height_file(v)


def check_n_side_sweep(scene_map: dict, sweep: dict, data: dict) -> None:
    """With ``sweep.n_side``: refuse, in one line naming the field, what depends on the pillar
    count (module docstring). ``scene_map``: the grid's ``scene``; ``data``: the whole grid."""
    if "n_side" not in sweep:
        return
    for name in ("n_side", "n_pillars"):
        if scene_map.get(name) is not None:
            raise ConfigError(f"scene.{name}", scene_map[name], "absent with sweep.n_side (the "
                              "brush side is swept; give the sizes there)")
    laws = {"heights": "a law ('gaussian', 'exponential' or 'uniform')",
            "k_law": "a law ('one' or 'lognormal')"}
    why = (" with sweep.n_side: measured values are one per pillar of one brush size (sweep "
           "n_side with a law, or run one grid per n_side)")
    for name, text in laws.items():
        if _per_pillar(scene_map.get(name)):
            raise ConfigError(f"scene.{name}", scene_map[name], text + why)
        for item in sweep.get(name, ()):
            if _per_pillar(item):
                raise ConfigError(f"sweep.{name}", item, text + why)
    block = scene_map.get("physical")
    given = [(f"scene.physical.{k}", block[k], SI_SETTERS[k]) for k in SI_SETTERS
             if isinstance(block, dict) and k in block]
    given += [(k, data[k], SI_SETTERS[k]) for k in ("k", "sigma") if k in data]
    if given:
        name, value, norm = given[0]
        dep = ("k~ = k/(E* L)" if norm == "k_tilde" else "sigma~ = sigma/d_c") + \
            " depends on the brush side L, so one SI value is another " + norm + " at each n_side"
        raise ConfigError(name, value, f"absent with sweep.n_side ({dep}): give {norm} to "
                          "compare brush sizes at the same normalised value")


def sweep_files(sweep: dict, base: Scene, base_dir: str) -> dict:
    """{(field, value): ((field, values), (source field, "path sha256:...")), ...} for the swept
    values of a field that takes files: each file read once, relative to the YAML's folder, and
    its count checked here, so a bad file is one line naming ``sweep.<field>`` and the file; a
    law (not a file) clears the source a measured file of the base scene left."""
    out = {}
    n = base.n_side**2
    for name, src in FILE_FIELDS.items():
        for item in sweep.get(name, ()):
            if not isinstance(item, str):
                continue                    # checked with the job's scene
            if not is_height_file(item):
                out[(name, item)] = ((name, item), (src, ""))
                continue
            path = os.path.join(base_dir, os.path.expanduser(item))
            try:
                values, source = read_height_file(path, name)
            except ConfigError as exc:
                raise ConfigError(f"sweep.{name}", item, exc.allowed) from None
            if len(values) != n:
                raise ConfigError(f"sweep.{name}", item, f"one value per pillar: n_side**2 = {n} "
                                  f"(the file holds {len(values)})")
            out[(name, item)] = ((name, values), (src, source))
    return out


__all__ = ["SWEEPABLE", "LAB_FIELDS", "FILE_FIELDS", "parse_sweep", "check_n_side_sweep",
           "sweep_files"]

"""The SI columns of a campaign given in physical units (docs/units.md).

A grid with ``scene.physical`` stores its jobs in normalised form, like any other, plus the SI
value of every unit in the root attribute ``units``. The force and displacement units depend on
the job's lattice (F_c and d_c use its discrete filling ratio), so they are computed per job
from its stored scene, once per distinct lattice and unit system.
"""

from __future__ import annotations

import math

import numpy as np
import yaml

from ...geometry.grid import Lattice
from ...inputs.scene import scene_from_dict
from ...io.results import SI_FIELDS

#: SI column -> (long name, unit), in the order they follow the normalised columns
SI_COLUMNS = {
    "F_c_N": ("force unit F_c", "N"),
    "d_c_m": ("displacement unit d_c", "m"),
    "k_N_per_m": ("pillar spring stiffness k", "N/m"),
    "sigma_m": ("standard deviation of the pillar lengths", "m"),
    "F_P_N": ("force at the end of loading", "N"),
    "F_A_N": ("pull-off force", "N"),
    "d_max_m": ("plate displacement at the end of loading", "m"),
    "d_at_F_A_m": ("plate displacement at pull-off", "m"),
}


def has_units(meta: dict) -> bool:
    """Whether a campaign file was written from a grid in physical units."""
    return bool(meta.get("units"))


def _scales(rec: dict, cache: dict) -> dict | None:
    text = rec.get("scene_yaml") or ""
    at = text.find("physical:")
    if at < 0:
        return None
    key = (rec.get("discretisation"), text[at:at + 200])
    if key not in cache:
        scene = scene_from_dict(yaml.safe_load(text))
        lattice = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
        cache[key] = scene.physical.si(lattice)
    return cache[key]


def si_columns(jobs) -> dict:
    """SI column name -> float array over ``jobs`` (NaN where a job has no unit system)."""
    cache: dict = {}
    out = {name: np.full(len(jobs), math.nan) for name in SI_COLUMNS}
    for i, rec in enumerate(jobs):
        u = _scales(rec, cache)
        if u is None:
            continue
        out["F_c_N"][i], out["d_c_m"][i] = u["F_c"], u["d_c"]
        out["k_N_per_m"][i] = float(rec["k_tilde"]) * u["k_unit"]
        out["sigma_m"][i] = float(rec["sigma_tilde"]) * u["d_c"]
        for name, (src, scale, _) in SI_FIELDS.items():
            v = rec.get(src)
            out[name][i] = math.nan if v is None else float(v) * u[scale]
    return out


__all__ = ["SI_COLUMNS", "has_units", "si_columns"]

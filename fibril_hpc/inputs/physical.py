"""A scene in physical units (SI): the ``physical:`` block of a scene or grid (docs/units.md).

The solver works in dimensionless form (:mod:`fibril_hpc.geometry.scaling`). A scene may instead
give its material and geometry in SI units, plain floats::

    physical:
      E_star: 1.0e6          # Pa, contact modulus of the counter body; or E: and nu:
      dgamma: 0.04           # J/m^2, work of adhesion
      diameter: 10.0e-6      # m, pillar diameter; or pitch:, or both (then phi follows)
      k: 2.0                 # N/m per pillar (optional); or pillar_length: and pillar_modulus:
      sigma: 2.0e-7          # m, standard deviation of the pillar lengths (optional)

From these fibril-hpc derives k~ = k/(E* L) and sigma~ = sigma/d_c (and phi when both the
diameter and the pitch are given), with L the side of the simulated square and d_c the
displacement unit of the discrete footprint (docs/model.md §2-3). What stays with the scene is
its unit system, :class:`Units` (E*, dgamma, the pitch): it is stored with the scene text, left
out of campaign job keys (a job is keyed by its normalised values, so the same physics gives the
same key), and turns every normalised output back into newtons and metres (:meth:`Units.si`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ConfigError, unknown_key
from ..geometry.grid import Lattice
from .ranges import Real

#: keys of the ``physical:`` block and their ranges (SI units)
RANGES = {
    "E_star": Real(0, 1e13, lo_open=True, note=" (Pa)"),
    "E": Real(0, 1e13, lo_open=True, note=" (Pa)"),
    "nu": Real(0, 0.5),
    "dgamma": Real(0, 1e4, lo_open=True, note=" (J/m^2)"),
    "diameter": Real(0, 1, lo_open=True, note=" (m)"),
    "pitch": Real(0, 1, lo_open=True, note=" (m)"),
    "k": Real(0, lo_open=True, note=" (N/m), or inf for rigid pillars"),
    "pillar_length": Real(0, 1, lo_open=True, note=" (m)"),
    "pillar_modulus": Real(0, 1e13, lo_open=True, note=" (Pa)"),
    "sigma": Real(0, 1, note=" (m)"),
}
#: the keys that set k~ and sigma~ (input conveniences: the scene keeps the normalised values)
SPRING_KEYS = ("k", "pillar_length", "pillar_modulus")


@dataclass(frozen=True)
class Units:
    """The unit system of a scene given in physical units: E* (Pa), dgamma (J/m^2), pitch (m).

    Together with the scene's lattice they fix every scale (:meth:`si`).
    """

    E_star: float
    dgamma: float
    pitch: float

    def to_dict(self) -> dict:
        """The block as stored in a scene text (``physical:``)."""
        return {"E_star": self.E_star, "dgamma": self.dgamma, "pitch": self.pitch}

    def si(self, lattice: Lattice) -> dict:
        """The SI value of every unit of a scene on ``lattice`` (docs/units.md).

        L = pitch x grid side / pitch in elements is the side of the simulated square, A0 its
        nominal area (L^2 on the square lattice), and F_c, d_c use the discrete filling ratio,
        exactly as the normalisation of the results does.
        """
        L = self.pitch * lattice.grid_side / lattice.pitch
        area = lattice.area_fraction * L * L
        a0 = math.sqrt(area / math.pi)
        phi = lattice.phi_discrete
        return {
            "E_star": self.E_star, "dgamma": self.dgamma, "pitch": self.pitch,
            "diameter": 2.0 * lattice.radius / lattice.pitch * self.pitch,
            "L": L, "A0": area,
            "F_c": math.sqrt(8.0 * math.pi * phi * self.E_star * self.dgamma * a0**3),
            "d_c": math.sqrt(2.0 * math.pi * phi * self.dgamma * a0 / self.E_star),
            "k_unit": self.E_star * L,
            "phi_discrete": phi,
        }


#: the SI unit of each entry of :meth:`Units.si`
SI_UNITS = {"E_star": "Pa", "dgamma": "J/m^2", "pitch": "m", "diameter": "m", "L": "m",
            "A0": "m^2", "F_c": "N", "d_c": "m", "k_unit": "N/m", "phi_discrete": "1"}


def _cell(lattice: str) -> float:
    """Unit-cell area over pitch^2."""
    return 1.0 if lattice == "square" else math.sqrt(3.0) / 2.0


def parse(block, *, where: str = "") -> dict:
    """The checked values of a ``physical:`` mapping (floats), or a one-line ConfigError."""
    name = where + "physical"
    if not isinstance(block, dict) or not block:
        raise ConfigError(name, block, "a mapping of " + ", ".join(RANGES))
    out = {}
    for key, v in block.items():
        if key not in RANGES:
            raise unknown_key(f"{name}.{key}", v, RANGES)
        out[key] = RANGES[key].check(f"{name}.{key}", v)
    pairs = (("E_star", ("E", "nu")), ("k", ("pillar_length", "pillar_modulus")))
    for one, two in pairs:
        given = [k for k in two if k in out]
        if one in out and given:
            raise ConfigError(f"{name}.{given[0]}", out[given[0]],
                              f"absent when {one} is given (give {one} or {' and '.join(two)})")
        if given and len(given) != 2:
            missing = next(k for k in two if k not in out)
            raise ConfigError(f"{name}.{missing}", None, f"a number (with {given[0]})")
    if "E_star" not in out and "E" not in out:
        raise ConfigError(f"{name}.E_star", None, "a number (Pa), or E and nu")
    if "dgamma" not in out:
        raise ConfigError(f"{name}.dgamma", None, "a number (J/m^2): the work of adhesion")
    if "diameter" not in out and "pitch" not in out:
        raise ConfigError(f"{name}.diameter", None, "a number (m), or pitch, or both")
    if "E" in out:
        out["E_star"] = out.pop("E") / (1.0 - out.pop("nu") ** 2)
    return out


def resolve(values: dict, fields: dict, *, where: str = "") -> tuple[Units, dict]:
    """(unit system, scene fields it sets before the lattice is known: ``phi``) from checked
    ``physical`` values and the scene's other given ``fields`` (phi, lattice)."""
    lattice = fields.get("lattice", "square")
    cell = _cell(lattice if isinstance(lattice, str) else "square")
    set_ = {}
    if "diameter" in values and "pitch" in values:
        if "phi" in fields:
            raise ConfigError(where + "phi", fields["phi"], "absent when physical gives both "
                              "diameter and pitch (phi follows from them)")
        set_["phi"] = math.pi * values["diameter"] ** 2 / (4.0 * cell * values["pitch"] ** 2)
        pitch = values["pitch"]
    elif "pitch" in values:
        pitch = values["pitch"]
    else:
        phi = fields.get("phi", 0.16)
        if isinstance(phi, bool) or not isinstance(phi, (int, float)) or not 0 < phi < 1:
            raise ConfigError(where + "phi", phi, "a number in (0, pi/4)")
        pitch = values["diameter"] * math.sqrt(math.pi / (4.0 * cell * phi))
    return Units(values["E_star"], values["dgamma"], pitch), set_


def spring_k(values: dict, units: Units, phi: float, lattice: str = "square") -> float | None:
    """The pillar spring in N/m the block gives (``k``, or E_p A / l with the nominal diameter),
    or None."""
    if "k" in values:
        return values["k"]
    if "pillar_length" not in values:
        return None
    area = phi * _cell(lattice) * units.pitch**2          # pi D^2 / 4
    return values["pillar_modulus"] * area / values["pillar_length"]


def scene_with_physical(block, fields: dict, build, *, where: str = ""):
    """The scene of a mapping of scene ``fields`` with a ``physical:`` ``block``:
    ``build(fields)`` makes a Scene; k~ and sigma~ (and phi) are derived where the block gives
    them, and the scene keeps the unit system (``physical``)."""
    values = parse(block, where=where)
    for key, sets in (("k", "k_tilde"), ("pillar_length", "k_tilde"), ("sigma", "sigma_tilde")):
        if key in values and sets in fields:
            raise ConfigError(where + sets, fields[sets], f"absent when physical.{key} is given "
                              f"(give {sets} or physical.{key})")
    units, set_ = resolve(values, fields, where=where)
    scene = build({**fields, **set_, "physical": units})
    lattice = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
    derived = normalised(units, lattice, k=spring_k(values, units, scene.phi, scene.lattice),
                         sigma=values.get("sigma"))
    if not derived:
        return scene
    try:
        return scene.replace(**derived)
    except ConfigError as exc:
        src = "sigma" if exc.field.endswith("sigma_tilde") else "k"
        raise ConfigError(f"{where}physical.{src}", values.get(src, exc.value),
                          f"a value giving {exc.field} = {exc.value!r} in range: {exc.allowed}") \
            from None


def grid_values(data: dict, block, base) -> dict:
    """The ``k_tilde`` and ``sigma_tilde`` entries of a campaign grid that gives them in SI: as
    top-level lists ``k`` (N/m) and ``sigma`` (m), converted with the unit system of the base
    scene ``base``, or fixed in ``scene.physical`` (a list of one value)."""
    given = parse(block, where="scene.") if block is not None else {}
    out = {}
    for si_key, key, fixed in (("k", "k_tilde", "k" in given or "pillar_length" in given),
                               ("sigma", "sigma_tilde", "sigma" in given)):
        names = [n for n, there in ((key, key in data), (si_key, si_key in data),
                                    (f"scene.physical.{si_key}", fixed)) if there]
        if len(names) > 1:
            raise ConfigError(names[1], data.get(names[1]), f"absent when {names[0]} is given "
                              "(one of them)")
        if fixed:
            out[key] = getattr(base, key)
        elif si_key in data:
            if base.physical is None:
                raise ConfigError(si_key, data[si_key], f"a list in SI units with scene.physical "
                                  f"(E_star, dgamma, diameter or pitch) to convert it, or {key}")
            items = data[si_key] if isinstance(data[si_key], list) else [data[si_key]]
            values = [RANGES[si_key].check(si_key, v) for v in items]
            lattice = Lattice.of(base.n_side, base.phi, base.elements_per_diameter, base.lattice)
            out[key] = [normalised(base.physical, lattice, **{si_key: v})[key] for v in values]
    return out


class UnitsRange:
    """The range of ``Scene.physical``: None or a :class:`Units` (a stored block's mapping of
    E_star, dgamma and pitch is read back into one)."""

    def allowed(self, plural: bool = False) -> str:  # noqa: ARG002
        """The text of the allowed values."""
        return "a mapping of " + ", ".join(RANGES)

    def check(self, name: str, v):
        """The value as Units (or None), or a one-line ConfigError."""
        if v is None or isinstance(v, Units):
            return v
        if isinstance(v, dict) and set(v) == {"E_star", "dgamma", "pitch"}:
            got = parse(v, where=name.removesuffix("physical"))
            return Units(got["E_star"], got["dgamma"], got["pitch"])
        raise ConfigError(name, v, "Units, or a mapping of E_star, dgamma and pitch")


def normalised(units: Units, lattice: Lattice, *, k=None, sigma=None) -> dict:
    """k~ and sigma~ of a spring ``k`` (N/m) and a length spread ``sigma`` (m), where given."""
    si = units.si(lattice)
    out = {}
    if k is not None:
        out["k_tilde"] = k / si["k_unit"]
    if sigma is not None:
        out["sigma_tilde"] = sigma / si["d_c"]
    return out


__all__ = ["Units", "UnitsRange", "scene_with_physical", "grid_values", "RANGES", "SI_UNITS",
           "SPRING_KEYS", "parse", "resolve", "spring_k", "normalised"]

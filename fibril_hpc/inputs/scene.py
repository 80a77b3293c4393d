"""The physical scene: a frozen, validated dataclass (its solver options: :mod:`.options`).

Every input is dimensionless (see docs/model.md and :mod:`fibril_hpc.geometry.scaling`). One name per
quantity: the YAML key, the dataclass field, the HDF5 attribute and the JSON key are the same.
Construction validates every field and raises :class:`~fibril_hpc.errors.ConfigError` naming the
field and the allowed range; nothing else in the package re-checks user input.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass

from ..errors import ConfigError, unknown_key
from ..geometry import tips as _tips
from ..geometry.grid import LATTICES, MAX_N_SIDE, n_side_of
from ..solve.coarse import MAX_PILLARS
from . import heights as _heights
from . import physical as _physical
from .limits import check_grid
from .options import SOLVER_FIELDS, SolverOptions
from .presets import DEFAULT_PRESET, PRESET_NAMES, preset_values
from .ranges import Choice, Flag, Int, Real, check_fields

#: Pillars per side when neither n_side nor n_pillars is given.
DEFAULT_N_SIDE = 18

#: Largest filling ratio a square lattice of discs can hold (touching discs).
PHI_MAX = math.pi / 4

def _in(default, rng, many: bool = False):
    return dataclasses.field(default=default, metadata={"range": rng, "many": many})


def _lab(default, rng, key: bool = True):
    """A field of the lab scenes (issue 11): stored and part of job keys only when it differs
    from its default, so every scene written before it existed keeps its text and key."""
    return dataclasses.field(default=default, metadata={"range": rng, "many": False,
                                                        "extra": True, "key": key})


@dataclass(frozen=True)
class Scene:
    """A pillar-array pull-off scene in dimensionless inputs (docs/model.md §1-2).

    Attributes
    ----------
    n_side : int
        Pillars per side of the square lattice (n = n_side**2 pillars). Default 18; 1 is a single
        pillar. Range [1, 1000] (the grid and memory checks decide what runs). Or give
        ``n_pillars`` instead (not both).
    phi : float
        Nominal filling ratio n*pi*D**2/(4*A0). Default 0.16. Range (0, pi/4).
    k_tilde : float
        Pillar spring stiffness k/(E* L); ``inf`` for rigid pillars. Default 0.01. Range (0, inf].
    sigma_tilde : float
        Standard deviation of pillar length over d_c. Default 0.5. Range [0, 1e3].
    d_tilde : tuple of float or None
        Preload(s) as maximum indentation d/d_c (d = 0 when the longest pillar first touches).
        Any finite value; below 0 touches nothing.
    F_P : tuple of float or None
        Preload(s) as target force F/F_c (> 0); the solver finds the indentation reaching it.
        Give ``d_tilde`` or ``F_P``, not both; if neither, ``F_P = 4``.
    seed : int
        Seed of the pillar lengths (numpy PCG64, standard normals drawn in row-major pillar
        order). Default 0. Range [0, 2**63 - 1].
    elements_per_diameter : float or None
        Resolution target: elements across a nominal pillar diameter. The pitch becomes the nearest
        odd whole number of elements (pillar centres on element centres), so the realised value
        is reported. ``None``: the preset's (8 for ``default``). Range [2, 128].
    adhesion : bool
        Default true. False gives frictionless, non-adhesive contact (no detachment criterion,
        no unloading branch: it retraces the loading one, so F_A = 0).
    work_of_adhesion : float
        Internal unit of the adhesion energy (E* = L = 1). Normalised results do not depend on it
        (scale invariance, docs/model.md §2); it exists so that tests can prove that. Default 1.
    preset : str
        Accuracy preset, ``fast``, ``default`` or ``accurate`` (:mod:`fibril_hpc.inputs.presets`): fills
        ``elements_per_diameter`` if it is ``None`` and the solver knobs if ``solver`` is ``None``
        or a mapping (whose keys override the preset's). Default ``default`` (package defaults).
    solver : SolverOptions, mapping or None
        Numerical options: a complete :class:`SolverOptions` (used as given), or a mapping of the
        knobs that override the preset's, or ``None`` (the preset's). Stored resolved.

    The fields below describe lab scenes. Each is off at its default, which gives exactly the
    scene above (bitwise), and is stored (and enters a campaign job key) only when it is not at
    its default.

    lattice : str
        ``square`` (default) or ``hexagonal`` (n_side pillars per row, n_side rows, every other
        row shifted by half a pitch; phi is the pillar area over the unit cell s**2 sqrt(3)/2 and
        the pitch s the nearest-neighbour distance, as for the square lattice; docs/model.md §9).
        The discrete filling ratio is reported as ``phi_discrete``.
    heights : str or tuple of float
        Pillar length law, ``gaussian`` (default), ``exponential`` or ``uniform`` (each of
        standard deviation sigma~; :mod:`fibril_hpc.inputs.heights`), or measured lengths: a ``.csv`` or
        ``.npy`` file (read once, the values are kept in the scene) or a list, one per pillar.
    heights_d_c : float or None
        ``None`` (default): measured lengths are in units of d_c; else d_c in the file's unit.
    heights_source : str
        Set when the lengths come from a file: its name and SHA-256 (not part of job keys).
    k_law : str or tuple of float
        Per-pillar stiffness: ``one`` (default: every pillar ``k_tilde``), ``lognormal``
        (k~_n = k_tilde exp(k_spread z_n), z_n standard normal from its own stream of the seed;
        median ``k_tilde``), or per-pillar k~ values: a ``.csv``/``.npy`` file or a list.
    k_spread : float
        Standard deviation of ln k~ of the ``lognormal`` law. Default 0. Range [0, 10].
    k_source : str
        Set when the stiffnesses come from a file: its name and SHA-256 (not part of job keys).
    tip : str
        ``flat`` (default), ``sphere`` (a spherical cap) or ``rounded`` (a flat tip with a
        rounded edge); :mod:`fibril_hpc.geometry.tips`.
    tip_radius : float or None
        Cap radius (>= 0.5) or edge radius (in (0, 0.5]) over the pillar diameter; ``None`` for
        flat tips.
    k_machine : float
        Stiffness of the loading machine, dimensionless like k~ (k_m/(E* L)); ``inf`` (default)
        is displacement control, small values approach force control
        (:mod:`fibril_hpc.path.machine`). Range (0, inf].
    n_pillars : int or None
        The pillar count instead of ``n_side`` (not both): a square number n_side**2, since
        both lattices hold n_side rows of n_side pillars (:func:`~fibril_hpc.geometry.grid.n_side_of`).
        It is resolved to ``n_side`` at once and then reads ``None``, so a scene given by its
        count is the very scene (text, job key) given by its side.
    physical : Units or None
        The unit system of a scene given in physical units (``physical:`` in YAML, which may
        also set k~, sigma~ and phi; :mod:`fibril_hpc.inputs.physical`, docs/units.md): outputs
        then carry newtons and metres too. Not part of job keys.
    """

    n_side: int = _in(None, Int(1, MAX_N_SIDE))     # None: 18, or from n_pillars
    phi: float = _in(0.16, Real(0, PHI_MAX, lo_open=True, hi_open=True))
    k_tilde: float = _in(0.01, Real(0, lo_open=True, note=", or inf for rigid pillars"))
    sigma_tilde: float = _in(0.5, Real(0, 1000))
    d_tilde: tuple | None = _in(None, Real(hi_open=True), many=True)   # finite: no .inf
    F_P: tuple | None = _in(None, Real(0, 1e6, lo_open=True, hi_open=True), many=True)
    seed: int = _in(0, Int(0, 2**63 - 1, hi_text="2**63-1"))
    elements_per_diameter: float | None = _in(None, Real(2, 128))
    adhesion: bool = _in(True, Flag())
    work_of_adhesion: float = _in(1.0, Real(0, 1e12, lo_open=True, hi_open=True))
    preset: str = _in(DEFAULT_PRESET, Choice(PRESET_NAMES))
    solver: SolverOptions | dict | None = None
    lattice: str = _lab("square", Choice(LATTICES))
    heights: str | tuple = _lab("gaussian", _heights.HeightsRange())
    heights_d_c: float | None = _lab(None, Real(0, lo_open=True, hi_open=True,
                                                none="null (lengths in units of d_c)"))
    heights_source: str = _lab("", None, key=False)
    k_law: str | tuple = _lab("one", _heights.KLawRange())
    k_spread: float = _lab(0.0, Real(0, 10))
    k_source: str = _lab("", None, key=False)
    tip: str = _lab("flat", Choice(_tips.TIPS))
    tip_radius: float | None = _lab(None, Real(0, lo_open=True, hi_open=True, none="null"))
    k_machine: float = _lab(math.inf, Real(0, lo_open=True,
                                           note=", or inf (displacement control)"))
    n_pillars: int | None = _lab(None, None, key=False)
    physical: _physical.Units | None = _lab(None, _physical.UnitsRange(), key=False)

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if self.n_pillars is not None:          # the count resolves to n_side (then reads None)
            if self.n_side is not None:
                raise ConfigError("n_pillars", self.n_pillars, "give n_side or n_pillars, not "
                                  f"both (n_side: {self.n_side!r})")
            lattice = self.lattice if self.lattice in LATTICES else "square"
            set_("n_side", n_side_of(self.n_pillars, lattice))
            set_("n_pillars", None)
        elif self.n_side is None:
            set_("n_side", DEFAULT_N_SIDE)
        if _heights.is_file(self.heights):
            values, source = _heights.read_file(self.heights)
            set_("heights", values)
            set_("heights_source", source)
        if _heights.is_file(self.k_law):
            values, source = _heights.read_file(self.k_law, "k_law")
            set_("k_law", values)
            set_("k_source", source)
        for name in ("heights_source", "k_source"):
            if not isinstance(getattr(self, name), str):
                raise ConfigError(name, getattr(self, name), "a text")
        pv = preset_values(Choice(PRESET_NAMES).check("preset", self.preset))
        if self.elements_per_diameter is None:      # the preset fills what is not given
            set_("elements_per_diameter", pv["elements_per_diameter"])
        if self.solver is None or isinstance(self.solver, dict):
            bad = sorted(set(self.solver or {}) - set(SOLVER_FIELDS))
            if bad:
                raise unknown_key(f"solver.{bad[0]}", self.solver[bad[0]], SOLVER_FIELDS,
                                  "a known option")
            set_("solver", SolverOptions(**{**pv["solver"], **(self.solver or {})}))
        if self.d_tilde is not None and self.F_P is not None:
            raise ConfigError("F_P", self.F_P, "give either d_tilde or F_P, not both")
        check_fields(self)
        if self.d_tilde is None and self.F_P is None:
            set_("F_P", (4.0,))
        check_grid(self.n_side, self.phi, self.elements_per_diameter, self.lattice)  # before work
        if not isinstance(self.solver, SolverOptions):
            raise ConfigError("solver", self.solver, "a mapping of solver options")
        if not isinstance(self.heights, str) and len(self.heights) != self.n_side**2:
            raise ConfigError("heights", f"{len(self.heights)} lengths",
                              f"one length per pillar: n_side**2 = {self.n_side**2}")
        if isinstance(self.heights, str) and self.heights_d_c is not None:
            raise ConfigError("heights_d_c", self.heights_d_c,
                              "null unless heights are measured lengths (a file or a list)")
        if not isinstance(self.k_law, str) and len(self.k_law) != self.n_side**2:
            raise ConfigError("k_law", f"{len(self.k_law)} values",
                              f"one stiffness per pillar: n_side**2 = {self.n_side**2}")
        if (self.k_law == "lognormal") != (self.k_spread > 0):
            raise ConfigError("k_spread", self.k_spread,
                              "a number in (0, 10] with k_law: lognormal, else 0")
        if self.k_law != "one" and self.rigid:
            raise ConfigError("k_law", self.k_law, "'one' for rigid pillars (k_tilde: inf)")
        _tips.check_tip(self.tip, self.tip_radius)
        if self.solver.criterion == "footprint" and self.tip != "flat":
            raise ConfigError("solver.criterion", self.solver.criterion,
                              "mesh for tip: " + self.tip + " (the footprint calibration is "
                              "defined by a flat pillar)")
        if self.solver.preconditioner in ("two_level", "moments"):
            if self.n_side**2 > MAX_PILLARS:
                raise ConfigError("solver.preconditioner", self.solver.preconditioner,
                                  f"auto, block or diagonal for {self.n_side**2} pillars "
                                  f"({self.solver.preconditioner}: at most {MAX_PILLARS})")

    @property
    def rigid(self) -> bool:
        """Whether the pillars are rigid (k~ = inf)."""
        return math.isinf(self.k_tilde)

    @property
    def preload_kind(self) -> str:
        """``"d_tilde"`` or ``"F_P"``."""
        return "d_tilde" if self.d_tilde is not None else "F_P"

    @property
    def preloads(self) -> tuple:
        """The preload values (``d_tilde`` or ``F_P``, ascending)."""
        return self.d_tilde if self.d_tilde is not None else self.F_P

    def replace(self, **changes) -> Scene:
        """A copy with fields changed (``d_tilde``/``F_P`` swap cleanly)."""
        if "d_tilde" in changes and "F_P" not in changes:
            changes["F_P"] = None
        if "F_P" in changes and "d_tilde" not in changes:
            changes["d_tilde"] = None
        if changes.get("n_pillars") is not None and "n_side" not in changes:
            changes["n_side"] = None                # the count replaces the side
        return dataclasses.replace(self, **changes)

    def with_checked_axes(self, **changes) -> Scene:
        """A copy with campaign axes changed (``k_tilde``, ``sigma_tilde``, ``seed``, ``F_P``,
        ``d_tilde``) *without* validating again: for a campaign's loading paths, whose values
        were each validated with this scene already (a Scene per path made the enumeration of
        a large grid take minutes). Any other field is a ValueError; ``replace`` validates."""
        bad = set(changes) - {"k_tilde", "sigma_tilde", "seed", "F_P", "d_tilde"}
        if bad:
            raise ValueError(f"with_checked_axes changes the campaign axes only, not {sorted(bad)}")
        if "d_tilde" in changes and "F_P" not in changes:
            changes["F_P"] = None
        if "F_P" in changes and "d_tilde" not in changes:
            changes["d_tilde"] = None
        out = copy.copy(self)
        for k, v in changes.items():
            object.__setattr__(out, k, v)
        return out

    def to_dict(self) -> dict:
        """Plain, YAML/JSON-ready dict of every resolved field (``inf`` kept as a float)."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
               if f.name != "solver" and not f.metadata.get("extra")}
        for key in ("d_tilde", "F_P"):
            out[key] = None if out[key] is None else list(out[key])
        out["solver"] = dataclasses.asdict(self.solver)
        filled = preset_values(self.preset)["solver"]
        for f in dataclasses.fields(SolverOptions):     # new options: only off their default
            if f.metadata.get("extra") and out["solver"][f.name] == f.default \
                    and filled.get(f.name, f.default) == f.default:
                del out["solver"][f.name]
        for f in dataclasses.fields(self):      # lab fields: only when not at their default
            if f.metadata.get("extra") and getattr(self, f.name) != f.default:
                v = getattr(self, f.name)
                out[f.name] = (list(v) if isinstance(v, tuple) else
                               v.to_dict() if isinstance(v, _physical.Units) else v)
        return out


SCENE_FIELDS = tuple(f.name for f in dataclasses.fields(Scene))


def scene_from_dict(data: dict, *, where: str = "") -> Scene:
    """Build a :class:`Scene` from a plain mapping, rejecting unknown keys.

    ``where`` prefixes field names in error messages (e.g. ``"scene."``).
    """
    if not isinstance(data, dict):
        raise ConfigError(where.rstrip(".") or "scene", data, "a mapping of scene fields")
    unknown = sorted(set(data) - set(SCENE_FIELDS))
    if unknown:
        raise unknown_key(where + str(unknown[0]), data[unknown[0]], SCENE_FIELDS, "a known field")
    kwargs = dict(data)
    solver = kwargs.pop("solver", None)     # a mapping overrides the preset's knobs key by key
    if solver is not None and not isinstance(solver, (dict, SolverOptions)):
        raise ConfigError(where + "solver", solver, "a mapping of solver options")
    if isinstance(kwargs.get("physical"), dict) and \
            set(kwargs["physical"]) != {"E_star", "dgamma", "pitch"}:     # not a stored block
        return _physical.scene_with_physical(kwargs.pop("physical"), kwargs,
                                             lambda kw: _build(kw, solver, where), where=where)
    return _build(kwargs, solver, where)


def _build(kwargs: dict, solver, where: str) -> Scene:
    try:
        return Scene(**kwargs, solver=solver)
    except ConfigError as exc:
        raise ConfigError(where + exc.field, exc.value, exc.allowed) from None

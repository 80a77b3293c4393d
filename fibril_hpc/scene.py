"""The physical scene and the solver options: frozen, validated dataclasses.

Every input is dimensionless (see ``docs``/README and :mod:`fibril_hpc.scaling`). One name per
quantity: the YAML key, the dataclass field, the HDF5 attribute and the JSON key are the same.
Construction validates every field and raises :class:`~fibril_hpc.errors.ConfigError` naming the
field and the allowed range; nothing else in the package re-checks user input.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

from .errors import ConfigError

#: Largest filling ratio a square lattice of discs can hold (touching discs).
PHI_MAX = math.pi / 4


def _is_int(v):
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def _is_real(v):
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _as_float(name, v, allowed):
    if isinstance(v, str):
        s = v.strip().lower()
        if s in ("inf", "+inf", "infinity", ".inf"):
            return math.inf
        try:
            v = float(s)
        except ValueError:
            raise ConfigError(name, v, allowed) from None
    if not _is_real(v):
        raise ConfigError(name, v, allowed)
    v = float(v)
    if math.isnan(v):
        raise ConfigError(name, v, allowed)
    return v


def _as_int(name, v, lo, hi, allowed):
    if not _is_int(v) or not (lo <= v <= hi):
        raise ConfigError(name, v, allowed)
    return int(v)


def _as_list(name, v, check, allowed):
    if v is None:
        return None
    items = list(v) if isinstance(v, (list, tuple)) else [v]
    if not items:
        raise ConfigError(name, v, allowed)
    out = []
    for item in items:
        x = _as_float(name, item, allowed)
        if not check(x):
            raise ConfigError(name, item, allowed)
        out.append(x)
    if len(set(out)) != len(out):
        raise ConfigError(name, v, allowed + " (no duplicates)")
    return tuple(sorted(out))


@dataclass(frozen=True)
class SolverOptions:
    """Numerical knobs; every one has a documented default.

    Attributes
    ----------
    cg_tol : float
        Relative tolerance of the constrained CG, measured against the half-space part of the
        operator: ``||r|| <= cg_tol * ||K p||`` (physics.md §4: stays accurate for soft springs).
        Range (0, 1e-2]. Default 1e-8.
    cg_maxiter : int
        Iteration cap of one CG solve; exceeding it is a :class:`NoConvergenceError`. Default 5000.
    relax_tol : float
        CG tolerance of the intermediate passes of a detachment/attachment cascade at fixed d; a
        set that is stable at it is confirmed at ``cg_tol`` before the cascade ends. Setting it
        equal to ``cg_tol`` (or below) solves every pass fully. Range (0, 1e-2]. Default 1e-5.
    event_merge : float
        While unloading, contact-set events whose plate displacement lies within this distance (in
        units of d_c) after the first one are handled as one batch: the path moves to the last of
        them before the set is relaxed. The force just before the first event is always recorded
        exactly. Range [0, 1]. Default 1e-4.
    load_event_merge : float
        The same while loading, where it hardly changes F_A (the set at the preload is what
        matters) but saves many solves. Range [0, 1]. Default 1e-2.
    max_events : int
        Cap on contact-set events along one curve (a runaway guard). Default 1_000_000.
    max_wall_s : float or None
        Wall-time cap of one simulation in seconds (``None``: none); exceeding it fails the
        simulation with that reason (campaigns use it to turn a runaway job into a failed record).
    preconditioner : str
        ``"auto"`` (default: exact per-pillar block Jacobi where all pillars share one footprint,
        else the diagonal one), ``"block"`` or ``"diagonal"`` (c0 I + alpha B B^T).
    detach_policy : str
        ``"all"`` (reference: every supercritical element detaches in one pass) or ``"worst"``
        (only the most supercritical element of each pillar per pass). Default ``"all"``.
    fft_backend : str
        ``"pyfftw"`` (default) or ``"numpy"`` (reference/comparison).
    fft_threads : int or None
        Threads of the FFT; ``None`` (default) means one. Measured on the 2-core machine: the
        default 18 x 18 scene took 61 s with one FFTW thread and 204 s with two (the row-pruned
        pair is many short batched 1-D transforms, where FFTW's threads cost more than they
        save), so more threads are opt-in (e.g. ``fibril-campaign --fft-threads`` from Slurm's
        cpus-per-task). MPI campaigns run one single-threaded job per rank. The numba kernels
        are serial; BLAS (block preconditioner) follows ``OPENBLAS_NUM_THREADS``.
    fft_planner : str
        FFTW planning effort: ``"estimate"`` (default, instant), ``"measure"`` or ``"patient"``.
    cascade : str
        How a detachment/attachment cascade at fixed d is solved (does not define the result:
        both reach the same fixed point, tested): ``"local"`` (default: the pillars whose set
        changed are solved directly with the rest of the grid held, then one global solve
        confirms) or ``"global"`` (the reference: a global solve per pass).
    """

    cg_tol: float = 1e-8
    cg_maxiter: int = 5000
    relax_tol: float = 1e-5
    event_merge: float = 1e-4
    load_event_merge: float = 1e-2
    max_events: int = 1_000_000
    max_wall_s: float | None = None
    preconditioner: str = "auto"
    detach_policy: str = "all"
    fft_backend: str = "pyfftw"
    fft_threads: int | None = None
    fft_planner: str = "estimate"
    cascade: str = "local"

    def __post_init__(self):
        tol = _as_float("solver.cg_tol", self.cg_tol, "a number in (0, 1e-2]")
        if not (0 < tol <= 1e-2):
            raise ConfigError("solver.cg_tol", self.cg_tol, "a number in (0, 1e-2]")
        object.__setattr__(self, "cg_tol", tol)
        rt = _as_float("solver.relax_tol", self.relax_tol, "a number in (0, 1e-2]")
        if not (0 < rt <= 1e-2):
            raise ConfigError("solver.relax_tol", self.relax_tol, "a number in (0, 1e-2]")
        object.__setattr__(self, "relax_tol", rt)
        object.__setattr__(self, "cg_maxiter", _as_int(
            "solver.cg_maxiter", self.cg_maxiter, 1, 10**7, "an integer in [1, 1e7]"))
        for name in ("event_merge", "load_event_merge"):
            em = _as_float("solver." + name, getattr(self, name), "a number in [0, 1]")
            if not (0 <= em <= 1):
                raise ConfigError("solver." + name, getattr(self, name), "a number in [0, 1]")
            object.__setattr__(self, name, em)
        object.__setattr__(self, "max_events", _as_int(
            "solver.max_events", self.max_events, 1, 10**9, "an integer in [1, 1e9]"))
        if self.max_wall_s is not None:
            w = _as_float("solver.max_wall_s", self.max_wall_s, "null or a number > 0")
            if not w > 0:
                raise ConfigError("solver.max_wall_s", self.max_wall_s, "null or a number > 0")
            object.__setattr__(self, "max_wall_s", w)
        if self.preconditioner not in ("auto", "block", "diagonal"):
            raise ConfigError("solver.preconditioner", self.preconditioner,
                              "'auto', 'block' or 'diagonal'")
        if self.detach_policy not in ("all", "worst"):
            raise ConfigError("solver.detach_policy", self.detach_policy, "'all' or 'worst'")
        if self.fft_backend not in ("pyfftw", "numpy"):
            raise ConfigError("solver.fft_backend", self.fft_backend, "'pyfftw' or 'numpy'")
        if self.fft_threads is not None:
            _as_int("solver.fft_threads", self.fft_threads, 1, 1024,
                    "null (all CPUs of this process) or an integer in [1, 1024]")
        if self.fft_planner not in ("estimate", "measure", "patient"):
            raise ConfigError("solver.fft_planner", self.fft_planner,
                              "'estimate', 'measure' or 'patient'")
        if self.cascade not in ("local", "global"):
            raise ConfigError("solver.cascade", self.cascade, "'local' or 'global'")

    @property
    def threads(self) -> int:
        """Resolved FFT thread count: ``fft_threads``, else 1 (see the attribute's docs)."""
        return 1 if self.fft_threads is None else self.fft_threads

    def replace(self, **changes) -> "SolverOptions":
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class Scene:
    """A pillar-array pull-off scene in dimensionless inputs (physics.md §1-2).

    Attributes
    ----------
    n_side : int
        Pillars per side of the square lattice (n = n_side**2 pillars). Default 18; 1 is a single
        pillar. Range [1, 200].
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
        (scale invariance, physics.md §2); it exists so that tests can prove that. Default 1.
    preset : str
        Accuracy preset, ``fast``, ``default`` or ``accurate`` (:mod:`fibril_hpc.presets`): fills
        ``elements_per_diameter`` if it is ``None`` and the solver knobs if ``solver`` is ``None``
        or a mapping (whose keys override the preset's). Default ``default`` (package defaults).
    solver : SolverOptions, mapping or None
        Numerical options: a complete :class:`SolverOptions` (used as given), or a mapping of the
        knobs that override the preset's, or ``None`` (the preset's). Stored resolved.
    """

    n_side: int = 18
    phi: float = 0.16
    k_tilde: float = 0.01
    sigma_tilde: float = 0.5
    d_tilde: tuple | None = None
    F_P: tuple | None = None
    seed: int = 0
    elements_per_diameter: float | None = None
    adhesion: bool = True
    work_of_adhesion: float = 1.0
    preset: str = "default"
    solver: SolverOptions | dict | None = None

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        from .presets import check_name, preset_values
        pv = preset_values(check_name(self.preset))     # preset fills what is not given
        if self.elements_per_diameter is None:
            set_("elements_per_diameter", pv["elements_per_diameter"])
        if self.solver is None or isinstance(self.solver, dict):
            bad = sorted(set(self.solver or {}) - set(SOLVER_FIELDS))
            if bad:
                raise ConfigError(f"solver.{bad[0]}", self.solver[bad[0]],
                                  "a known option: " + ", ".join(SOLVER_FIELDS))
            set_("solver", SolverOptions(**{**pv["solver"], **(self.solver or {})}))
        set_("n_side", _as_int("n_side", self.n_side, 1, 200, "an integer in [1, 200]"))
        phi = _as_float("phi", self.phi, "a number in (0, 0.785)")
        if not (0 < phi < PHI_MAX):
            raise ConfigError("phi", self.phi, "a number in (0, 0.785)")
        set_("phi", phi)
        k = _as_float("k_tilde", self.k_tilde, "a number > 0, or inf for rigid pillars")
        if not k > 0:
            raise ConfigError("k_tilde", self.k_tilde, "a number > 0, or inf for rigid pillars")
        set_("k_tilde", k)
        s = _as_float("sigma_tilde", self.sigma_tilde, "a number in [0, 1000]")
        if not (0 <= s <= 1000):
            raise ConfigError("sigma_tilde", self.sigma_tilde, "a number in [0, 1000]")
        set_("sigma_tilde", s)
        if self.d_tilde is not None and self.F_P is not None:
            raise ConfigError("F_P", self.F_P, "give either d_tilde or F_P, not both")
        set_("d_tilde", _as_list("d_tilde", self.d_tilde, math.isfinite,
                                 "a finite number or a non-empty list of them"))
        set_("F_P", _as_list("F_P", self.F_P, lambda x: 0 < x < 1e6,
                             "a number in (0, 1e6) or a non-empty list of them"))
        if self.d_tilde is None and self.F_P is None:
            set_("F_P", (4.0,))
        set_("seed", _as_int("seed", self.seed, 0, 2**63 - 1, "an integer in [0, 2**63-1]"))
        e = _as_float("elements_per_diameter", self.elements_per_diameter,
                      "a number in [2, 128]")
        if not (2 <= e <= 128):
            raise ConfigError("elements_per_diameter", self.elements_per_diameter,
                              "a number in [2, 128]")
        set_("elements_per_diameter", e)
        if not isinstance(self.adhesion, bool):
            raise ConfigError("adhesion", self.adhesion, "true or false")
        w = _as_float("work_of_adhesion", self.work_of_adhesion, "a number in (0, 1e12)")
        if not (0 < w < 1e12):
            raise ConfigError("work_of_adhesion", self.work_of_adhesion, "a number in (0, 1e12)")
        set_("work_of_adhesion", w)
        if not isinstance(self.solver, SolverOptions):
            raise ConfigError("solver", self.solver, "a mapping of solver options")

    @property
    def rigid(self) -> bool:
        return math.isinf(self.k_tilde)

    @property
    def preload_kind(self) -> str:
        """``"d_tilde"`` or ``"F_P"``."""
        return "d_tilde" if self.d_tilde is not None else "F_P"

    @property
    def preloads(self) -> tuple:
        return self.d_tilde if self.d_tilde is not None else self.F_P

    def replace(self, **changes) -> "Scene":
        """A copy with fields changed (``d_tilde``/``F_P`` swap cleanly)."""
        if "d_tilde" in changes and "F_P" not in changes:
            changes["F_P"] = None
        if "F_P" in changes and "d_tilde" not in changes:
            changes["d_tilde"] = None
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """Plain, YAML/JSON-ready dict of every resolved field (``inf`` kept as a float)."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "solver"}
        for key in ("d_tilde", "F_P"):
            out[key] = None if out[key] is None else list(out[key])
        out["solver"] = dataclasses.asdict(self.solver)
        return out


SCENE_FIELDS = tuple(f.name for f in dataclasses.fields(Scene))
SOLVER_FIELDS = tuple(f.name for f in dataclasses.fields(SolverOptions))


def scene_from_dict(data: dict, *, where: str = "") -> Scene:
    """Build a :class:`Scene` from a plain mapping, rejecting unknown keys.

    ``where`` prefixes field names in error messages (e.g. ``"scene."``).
    """
    if not isinstance(data, dict):
        raise ConfigError(where.rstrip(".") or "scene", data, "a mapping of scene fields")
    unknown = sorted(set(data) - set(SCENE_FIELDS))
    if unknown:
        raise ConfigError(where + str(unknown[0]), data[unknown[0]],
                          "a known field: " + ", ".join(SCENE_FIELDS))
    kwargs = dict(data)
    solver = kwargs.pop("solver", None)     # a mapping overrides the preset's knobs key by key
    if solver is not None and not isinstance(solver, (dict, SolverOptions)):
        raise ConfigError(where + "solver", solver, "a mapping of solver options")
    try:
        return Scene(**kwargs, solver=solver)
    except ConfigError as exc:
        raise ConfigError(where + exc.field, exc.value, exc.allowed) from None

"""Wires the operator and the physics a scene calls for, once (design habit: physics is chosen
when the model is built, not asked in every iteration).

* rigid pillars (k = inf): alpha = 0, the kernels skip every spring sum and the tip elongation is 0;
* no adhesion: sigma_c = 0 (an element leaves contact as soon as it would carry tension) and the
  load-path driver computes no unloading branch (frictionless contact retraces its loading path);
* only elements inside pillar footprints exist for the solver: the rest are never iterated over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .elastic.halfspace import HalfSpace
from .errors import ConfigError
from .geometry.grid import Geometry, Lattice, PillarGrid, build_pillar_grid
from .geometry.scaling import Scaling, critical_stress
from .geometry.tips import tip_offsets
from .inputs.heights import pillar_stiffness, setbacks
from .inputs.options import SolverOptions
from .inputs.scene import Scene
from .solve.farfield import MultipoleField
from .solve.solver import ConstrainedCG


@dataclass
class Model:
    """Everything that is built once per scene: operator (plans, buffers), solver, physics."""

    geometry: Geometry
    operator: HalfSpace | MultipoleField     # the latter under solver.far_field: multipole
    solver: ConstrainedCG
    k: float | np.ndarray    # spring stiffness (internal units), inf for rigid; one per pillar
    #                          only when the scene asks for per-pillar stiffnesses
    sigma_c: float           # detachment stress (0 without adhesion)
    adhesion: bool
    scaling: Scaling
    options: SolverOptions
    grid: PillarGrid | None = None
    #: sigma_c over the mesh criterion's sqrt(E* dgamma/(kappa h)) (``solver.criterion``;
    #: :mod:`fibril_hpc.path.criterion`); 1.0 for the mesh criterion
    criterion_factor: float = 1.0

    @property
    def rigid(self) -> bool:
        """Whether the pillars are rigid (k = inf)."""
        return not self.per_pillar and math.isinf(self.k)

    @property
    def per_pillar(self) -> bool:
        """Whether every pillar has its own stiffness (``k`` is an array)."""
        return isinstance(self.k, np.ndarray)

    @property
    def fft_pairs(self) -> int:
        """FFT pairs executed by the operator so far."""
        return self.operator.n_pairs


def build_model(geometry: Geometry, *, k: float, adhesion: bool, work_of_adhesion: float,
                scaling: Scaling, options: SolverOptions, grid: PillarGrid | None = None,
                operator: HalfSpace | None = None, m: int | None = None,
                criterion_factor: float = 1.0) -> Model:
    """Build a model on any geometry (pillars, or a test-only indenter shape).

    ``operator`` reuses an existing :class:`HalfSpace` (FFT plans, buffers, kernel transform); it
    must have been built on a geometry with the same grid and active elements (heights may differ).
    ``m`` sets the padded FFT size of a new operator (default:
    :func:`~fibril_hpc.elastic.greens.padded_size`).
    ``criterion_factor`` scales the mesh criterion's sigma_c (:mod:`fibril_hpc.path.criterion`).
    """
    if operator is None:
        op = HalfSpace.from_options(geometry, options, m=m)
    else:
        g0 = operator.geometry
        if not (g0.n == geometry.n and np.array_equal(g0.iy, geometry.iy)
                and np.array_equal(g0.ix, geometry.ix) and np.array_equal(g0.starts, geometry.starts)):
            raise ValueError("the operator was built on a different grid")
        op = operator
    if options.far_field == "multipole":
        try:
            op = MultipoleField(op, options.far_refresh)
        except ValueError as exc:
            raise ConfigError("solver.far_field", options.far_field,
                              f"'exact' ({exc})") from None
    if isinstance(k, np.ndarray):
        alpha = geometry.h**2 / k              # one spring coefficient per pillar
    else:
        alpha = 0.0 if math.isinf(k) else geometry.h**2 / k
    solver = ConstrainedCG(op, alpha, options.cg_tol, options.cg_maxiter,
                           preconditioner=options.preconditioner)
    sigma_c = critical_stress(geometry.h, work_of_adhesion) if adhesion else 0.0
    if criterion_factor != 1.0:     # the mesh criterion keeps today's sigma_c bit for bit
        sigma_c *= criterion_factor
    return Model(geometry=geometry, operator=op, solver=solver, k=k, sigma_c=sigma_c,
                 adhesion=adhesion, scaling=scaling, options=options, grid=grid,
                 criterion_factor=criterion_factor)


def scene_lattice(scene: Scene) -> Lattice:
    """The lattice step of a scene (see :class:`~fibril_hpc.geometry.grid.Lattice`)."""
    return Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)


def scene_scaling(scene: Scene) -> tuple[Scaling, int, tuple]:
    """(scaling, pitch, footprint) of a scene, from its lattice step."""
    lat = scene_lattice(scene)
    return lat.scaling(scene.work_of_adhesion), lat.pitch, lat.footprint


def build_scene_model(scene: Scene, operators: OperatorCache | None = None, *,
                      m: int | None = None, calibrate=None) -> Model:
    """Discretise a pillar scene and build its model (reusing a cached operator, and a cached
    criterion factor, if given; ``m`` sets the padded FFT size of a new operator).

    ``calibrate(scene) -> float`` computes the detachment criterion's factor
    (:func:`fibril_hpc.api.calibrate`, which :func:`fibril_hpc.simulate` passes). Only a scene
    with ``solver.criterion: footprint`` and adhesion needs it; without it such a scene is a
    ValueError.
    """
    lat = scene_lattice(scene)
    scaling = lat.scaling(scene.work_of_adhesion)
    sigma = scene.sigma_tilde * scaling.d_c
    # the default scene (gaussian heights, flat tips) takes the grid's own draw: no extra arrays
    heights = None if scene.heights == "gaussian" else setbacks(
        scene.heights, scene.heights_d_c, scene.n_side**2, sigma, scene.seed, scaling.d_c)
    offsets = tip_offsets(scene.tip, scene.tip_radius, lat.footprint, lat.radius,
                          1.0 / lat.grid_side)
    grid = build_pillar_grid(scene.n_side, scene.phi, scene.elements_per_diameter, sigma,
                             scene.seed, lattice=scene.lattice, heights=heights,
                             tip_offsets=offsets)
    op = None if operators is None else operators.get(scene, grid.geometry)
    k_tilde = pillar_stiffness(scene.k_tilde, scene.k_law, scene.k_spread, scene.n_side**2,
                               scene.seed)
    if scene.solver.criterion == "mesh" or not scene.adhesion:
        factor = 1.0
    elif calibrate is None:
        raise ValueError("the footprint criterion needs calibrate= (fibril_hpc.simulate passes it)")
    else:
        factor = calibrate(scene) if operators is None else operators.factor(scene, calibrate)
    return build_model(grid.geometry, k=scaling.k(k_tilde), adhesion=scene.adhesion,
                       work_of_adhesion=scene.work_of_adhesion, scaling=scaling,
                       options=scene.solver, grid=grid, operator=op, m=m,
                       criterion_factor=factor)


class OperatorCache:
    """Half-space operators (FFT plans + buffers + kernel transform) kept per grid, so that the
    jobs of a campaign on one grid plan once. Owned by its user (e.g. one campaign worker);
    ``maxsize`` bounds the memory it holds (least recently used grids are dropped)."""

    def __init__(self, maxsize: int = 2):
        self.maxsize = int(maxsize)
        self._ops: dict = {}
        self._factors: dict = {}

    def factor(self, scene: Scene, compute) -> float:
        """The detachment criterion's factor of ``scene`` (``compute(scene)``, once per lattice
        step and accuracy options: it depends on the footprint and the solver's tolerances, not
        on the number of pillars, so the grids of a campaign that differ only in ``n_side``
        share it)."""
        if scene.solver.criterion == "mesh" or not scene.adhesion:
            return 1.0
        k = (scene.phi, scene_lattice(scene).pitch, scene.lattice,
             tuple(getattr(scene.solver, n) for n in SolverOptions.of_kind("accuracy")))
        if k not in self._factors:
            self._factors[k] = compute(scene)
        return self._factors[k]

    @staticmethod
    def key(scene: Scene) -> tuple:
        """The grid (lattice step) and the options an operator depends on
        (``SolverOptions.operator_settings``)."""
        return (scene.n_side, scene.phi, scene_lattice(scene).pitch, scene.lattice,
                *sorted(scene.solver.operator_settings().items()))

    def get(self, scene: Scene, geometry: Geometry) -> HalfSpace:
        """The operator for ``scene``'s grid: cached, or built on ``geometry`` and cached."""
        k = self.key(scene)
        op = self._ops.pop(k, None)
        if op is None:
            op = HalfSpace.from_options(geometry, scene.solver)
        self._ops[k] = op
        while len(self._ops) > self.maxsize:
            self._ops.pop(next(iter(self._ops)))
        return op

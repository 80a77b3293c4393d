"""The detachment criterion's constant (``SolverOptions.criterion``; docs/model.md §5).

``mesh`` (default): an attached element of side h detaches when its tension reaches
sigma_c = sqrt(E* dgamma / (kappa h)), kappa = 0.473201
(:func:`~fibril_hpc.geometry.scaling.critical_stress`).
The constant is exact for a straight crack front along a row of square elements; on the coarse
discs of a pillar footprint the pull-off of one isolated pillar misses Kendall's by a few per cent,
and the error jumps with the resolution (a staircase, benchmarks/NOTES.md).

``footprint``: sigma_c = c sqrt(E* dgamma / (kappa h)), with one factor c per pillar footprint (in
elements) chosen so that ONE isolated rigid flat pillar of that footprint, solved by this solver
with the scene's numerical options, pulls off at exactly Kendall's force for the footprint's area,
sqrt(8 pi E* dgamma a^3) with pi a^2 = (elements in the footprint) h^2.

Why one solve and a ratio suffice: a rigid flat pillar is in full contact at any indentation > 0,
and on the way back everything it does (pressures, gaps, which element leaves next) is linear in
(d, sigma_c) jointly; scaling sigma_c by c scales the whole unloading branch, F_A included, by c
(the event batching distance ``event_merge`` is the only part that does not scale; it moves F_A by
far less than the solver tolerance, tested). So c = F_Kendall / F_A(mesh criterion).

The calibration solve is the caller's: :func:`footprint_factor` takes the ``simulate`` function
(:func:`fibril_hpc.simulate` passes itself), so that this layer, below the model and the API,
never imports them.

The factor depends on the footprint in elements only (the half-space has no length scale of its
own), not on h, on the brush around the pillar, or on its spring: it is computed on a one-pillar
grid of the scene's lattice and resolution. It tends to one as the footprint is refined (both
criteria have the same limit h -> 0). Shaped tips (``tip: sphere | rounded``) are refused: their
contact is not the footprint, and a flat pillar defines the calibration.
"""

from __future__ import annotations

import math

from ..elastic.analytic import single_pillar_F_A
from ..errors import NoConvergenceError


def calibration_scene(scene):
    """The one-pillar scene that calibrates ``scene``'s footprint: same lattice, resolution and
    numerical options, a rigid flat pillar preloaded into full contact, the mesh criterion (a
    scene of ``scene``'s own class, every other field at its default)."""
    return type(scene)(n_side=1, phi=scene.phi, k_tilde=math.inf, sigma_tilde=0.0, d_tilde=(1.0,),
                 elements_per_diameter=scene.elements_per_diameter, lattice=scene.lattice,
                 preset=scene.preset, solver=scene.solver.replace(criterion="mesh"))


def footprint_factor(scene, simulate) -> float:
    """c = F_Kendall / F_A of the calibration pillar (1.0 for the ``mesh`` criterion or a scene
    without adhesion), the pillar solved by ``simulate`` (scene -> result, i.e.
    :func:`fibril_hpc.simulate`). Raises :class:`~fibril_hpc.errors.NoConvergenceError` if its
    solve fails."""
    if scene.solver.criterion == "mesh" or not scene.adhesion:
        return 1.0
    one = calibration_scene(scene)
    r = simulate(one)
    res = r.main
    if res.status != "ok" or not (res.F_A > 0 and math.isfinite(res.F_A)):
        raise NoConvergenceError(f"footprint calibration: the one-pillar solve failed "
                                 f"({res.message or res.status})")
    return single_pillar_F_A(r.discretisation["phi_discrete"]) / res.F_A


__all__ = ["calibration_scene", "footprint_factor"]

"""Which preconditioner a scene gets: :func:`make_preconditioner` and the ``auto`` rule.

The factory sits above every level it can build (:mod:`.precond`'s diagonal and block Jacobi,
:mod:`.coarse`'s force level, :mod:`.moments`' force-and-tilts level), so that the levels build
on each other downwards and nothing below imports the factory.
"""

from __future__ import annotations

import numpy as np

from .coarse import MAX_PILLARS, TwoLevelPreconditioner
from .moments import MomentTwoLevelPreconditioner
from .precond import BlockPreconditioner, DiagonalPreconditioner, uniform_footprint

#: ``auto`` picks the moment coarse level over the force one where an FFT pair (~ M^2 log2 M for
#: an M x M transform) costs at least this many times the moment level's dense work per CG
#: iteration and per set change (~ (3 n_pillars)^2, an upper bound: F^-1 is kept on the pillars
#: in contact only). Measured with the compact F^-1 and the moment trust estimate
#: (benchmarks/NOTES.md, "Moment coarse level" and §22; CPU of the force level over the
#: moment level): 0.79x at a ratio of 2.2 (the `fast` 18 x 18 scene), 1.02x at 4 (the default
#: scene, 1.56x fewer FFT pairs), 0.96-1.03x at 8-17 (12 x 12 and 8 x 8 brushes, before), 1.20x
#: at 18 (`accurate` on 18 x 18, before); 1.17-1.56x fewer FFT pairs everywhere
MOMENTS_RATIO = 3.0


def prefers_moments(fft_size: int, n_pillars: int) -> bool:
    """Whether ``auto`` takes the moment coarse level for this transform size and pillar count
    (see :data:`MOMENTS_RATIO`)."""
    return fft_size * fft_size * np.log2(max(fft_size, 2)) >= MOMENTS_RATIO * (3 * n_pillars)**2


def make_preconditioner(geometry, alpha: float, c0: float, kind: str = "auto",
                        max_block: int = 1024, fft_size: int | None = None):
    """The CG preconditioner of ``kind``.

    ``"auto"``: a two-level one where all pillars share one footprint of at most ``max_block``
    elements and there are at most ``coarse.MAX_PILLARS`` pillars: ``"moments"`` (three coarse
    unknowns per pillar, :mod:`fibril_hpc.solve.moments`) where the FFT of side ``fft_size`` is dear
    enough to repay its dense work (:func:`prefers_moments`), else ``"two_level"`` (one force
    per pillar, :mod:`fibril_hpc.solve.coarse`); ``"block"`` where only the pillar count is too large,
    else ``"diagonal"``. An explicit ``"block"``, ``"two_level"`` or ``"moments"`` the geometry
    does not allow is a ValueError.
    """
    if kind == "diagonal":
        return DiagonalPreconditioner(geometry, alpha, c0)
    m = uniform_footprint(geometry)
    if m is None or m > max_block:
        if kind != "auto":
            raise ValueError(f"{kind} preconditioner needs groups with one shared footprint of "
                             f"at most {max_block} elements")
        return DiagonalPreconditioner(geometry, alpha, c0)
    if kind == "block":
        return BlockPreconditioner(geometry, alpha)
    if geometry.n_groups <= MAX_PILLARS:
        if kind == "moments" or (kind == "auto" and fft_size is not None
                                 and prefers_moments(fft_size, geometry.n_groups)):
            return MomentTwoLevelPreconditioner(geometry, alpha)
        return TwoLevelPreconditioner(geometry, alpha)
    if kind in ("two_level", "moments"):            # Scene refuses this first, in one line
        raise ValueError(f"{kind} preconditioner needs at most {MAX_PILLARS} pillars "
                         f"(got {geometry.n_groups})")
    return BlockPreconditioner(geometry, alpha)        # "auto" on a big brush

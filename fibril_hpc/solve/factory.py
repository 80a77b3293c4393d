"""Which preconditioner a scene gets: :func:`make_preconditioner` and the ``auto`` rule.

The factory sits above every level it can build (:mod:`.precond`'s diagonal and block Jacobi,
:mod:`.coarse`'s force level, :mod:`.moments`' force-and-tilts level with its inverse kept
dense, :mod:`.lattice`'s same level applied by FFT on the pillar lattice), so that the levels build
on each other downwards and nothing below imports the factory.
"""

from __future__ import annotations

import numpy as np

from .coarse import MAX_PILLARS, TwoLevelPreconditioner
from .lattice import LatticeMomentPreconditioner, PillarLattice
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


#: ``auto`` takes the lattice level (:mod:`fibril_hpc.solve.lattice`) from this many pillars on,
#: and below it wherever the moment level would repay its work (:func:`prefers_moments`).
#: Measured side by side (benchmarks/NOTES.md, "The lattice coarse level, and brushes to
#: 100 x 100"; CPU of the lattice level over the level ``auto`` took before it): `default`
#: preset 1.0x on 8 x 8 and 12 x 12, 0.82x on 18 x 18 (the same FFT pairs as the dense
#: moments); `fast` preset 1.02x on 18 x 18 (the force level keeps it, though the lattice level
#: takes 28 % fewer pairs), 0.90x on 24 x 24 and 0.54x on 36 x 36
LATTICE_MIN_PILLARS = 400


def auto_kind(n_pillars: int, fft_size: int | None, on_lattice: bool = True) -> str:
    """The coarse level ``auto`` takes for pillars of one footprint: ``"lattice"`` on a lattice
    from :data:`LATTICE_MIN_PILLARS` pillars or where :func:`prefers_moments`; otherwise, up
    to ``coarse.MAX_PILLARS`` pillars, ``"moments"`` where :func:`prefers_moments`, else
    ``"two_level"``; ``"block"`` for more pillars off any lattice."""
    dear = fft_size is not None and prefers_moments(fft_size, n_pillars)
    if on_lattice and (dear or n_pillars >= LATTICE_MIN_PILLARS):
        return "lattice"
    if n_pillars > MAX_PILLARS:
        return "block"
    return "moments" if dear else "two_level"


def make_preconditioner(geometry, alpha: float, c0: float, kind: str = "auto",
                        max_block: int = 1024, fft_size: int | None = None):
    """The CG preconditioner of ``kind``.

    ``"auto"``: a two-level one where all pillars share one footprint of at most ``max_block``
    elements (:func:`auto_kind`: the lattice level, :mod:`fibril_hpc.solve.lattice`, wherever
    the pillars lie on a lattice and the brush or the FFT is large enough; else the dense moment
    level, :mod:`fibril_hpc.solve.moments`, or the force level, :mod:`fibril_hpc.solve.coarse`,
    up to ``coarse.MAX_PILLARS`` pillars, and block Jacobi above), else ``"diagonal"``. An
    explicit ``"block"``, ``"two_level"``, ``"moments"`` or ``"lattice"`` the geometry does not
    allow is a ValueError.
    """
    if kind == "diagonal":
        return DiagonalPreconditioner(geometry, alpha, c0)
    m = uniform_footprint(geometry)
    if m is None or m > max_block:
        if kind != "auto":
            raise ValueError(f"{kind} preconditioner needs groups with one shared footprint of "
                             f"at most {max_block} elements")
        return DiagonalPreconditioner(geometry, alpha, c0)
    ng = geometry.n_groups
    lattice = PillarLattice.of(geometry, m) if kind in ("auto", "lattice") else None
    if kind == "auto":
        kind = auto_kind(ng, fft_size, lattice is not None)
    if kind == "block":
        return BlockPreconditioner(geometry, alpha)
    if kind == "lattice":
        if lattice is None:
            raise ValueError("lattice preconditioner needs pillars on a regular lattice")
        return LatticeMomentPreconditioner(geometry, alpha, lattice)
    if ng > MAX_PILLARS:                            # Scene refuses this first, in one line
        raise ValueError(f"{kind} preconditioner needs at most {MAX_PILLARS} pillars "
                         f"(got {ng})")
    if kind == "moments":
        return MomentTwoLevelPreconditioner(geometry, alpha)
    return TwoLevelPreconditioner(geometry, alpha)

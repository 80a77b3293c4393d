"""Indenter geometries other than the pillar brush, for validation: a paraboloid (JKR/Hertz
sphere), a single flat punch and a row of flat punches. Each returns a
:class:`~fibril_hpc.geometry.grid.Geometry` whose active elements are those that can touch."""

from __future__ import annotations

import numpy as np

from .grid import Geometry


def sphere(R: float, radius_elements: int, h: float) -> Geometry:
    """Rigid paraboloid z0 = r^2/(2R) over the disc of ``radius_elements`` elements (one group)."""
    n = 2 * radius_elements + 1
    c = radius_elements
    iy, ix = np.nonzero(np.ones((n, n), bool))
    r2 = ((iy - c) ** 2 + (ix - c) ** 2) * h * h
    keep = r2 <= (radius_elements * h) ** 2
    iy, ix, r2 = iy[keep], ix[keep], r2[keep]
    return Geometry(n=n, h=h, iy=iy.astype(np.int64), ix=ix.astype(np.int64),
                    starts=np.array([0, len(iy)], dtype=np.int64), z0=r2 / (2.0 * R))


def punch_row(footprint, pitch: int, count: int, h: float) -> Geometry:
    """``count`` equal flat punches (one group each) with the given footprint, on a row at a pitch
    of ``pitch`` elements, on an (pitch*count)^2 grid."""
    half = (pitch - 1) // 2
    n = pitch * count
    di = np.array([o[0] for o in footprint], dtype=np.int64)
    dj = np.array([o[1] for o in footprint], dtype=np.int64)
    iy = np.concatenate([di + half for _ in range(count)])
    ix = np.concatenate([dj + j * pitch + half for j in range(count)])
    m = len(footprint)
    return Geometry(n=n, h=h, iy=iy, ix=ix, starts=np.arange(count + 1, dtype=np.int64) * m,
                    z0=np.zeros(m * count))

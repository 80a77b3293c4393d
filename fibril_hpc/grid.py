"""Element grid, pillar footprints, element-to-pillar labels and pillar heights (docs/model.md §1, §3).

Footprint convention (fixed, documented, stored): the pitch s is an *odd* whole number of elements,
so every pillar centre sits on an element centre, at ((I + 1/2) s, (J + 1/2) s). An element
belongs to a pillar when its centre lies within the nominal radius D/2 = s sqrt(phi/pi) of the
pillar centre (inclusive). Every pillar has the same footprint; its discrete area and the discrete
filling ratio are reported and used for normalisation; analytic comparisons use the equivalent
radius r_eq = sqrt(A_pillar/pi).

Heights: xi_n ~ N(0, 1) drawn by ``numpy.random.Generator(numpy.random.PCG64(seed))
.standard_normal(n)`` in row-major pillar order (n = I n_side + J, I along y); the pillar's set-back
is zeta_n = sigma (max xi - xi_n) >= 0 (d = 0 when the longest pillar touches).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError
from .scaling import Scaling

#: Name of the bit generator, stored with every result.
RNG_NAME = "numpy.random.PCG64 + Generator.standard_normal, row-major pillar order"


@dataclass(frozen=True)
class Geometry:
    """Elements that can ever touch, grouped (pillar by pillar) into contiguous slices.

    Attributes
    ----------
    n : int
        Grid side (elements); the grid covers n*h x n*h.
    h : float
        Element side (internal units).
    iy, ix : ndarray of int64
        Grid coordinates of the active elements, group-major (group g owns
        ``starts[g]:starts[g+1]``).
    starts : ndarray of int64
        Group offsets, length n_groups + 1.
    z0 : ndarray of float64
        Set-back of each element's tip from the lowest tip: the gap at d = 0 with no load.
    """

    n: int
    h: float
    iy: np.ndarray
    ix: np.ndarray
    starts: np.ndarray
    z0: np.ndarray

    @property
    def n_groups(self) -> int:
        """Number of groups (pillars)."""
        return len(self.starts) - 1

    @property
    def n_active(self) -> int:
        """Number of elements that can touch."""
        return len(self.iy)

    @property
    def labels(self) -> np.ndarray:
        """Group index of every active element."""
        return np.repeat(np.arange(self.n_groups), np.diff(self.starts))

    def to_map(self, values, fill=0.0) -> np.ndarray:
        """Scatter per-element values onto the n x n grid."""
        values = np.asarray(values)
        out = np.full((self.n, self.n), fill, dtype=values.dtype)
        out[self.iy, self.ix] = values
        return out


@dataclass(frozen=True)
class PillarGrid:
    """Discretisation of a pillar brush: grid, footprint and the realised resolution."""

    n_side: int
    pitch: int                  # elements per pitch s (odd)
    footprint: tuple            # ((di, dj), ...) offsets of one pillar's elements
    geometry: Geometry
    xi: np.ndarray              # standard normal draw per pillar
    zeta: np.ndarray            # set-back per pillar (internal length units)

    @property
    def n(self) -> int:
        """Grid side (elements)."""
        return self.geometry.n

    @property
    def h(self) -> float:
        """Element side (internal units)."""
        return self.geometry.h

    @property
    def elements_per_pillar(self) -> int:
        """Elements in one pillar's footprint."""
        return len(self.footprint)

    @property
    def r_eq(self) -> float:
        """Equivalent radius of the discrete footprint, sqrt(A_pillar/pi)."""
        return math.sqrt(self.elements_per_pillar * self.h**2 / math.pi)


def pitch_elements(phi: float, elements_per_diameter: float) -> int:
    """Odd pitch (elements) nearest to elements_per_diameter * s/D, at least 3."""
    target = elements_per_diameter * math.sqrt(math.pi / (4.0 * phi))
    s = 2 * int(round((target - 1.0) / 2.0)) + 1
    return max(3, s)


def footprint(pitch: int, phi: float) -> tuple:
    """Offsets (di, dj) of the elements whose centres lie within D/2 of the pillar centre."""
    r = pitch * math.sqrt(phi / math.pi)            # nominal radius, in elements
    half = (pitch - 1) // 2
    r2 = r * r * (1.0 + 1e-12)
    out = tuple((di, dj) for di in range(-half, half + 1) for dj in range(-half, half + 1)
                if di * di + dj * dj <= r2)
    return out


@dataclass(frozen=True)
class Lattice:
    """The lattice step of a brush: pitch and footprint in elements, and what follows from them.

    The one place where a resolution target becomes a grid (docs/model.md §3): the scaling
    (:meth:`scaling`), the pillar grid (:func:`build_pillar_grid`) and the campaign's cost
    estimate all build on it.

    Attributes
    ----------
    n_side : int
        Pillars per side.
    phi : float
        Nominal filling ratio.
    pitch : int
        Elements per pitch s (odd).
    footprint : tuple
        ((di, dj), ...) offsets of one pillar's elements from its centre element.
    """

    n_side: int
    phi: float
    pitch: int
    footprint: tuple

    @classmethod
    def of(cls, n_side: int, phi: float, elements_per_diameter: float) -> Lattice:
        """The lattice a resolution target gives (pitch: the nearest odd whole number)."""
        s = pitch_elements(phi, elements_per_diameter)
        return cls(n_side=n_side, phi=phi, pitch=s, footprint=footprint(s, phi))

    @property
    def elements_per_pillar(self) -> int:
        """Elements in one pillar's footprint."""
        return len(self.footprint)

    @property
    def phi_discrete(self) -> float:
        """Discrete filling ratio: pillar elements / pitch**2."""
        return self.elements_per_pillar / float(self.pitch * self.pitch)

    @property
    def grid_side(self) -> int:
        """N = n_side * pitch elements per side."""
        return self.n_side * self.pitch

    def scaling(self, work_of_adhesion: float = 1.0) -> Scaling:
        """The normalisation of this lattice (with the discrete filling ratio)."""
        return Scaling(phi=self.phi_discrete, work_of_adhesion=work_of_adhesion)


def pillar_heights(n_pillars: int, seed: int) -> np.ndarray:
    """Standard-normal draws of the pillars, in row-major pillar order (see module docstring)."""
    rng = np.random.Generator(np.random.PCG64(seed))
    return rng.standard_normal(n_pillars)


def build_pillar_grid(n_side: int, phi: float, elements_per_diameter: float, sigma: float,
                      seed: int, *, max_elements: int = 8192) -> PillarGrid:
    """Discretise a brush of n_side**2 pillars on the unit square.

    Parameters
    ----------
    sigma : float
        Standard deviation of the pillar length (internal length units).
    max_elements : int
        Largest grid side accepted (memory guard).
    """
    lat = Lattice.of(n_side, phi, elements_per_diameter)
    s, n, fp = lat.pitch, lat.grid_side, lat.footprint
    if n > max_elements:
        raise ConfigError("elements_per_diameter", elements_per_diameter,
                          f"a resolution giving at most {max_elements} elements per side "
                          f"(this one gives {n} for n_side={n_side})")
    h = 1.0 / n
    half = (s - 1) // 2
    di = np.array([o[0] for o in fp], dtype=np.int64)
    dj = np.array([o[1] for o in fp], dtype=np.int64)
    I, J = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
    cy = (I.ravel() * s + half)[:, None]
    cx = (J.ravel() * s + half)[:, None]
    iy = (cy + di[None, :]).ravel()
    ix = (cx + dj[None, :]).ravel()
    m = len(fp)
    n_p = n_side * n_side
    starts = np.arange(n_p + 1, dtype=np.int64) * m
    xi = pillar_heights(n_p, seed)
    zeta = sigma * (xi.max() - xi) if n_p else np.zeros(0)
    z0 = np.repeat(zeta, m)
    geom = Geometry(n=n, h=h, iy=iy.astype(np.int64), ix=ix.astype(np.int64),
                    starts=starts, z0=z0.astype(np.float64))
    return PillarGrid(n_side=n_side, pitch=s, footprint=fp, geometry=geom, xi=xi, zeta=zeta)

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

from ..errors import ConfigError
from .scaling import Scaling

#: Name of the bit generator, stored with every result.
RNG_NAME = "numpy.random.PCG64 + Generator.standard_normal, row-major pillar order"


#: largest pillars per side of a scene (Scene.n_side's range)
MAX_N_SIDE = 1000


def n_side_of(n_pillars, lattice: str = "square") -> int:
    """Pillars per side of a brush of ``n_pillars`` pillars.

    Both lattices hold n_side rows of n_side pillars (the hexagonal one shifts every other row
    by half a pitch), so the count must be a square number n_side**2 with n_side in
    [1, MAX_N_SIDE]; anything else is a one-line :class:`ConfigError` naming ``n_pillars`` and
    the nearest allowed counts.
    """
    top = MAX_N_SIDE**2
    if isinstance(n_pillars, bool) or not isinstance(n_pillars, (int, np.integer)) \
            or not 1 <= n_pillars <= top:
        raise ConfigError("n_pillars", n_pillars, f"a square number n_side**2 in [1, {top}] "
                          f"(n_side rows of n_side pillars, lattice {lattice})")
    n = int(n_pillars)
    root = math.isqrt(n)
    if root * root != n:
        lo, hi = root, min(root + 1, MAX_N_SIDE)
        raise ConfigError("n_pillars", n, f"a square number n_side**2 (n_side rows of n_side "
                          f"pillars, lattice {lattice}): the nearest are {lo * lo} "
                          f"(n_side {lo}) and {hi * hi} (n_side {hi})")
    return root


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

    def length_spread(self) -> float:
        """Standard deviation of the groups' mean set-backs (internal units): the brush's own
        length spread, which bounds a loading batch (``solver.load_merge_spread``); inf for a
        single group (no spread to resolve), 0 where a group is empty."""
        counts = np.diff(self.starts)
        if counts.size < 2:
            return math.inf
        if np.any(counts == 0):
            return 0.0
        return float(np.std(np.add.reduceat(self.z0, self.starts[:-1]) / counts))

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


#: Lattices a brush can have (``Scene.lattice``).
LATTICES = ("square", "hexagonal")


def pitch_elements(phi: float, elements_per_diameter: float) -> int:
    """Odd pitch (elements) nearest to elements_per_diameter * s/D, at least 3."""
    target = elements_per_diameter * math.sqrt(math.pi / (4.0 * phi))
    s = 2 * int(round((target - 1.0) / 2.0)) + 1
    return max(3, s)


def hex_pitch_elements(phi: float, elements_per_diameter: float) -> tuple:
    """(pitch, row spacing) of a hexagonal lattice in elements: the pitch is the *even* number
    nearest to elements_per_diameter * s/D (at least 4; even so that the half-pitch shift of every
    other row is whole elements), with s/D = sqrt(pi / (2 sqrt(3) phi)); the rows are
    round(pitch sqrt(3)/2) elements apart."""
    target = elements_per_diameter * math.sqrt(math.pi / (2.0 * math.sqrt(3.0) * phi))
    a = max(4, 2 * int(round(target / 2.0)))
    return a, int(round(a * math.sqrt(3.0) / 2.0))


def disc_footprint(radius: float, half: int) -> tuple:
    """Offsets (di, dj), |di|, |dj| <= half, of the elements whose centres lie within ``radius``
    (in elements) of the centre element."""
    r2 = radius * radius * (1.0 + 1e-12)
    return tuple((di, dj) for di in range(-half, half + 1) for dj in range(-half, half + 1)
                 if di * di + dj * dj <= r2)


def footprint(pitch: int, phi: float) -> tuple:
    """Offsets (di, dj) of the elements whose centres lie within D/2 of the pillar centre."""
    return disc_footprint(pitch * math.sqrt(phi / math.pi), (pitch - 1) // 2)


@dataclass(frozen=True)
class Lattice:
    """The lattice step of a brush: pitch and footprint in elements, and what follows from them.

    The one place where a resolution target becomes a grid (docs/model.md §3): the scaling
    (:meth:`scaling`), the pillar grid (:func:`build_pillar_grid`) and the campaign's cost
    estimate all build on it.

    Attributes
    ----------
    n_side : int
        Pillars per side (square), or pillars per row and rows (hexagonal).
    phi : float
        Nominal filling ratio.
    pitch : int
        Elements per pitch s (odd for the square lattice, even for the hexagonal one, whose pitch
        is the nearest-neighbour distance along a row).
    footprint : tuple
        ((di, dj), ...) offsets of one pillar's elements from its centre element.
    kind : str
        ``"square"`` (default) or ``"hexagonal"``.
    row_pitch : int
        Elements between rows (0: the pitch; hexagonal: round(pitch sqrt(3)/2)).
    """

    n_side: int
    phi: float
    pitch: int
    footprint: tuple
    kind: str = "square"
    row_pitch: int = 0

    @classmethod
    def of(cls, n_side: int, phi: float, elements_per_diameter: float,
           kind: str = "square") -> Lattice:
        """The lattice a resolution target gives (pitch: the nearest odd whole number for the
        square lattice, see :func:`hex_pitch_elements` for the hexagonal one)."""
        if kind == "square":
            s = pitch_elements(phi, elements_per_diameter)
            return cls(n_side=n_side, phi=phi, pitch=s, footprint=footprint(s, phi))
        a, r = hex_pitch_elements(phi, elements_per_diameter)
        radius = a * math.sqrt(phi * math.sqrt(3.0) / (2.0 * math.pi))
        return cls(n_side=n_side, phi=phi, pitch=a, footprint=disc_footprint(radius, a // 2),
                   kind=kind, row_pitch=r)

    @property
    def radius(self) -> float:
        """Nominal pillar radius D/2 in elements."""
        if self.kind == "square":
            return self.pitch * math.sqrt(self.phi / math.pi)
        return self.pitch * math.sqrt(self.phi * math.sqrt(3.0) / (2.0 * math.pi))

    @property
    def rows(self) -> int:
        """Elements between rows of pillars."""
        return self.row_pitch or self.pitch

    @property
    def elements_per_pillar(self) -> int:
        """Elements in one pillar's footprint."""
        return len(self.footprint)

    @property
    def phi_discrete(self) -> float:
        """Discrete filling ratio: pillar elements / unit-cell elements (pitch x row spacing)."""
        return self.elements_per_pillar / float(self.pitch * self.rows)

    @property
    def grid_side(self) -> int:
        """N elements per side: n_side * pitch (hexagonal: plus half a pitch for the shifted
        rows)."""
        return self.n_side * self.pitch + (0 if self.kind == "square" else self.pitch // 2)

    @property
    def area_fraction(self) -> float:
        """Nominal area A0 = pillars x unit cell over the grid's area N**2 (1 for square)."""
        if self.kind == "square":
            return 1.0
        return self.n_side**2 * self.pitch * self.rows / float(self.grid_side**2)

    def centres(self) -> tuple:
        """(row, column) element indices of the pillar centres, in row-major pillar order."""
        I, J = np.meshgrid(np.arange(self.n_side), np.arange(self.n_side), indexing="ij")
        I, J = I.ravel(), J.ravel()
        if self.kind == "square":
            half = (self.pitch - 1) // 2
            return I * self.pitch + half, J * self.pitch + half
        half = self.pitch // 2
        return I * self.rows + half, J * self.pitch + half + (I % 2) * half

    def scaling(self, work_of_adhesion: float = 1.0) -> Scaling:
        """The normalisation of this lattice (with the discrete filling ratio)."""
        if self.kind == "square":
            return Scaling(phi=self.phi_discrete, work_of_adhesion=work_of_adhesion)
        return Scaling(phi=self.phi_discrete, work_of_adhesion=work_of_adhesion,
                       area=self.area_fraction)


#: largest grid side (elements) of a brush: 1 000 x 1 000 pillars at `fast` (13 000) fit under it;
#: whether a scene runs is the memory check's to say (:mod:`fibril_hpc.inputs.limits`, which
#: checks this limit on every scene before any work: the largest padded FFT grid, 32 768, would
#: need about 20 GiB at its rate alone)
MAX_GRID_SIDE = 16384


def pillar_heights(n_pillars: int, seed: int) -> np.ndarray:
    """Standard-normal draws of the pillars, in row-major pillar order (see module docstring)."""
    rng = np.random.Generator(np.random.PCG64(seed))
    return rng.standard_normal(n_pillars)


def build_pillar_grid(n_side: int, phi: float, elements_per_diameter: float, sigma: float,
                      seed: int, *, max_elements: int = MAX_GRID_SIDE, lattice: str = "square",
                      heights: tuple | None = None, tip_offsets: np.ndarray | None = None
                      ) -> PillarGrid:
    """Discretise a brush of n_side**2 pillars on the unit square.

    Parameters
    ----------
    sigma : float
        Standard deviation of the pillar length (internal length units).
    max_elements : int
        Largest grid side accepted (memory guard).
    lattice : str
        ``"square"`` (default) or ``"hexagonal"`` (:class:`Lattice`).
    heights : (xi, zeta) or None
        Per-pillar draws and set-backs (internal units) from another height law
        (:mod:`fibril_hpc.inputs.heights`); ``None``: the Gaussian draw of the module docstring.
    tip_offsets : ndarray or None
        Per-footprint-element height offsets of a shaped tip (internal units, >= 0, in footprint
        order; :mod:`fibril_hpc.geometry.tips`); ``None``: flat tips, no offsets.
    """
    lat = Lattice.of(n_side, phi, elements_per_diameter, lattice)
    s, n, fp = lat.pitch, lat.grid_side, lat.footprint
    if n > max_elements:
        raise ConfigError("elements_per_diameter", elements_per_diameter,
                          f"a resolution giving at most {max_elements} elements per side "
                          f"(this one gives {n} for n_side={n_side})")
    h = 1.0 / n
    di = np.array([o[0] for o in fp], dtype=np.int64)
    dj = np.array([o[1] for o in fp], dtype=np.int64)
    cy, cx = lat.centres()
    iy = (cy[:, None] + di[None, :]).ravel()
    ix = (cx[:, None] + dj[None, :]).ravel()
    m = len(fp)
    n_p = n_side * n_side
    starts = np.arange(n_p + 1, dtype=np.int64) * m
    if heights is None:
        xi = pillar_heights(n_p, seed)
        zeta = sigma * (xi.max() - xi) if n_p else np.zeros(0)
    else:
        xi, zeta = heights
    z0 = np.repeat(zeta, m)
    if tip_offsets is not None:
        z0 = z0 + np.tile(tip_offsets, n_p)
    geom = Geometry(n=n, h=h, iy=iy.astype(np.int64), ix=ix.astype(np.int64),
                    starts=starts, z0=z0.astype(np.float64))
    return PillarGrid(n_side=n_side, pitch=s, footprint=fp, geometry=geom, xi=xi, zeta=zeta)

"""The half-space product with the far field carried by pillar moments (``solver.far_field:
multipole``, opt-in; the reference is ``exact``: every CG iteration is one FFT pair on the
element grid).

On a brush whose pillars share one footprint and sit on a lattice, the product u = K p on the
active elements splits pillar by pillar:

    u_g = K_self p_g + sum_{h != g} K_gh p_h,

where K_self (m x m, the footprint's own Love coefficients) is the same matrix for every pillar.
The approximation Ka keeps K_self exactly and replaces every coupling K_gh by its multipole
expansion to the dipole-dipole term, C T_gh C^T: the moments of pillar h, C^T p_h = (force,
x-moment, y-moment) with C = [1, x - x_h, y - y_h] over the footprint, couple through the blocks
T_gh of :func:`fibril_hpc.solve.moments.multipole_kernel` to the value and gradient of the
displacement at the centre of g, spread over its footprint by C. The couplings are applied by
FFT on the pillar lattice (:class:`fibril_hpc.solve.lattice.LatticeCouplings`), so a product costs
one (n_pillars x m) by (m x m) matrix product plus six transforms of the (2 n_y) x (2 n_x)
lattice: no transform of the element grid, whose padded size is about 25 times the active
elements at 16 % pillar cover.

Ka is what CG iterates with in the states' solves (:meth:`apply_increment`), and what changes of
more than one footprint's elements are added with (:meth:`add_point_loads`; exact direct sums
below); the full field u = K p (:meth:`apply`) stays exact, one FFT pair, and the load path calls
it every ``refresh_every`` solves of the state (``loading_refresh_every`` while loading).
Between two refreshes the state's u is the exact
field of the last refresh plus Ka times what changed since, and its solves converge to the state
of that held field, not of K: the error is e = (K - Ka)(p - p0), p0 the pressure of the last
refresh. Between two pillars K - Ka is a block R_s that depends only on their lattice offset s
(R_0 = 0), so :meth:`MultipoleField.pillar_bound` bounds e pillar by pillar by the offset
norms (:meth:`MultipoleField.remainder_norms`, Frobenius norms >= |R_s|_2, computed once)
convolved with the pillars' changes; with it, and with p1 . e = w . (p - p0) for
w = (K - Ka) p1 (K and Ka are symmetric), the load path certifies the force of the state that
ends each relaxation and refreshes where that bound exceeds ``confirm_tol``
(:mod:`fibril_hpc.path.confirm`; under displacement control). Which elements flip is not
bounded, so neither is F~_A. The direction's solves (p1 = A^-1 1_S, which carries the force along a
segment and places the next event) stay exact: solved with Ka too they moved F~_A by up to 0.9 %
on small brushes, the held states by at most 0.14 % (benchmarks/NOTES.md, "The far field as
pillar moments"). ``solver.confirm: local``, whose certificate needs an exact u, does not combine
with it.

The lattice carries the same multipole couplings the preconditioner of
:mod:`fibril_hpc.solve.lattice` uses, so with that preconditioner CG on Ka converges in one or two
iterations: a state's solve costs no FFT of the element grid between refreshes.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from ..elastic.greens import love
from .lattice import LatticeCouplings, PillarLattice
from .precond import uniform_footprint


class MultipoleField:
    """u = K p on the active elements, exact on :meth:`apply` and with the far field by pillar
    moments on :meth:`apply_increment` (module docstring).

    Parameters
    ----------
    exact : HalfSpace
        The reference operator (its FFT pair makes the exact refreshes).
    refresh_every : int
        Solves of the state between two exact products (read by the load path).

    Raises ValueError when the pillars do not share one footprint on a regular lattice.
    """

    #: increments are not exact products: the load path refreshes each field on its own count
    exact_increments = False
    #: held solves of the state between two exact products while loading: a smooth brush's
    #: first contacts follow the held field's error at 4 (paper.yaml's sigma~ 0.01 corners at
    #: small preloads: F~_A off by up to 0.96 %), not at 3, 2 or 1 (benchmarks/NOTES.md,
    #: "paper.yaml's corners under the moments"); 2 keeps a margin for 3.7 % more FFT pairs
    LOADING_REFRESH_EVERY = 2

    def __init__(self, exact, refresh_every: int):
        g = exact.geometry
        m = uniform_footprint(g)
        lattice = None if m is None else PillarLattice.of(g, m)
        if lattice is None:
            raise ValueError("multipole needs pillars of one footprint on a regular lattice")
        self.exact = exact
        self.geometry = g
        self.m = exact.m
        self.c0 = exact.c0
        #: exact direct sums up to one footprint's elements (each costs about a product of Ka)
        self.max_direct = min(exact.max_direct, m)
        # one pillar: Ka is K, and the field needs no refresh beyond the drift guard
        self.refresh_every = int(refresh_every) if g.n_groups > 1 else exact.refresh_every
        #: the count while loading (at most LOADING_REFRESH_EVERY)
        self.loading_refresh_every = (min(self.refresh_every, self.LOADING_REFRESH_EVERY)
                                      if g.n_groups > 1 else self.refresh_every)
        #: exact solves (the direction's) only guard their exactly kept field against drift
        self.exact_refresh_every = exact.exact_refresh_every
        self.footprint = m
        h = g.h
        ng = g.n_groups
        x = (g.ix * h).reshape(ng, m)
        y = (g.iy * h).reshape(ng, m)
        xr = x[0] - x[0].mean()
        yr = y[0] - y[0].mean()
        self._C = np.ascontiguousarray(np.stack([np.ones(m), xr, yr], axis=1))      # (m, 3)
        self._self = np.ascontiguousarray(love(xr[:, None] - xr[None, :],
                                               yr[:, None] - yr[None, :], h))
        self.couplings = LatticeCouplings(lattice, h)
        self._blocks = np.zeros((ng, 3, 3))
        self._use = np.ones((ng, 3))
        self._q = np.zeros((ng, 3))
        self._t = np.zeros((ng, 3))
        self._v = np.zeros(g.n_active)
        # work vectors of a product (the moments' spread) and of a sparse change's product, so
        # that neither allocates per call
        self._spread = np.zeros(g.n_active)
        self._sum = np.zeros(g.n_active)
        self.applications = 0
        self._norms = {}            # remainder_norms() by kind, once asked for
        self._norms_hat = {}        # their transforms (pillar_bound)

    # the reference operator's attributes that other parts read (tests, certificates, cascades)
    @property
    def table(self) -> np.ndarray:
        """The exact real-space influence table (local dense solves read it)."""
        return self.exact.table

    @property
    def n_pairs(self) -> int:
        """FFT pairs of the element grid executed so far (the exact products)."""
        return self.exact.n_pairs

    def work_arrays(self) -> dict:
        """The arrays this operator owns, the reference operator's included."""
        out = dict(self.exact.work_arrays())
        out.update({"self_block": self._self, "far_moments": self._q, "far_values": self._t,
                    "sparse_change": self._v, "spread": self._spread, "change_product": self._sum})
        return out

    def dense(self) -> np.ndarray:
        """The exact dense influence matrix (small grids, tests only)."""
        return self.exact.dense()

    def apply(self, p: np.ndarray, out: np.ndarray) -> np.ndarray:
        """out <- K p exactly (one FFT pair of the element grid)."""
        return self.exact.apply(p, out)

    def apply_increment(self, p: np.ndarray, out: np.ndarray) -> np.ndarray:
        """out <- Ka p: each pillar's own block exact, the others through their moments."""
        ng, m = self._q.shape[0], self.footprint
        P = p.reshape(ng, m)
        O = out.reshape(ng, m)
        np.matmul(P, self._self, out=O)                 # K_self is symmetric
        np.matmul(P, self._C, out=self._q)
        self.couplings.apply(self._q, self._blocks, self._use, self._t)
        S = self._spread.reshape(ng, m)
        np.matmul(self._t, self._C.T, out=S)
        O += S
        self.applications += 1
        return out

    def remainder_norms(self, spectral: bool = False) -> np.ndarray:
        """A bound of |R_s|_2, the remainder K - Ka between two pillars at lattice offset
        s = (db, da), on the centred (2 n_y - 1, 2 n_x - 1) grid of offsets (offset (0, 0), the
        own block, exact: 0): the Frobenius norms (memory and time O(footprint x elements)), or
        with ``spectral`` the 2-norms themselves (an SVD per pillar and footprint-squared
        memory per pillar: studies and tests). Computed once per kind, exactly: the columns of K
        (direct sums) and of Ka of the four corner pillars' elements; an offset is seen from a
        corner or, as -s (R_-s = R_s^T), from the opposite one; checked against the offsets the
        brush's pillar pairs have (ValueError where one is missing)."""
        if spectral not in self._norms:
            lat = self.couplings.lattice
            ng, m = self._q.shape[0], self.footprint
            ny, nx = lat.shape
            ia, ib = np.asarray(lat.ia), np.asarray(lat.ib)
            table = np.zeros((2 * ny - 1, 2 * nx - 1))
            corners = {int(np.argmin(ia + ib)), int(np.argmax(ia + ib)),
                       int(np.argmin(ia - ib)), int(np.argmax(ia - ib))}
            n = ng * m
            unit, ke, ka = np.zeros(n), np.zeros(n), np.empty(n)
            for c in corners:
                R = np.empty((ng, m, m)) if spectral else None
                fro2 = np.zeros(ng)
                for f in range(m):
                    unit[c * m + f] = 1.0
                    ke[:] = 0.0
                    self.exact.add_point_loads(ke, np.array([c * m + f]), np.ones(1))
                    self.apply_increment(unit, ka)
                    unit[c * m + f] = 0.0
                    col = (ke - ka).reshape(ng, m)
                    if spectral:
                        R[:, :, f] = col
                    else:
                        fro2 += np.einsum("ij,ij->i", col, col)
                norms = np.linalg.norm(R, 2, axis=(1, 2)) if spectral else np.sqrt(fro2)
                db, da = ib - ib[c] + ny - 1, ia - ia[c] + nx - 1
                table[db, da] = np.maximum(table[db, da], norms)
            # R_-s = R_s^T has the same norms: offsets seen from no corner (a hexagonal
            # lattice's checkerboard ties its corners) are seen from the opposite one
            table = np.maximum(table, table[::-1, ::-1])
            table[ny - 1, nx - 1] = 0.0
            occ = np.zeros((ny, nx))
            occ[ib, ia] = 1.0
            shape = (2 * ny - 1, 2 * nx - 1)
            pairs = sfft.irfft2(sfft.rfft2(occ, s=shape) * np.conj(sfft.rfft2(occ, s=shape)),
                                s=shape)
            pairs = np.roll(pairs, (ny - 1, nx - 1), axis=(0, 1))  # offset (0, 0) at the centre
            pairs[ny - 1, nx - 1] = 0.0
            if np.any((pairs > 0.5) & (table == 0.0)):
                raise ValueError("the remainder's table misses offsets of the brush")
            self._norms[spectral] = table
        return self._norms[spectral]

    def pillar_bound(self, change_norms: np.ndarray, spectral: bool = False) -> np.ndarray:
        """b_g = sum_h N_(g-h) |x_h|_2 for the pillar norms ``change_norms`` of a change x and
        the offset norms N of :meth:`remainder_norms`: |((K - Ka) x)_g|_2 <= b_g on every pillar
        g (one FFT convolution on the lattice, the table's transform kept)."""
        lat = self.couplings.lattice
        ny, nx = lat.shape
        if spectral not in self._norms_hat:
            shape = (sfft.next_fast_len(3 * ny - 2, real=True),
                     sfft.next_fast_len(3 * nx - 2, real=True))
            self._norms_hat[spectral] = (shape, sfft.rfft2(self.remainder_norms(spectral),
                                                           s=shape))
        shape, hat = self._norms_hat[spectral]
        grid = np.zeros((ny, nx))
        grid[lat.ib, lat.ia] = change_norms
        full = sfft.irfft2(sfft.rfft2(grid, s=shape) * hat, s=shape)
        return np.maximum(full[ny - 1 + lat.ib, nx - 1 + lat.ia], 0.0)

    def add_point_loads(self, u: np.ndarray, idx: np.ndarray, vals: np.ndarray,
                        exact: bool = False) -> bool:
        """u += K[:, idx] vals: exactly by direct sums up to ``max_direct`` loads (one
        footprint), else by Ka (always done: returns True). ``exact``: as the reference
        operator does it (direct sums where cheaper than an FFT pair, else False: the caller
        makes the full product)."""
        if exact or len(idx) <= self.max_direct:
            return self.exact.add_point_loads(u, idx, vals)
        v = self._v
        v[:] = 0.0
        v[idx] = vals
        u += self.apply_increment(v, self._sum)
        return True

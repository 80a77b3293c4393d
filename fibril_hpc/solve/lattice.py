"""The moment coarse level applied by FFT on the pillar lattice (``solver.preconditioner:
lattice``; what ``auto`` takes from ``factory.LATTICE_MIN_PILLARS`` pillars on, and wherever
the dense moment level would pay).

The dense moment level (:mod:`fibril_hpc.solve.moments`) keeps F^-1 over all 3 n_pillars coarse
unknowns: (3 n)^2 memory, O((3 n)^2) per CG iteration and per set change, O((3 n)^3) per
rebuild, which caps it near a thousand pillars. But its off-diagonal blocks F_gh depend only on
the offset of the two footprint centres, and on a brush the centres lie on a regular lattice:
the coupling T v (v the coarse unknowns, one (force, x-moment, y-moment) per pillar) is a
discrete convolution on that lattice, applied exactly by real FFTs of the zero-padded
(2 n_y) x (2 n_x) lattice (three forward transforms, one 3 x 3 kernel product per frequency,
three inverse transforms, those along the rows pruned to the lattice's rows; the nine kernels
are transformed once and kept by their symmetry as six real rows). The coarse system

    F y = c,   F = T + blockdiag(F_gg)   on the unknowns in use,

is then solved by conjugate gradients inside every application of the preconditioner, with
blockdiag(D_g) = blockdiag(F_gg)^-1 as its preconditioner (each pillar's own exact block, which
``MomentModes`` keeps anyway), from zero, to a relative residual of ``INNER_TOL`` in the D-norm.
The blocks-only preconditioned coarse matrix is well conditioned (condition number 3.3 on
18 x 18, 8.4 on 36 x 36), so the inner solve takes about ten iterations on the default scenes
(7.0 per solve on 18 x 18, 9.8 on 36 x 36), each a few tiny FFTs; it is tight enough that the
outer CG sees the exact preconditioner (the dense moment level's): the same FFT pairs, events and
F~_A (benchmarks/NOTES.md, "The inner tolerance of the lattice level"). A circulant inner
preconditioner (the inverse symbol of T plus a fully attached pillar's block) was tried and
taken out: it ignores which pillars are in contact, and took more inner iterations than the
blocks (11.9 against 10.7 per solve on 18 x 18). Nothing grows faster than n log n in the
pillar count, there is no cap, and a set change only recomputes the changed pillars' own
blocks: nothing to update, nothing to rebuild, no history.

Needs pillars of one footprint whose footprint origins differ by whole multiples of a lattice
step in x and in y (square lattices; hexagonal ones as a checkerboard of half the row step), with
the lattice at most ``MAX_LATTICE_FILL`` times as many nodes as pillars;
:meth:`PillarLattice.of` returns None otherwise and the factory keeps the other levels.
"""

from __future__ import annotations

from functools import reduce
from math import gcd

import numpy as np
import scipy.fft as sfft

from ..kernels import compiled as kern
from .moments import MomentModes, multipole_kernel

#: a lattice with more nodes than this many times the pillars is not used (mostly empty)
MAX_LATTICE_FILL = 4


class PillarLattice:
    """Where each pillar sits on a regular lattice: ``ia``, ``ib`` (its x and y lattice
    indices), ``shape`` = (n_y, n_x) and the steps ``(sx, sy)`` in elements."""

    def __init__(self, ia, ib, shape, steps):
        self.ia, self.ib = ia, ib
        self.shape = shape
        self.steps = steps

    @classmethod
    def of(cls, geometry, m: int):
        """The lattice of a geometry whose groups share one footprint of ``m`` elements, or
        None (see the module docstring)."""
        ng = geometry.n_groups
        ox = geometry.ix.reshape(ng, m)[:, 0].astype(np.int64)
        oy = geometry.iy.reshape(ng, m)[:, 0].astype(np.int64)
        dx, dy = ox - ox.min(), oy - oy.min()
        sx = reduce(gcd, dx.tolist(), 0) or 1
        sy = reduce(gcd, dy.tolist(), 0) or 1
        ia, ib = dx // sx, dy // sy
        shape = (int(ib.max()) + 1, int(ia.max()) + 1)
        if shape[0] * shape[1] > MAX_LATTICE_FILL * ng:
            return None
        if len(np.unique(ib * shape[1] + ia)) != ng:
            return None
        return cls(ia, ib, shape, (sx, sy))


class LatticeCouplings:
    """y = T v (+ the pillars' own blocks), the multipole couplings of
    :mod:`fibril_hpc.solve.moments` between pillars on a :class:`PillarLattice`, by FFT (module
    docstring): single-threaded pyFFTW plans by stages, compiled scatter, 3 x 3 product per
    frequency (in place, by the spectra's symmetry) and gather. ``v`` and ``y`` are
    (n_pillars, 3)."""

    def __init__(self, lattice: PillarLattice, h: float):
        import pyfftw

        self.lattice = lattice
        ny, nx = lattice.shape
        self.fft_shape = (sfft.next_fast_len(2 * ny - 1, real=True),
                          sfft.next_fast_len(2 * nx - 1, real=True))
        py, px = self.fft_shape
        self._ks = self.symmetric_rows(self.spectra(lattice, h, self.fft_shape))
        # The transforms by stages, the rows' pruned to the n_y lattice rows (the other p_y - n_y
        # rows of the input are zero, and of the output not read): the rows' real transforms on
        # n_y rows only, the columns' complex ones on all p_y, the product in place in _hat
        # (the full 2-D transforms' numbers to rounding; 0.83x their time at 316 x 316)
        self._grid = pyfftw.zeros_aligned((3, ny, px), dtype=np.float64)
        self._hat = pyfftw.zeros_aligned((3, py, px // 2 + 1), dtype=np.complex128)
        self._out = pyfftw.zeros_aligned((3, ny, px), dtype=np.float64)
        flags = ("FFTW_MEASURE",)
        rows = self._hat[:, :ny, :]
        self._fwd_rows = pyfftw.FFTW(self._grid, rows, axes=(2,), flags=flags, threads=1)
        self._fwd_cols = pyfftw.FFTW(self._hat, self._hat, axes=(1,), flags=flags, threads=1)
        self._bwd_cols = pyfftw.FFTW(self._hat, self._hat, axes=(1,), flags=flags, threads=1,
                                     direction="FFTW_BACKWARD")
        self._bwd_rows = pyfftw.FFTW(rows, self._out, axes=(2,), direction="FFTW_BACKWARD",
                                     flags=flags + ("FFTW_DESTROY_INPUT",), threads=1)
        self._grid[...] = 0.0
        self._ia = np.ascontiguousarray(lattice.ia)
        self._ib = np.ascontiguousarray(lattice.ib)

    @staticmethod
    def spectra(lattice: PillarLattice, h: float, fft_shape) -> np.ndarray:
        """The couplings' (3, 3, n_freq) complex spectra on the padded lattice ``fft_shape``
        (p_y, p_x), with 1/(p_y p_x) folded in (the transforms are unnormalised)."""
        ny, nx = lattice.shape
        py, px = fft_shape
        # offsets s on the padded grid in wrap-around order; y(p) = sum_q f(q - p) v(q) is the
        # convolution of v with f(-s)
        sa = np.arange(px)
        sa = np.where(sa < nx, sa, sa - px)
        sb = np.arange(py)
        sb = np.where(sb < ny, sb, sb - py)
        rx = np.broadcast_to(-sa[None, :] * (lattice.steps[0] * h), (py, px)).astype(np.float64)
        ry = np.broadcast_to(-sb[:, None] * (lattice.steps[1] * h), (py, px)).astype(np.float64)
        zero = (rx == 0.0) & (ry == 0.0)
        rx = np.where(zero, 1.0, rx)                     # any nonzero offset: zeroed below
        f = multipole_kernel(rx, ry, h)                  # (py, px, 3, 3)
        f[zero] = 0.0
        f[np.abs(sb) >= ny, :] = 0.0                     # offsets no pair of pillars has
        f[:, np.abs(sa) >= nx] = 0.0
        # (3, 3, n_freq) spectra, unnormalised transforms: 1/(p_y p_x) folded in here
        spec = sfft.rfft2(np.moveaxis(f, (2, 3), (0, 1)), axes=(2, 3)) / (py * px)
        return spec.reshape(3, 3, -1)

    @staticmethod
    def symmetric_rows(spec) -> np.ndarray:
        """The six real rows (K00, K11, K22, K12, Im K01, Im K02) of the (3, 3, n) spectra.

        The couplings obey f(-s) = f(s)^T, with the force-force and tilt-tilt entries even in
        s and the force-tilt ones odd: so K00, K11, K22 and K12 = K21 are real, K01 = -K10 and
        K02 = -K20 imaginary (their other parts are the transform's rounding, 1e-16 of the
        largest entry). Kept as six float64 rows instead of nine complex ones, the product
        reads a third of the memory per frequency (benchmarks/NOTES.md, "The lattice
        couplings' spectra by their symmetry")."""
        return np.ascontiguousarray(np.stack([spec[0, 0].real, spec[1, 1].real,
                                              spec[2, 2].real, spec[1, 2].real,
                                              spec[0, 1].imag, spec[0, 2].imag]))

    def apply(self, v, blocks, use, out) -> np.ndarray:
        """out <- use * (T v + blockdiag(blocks) v) for v, out (n_pillars, 3), ``blocks``
        (n_pillars, 3, 3) and the 0/1 mask ``use`` (n_pillars, 3). The input grid's nodes without
        a pillar stay zero (the product comes back in a buffer of its own)."""
        ny = self._grid.shape[1]
        kern.lattice_scatter(v, self._ib, self._ia, self._grid)
        self._fwd_rows()
        self._hat[:, ny:, :] = 0.0              # the zero rows (the last inverse overwrote them)
        self._fwd_cols()
        kern.spectral3_sym(self._ks, self._hat.reshape(3, -1))
        self._bwd_cols(normalise_idft=False)
        self._bwd_rows(normalise_idft=False)
        kern.lattice_gather(self._out, self._ib, self._ia, blocks, v, use, out)
        return out


class LatticeMomentPreconditioner(MomentModes):
    """Block Jacobi plus the moment coarse level, its coarse system solved iteratively with the
    couplings applied by FFT on the pillar lattice (module docstring)."""

    #: the ``solver.preconditioner`` value that builds this one (``auto`` reports its choice)
    kind = "lattice"

    #: relative residual of the inner coarse solve, in the D-norm (see the module docstring):
    #: at 1e-6 the default 18 x 18 and 36 x 36 scenes take the same FFT pairs, events and F~_A
    #: (to 1e-11) as at 1e-10, with 34 % fewer inner iterations (benchmarks/NOTES.md, "The inner
    #: tolerance of the lattice level"); 1e-4 already costs the 18 x 18 scene 4 more pairs
    INNER_TOL = 1e-6
    #: inner iterations before the coarse solve is given up (a ValueError: never seen)
    INNER_MAXITER = 500

    _STATE = ("_att", "_zh", "_d", "_fgg", "_use")

    def __init__(self, geometry, alpha, lattice: PillarLattice | None = None):
        super().__init__(geometry, alpha)
        lattice = lattice or PillarLattice.of(geometry, self.m)
        if lattice is None:
            raise ValueError("lattice preconditioner needs pillars on a regular lattice")
        self.couplings = LatticeCouplings(lattice, geometry.h)
        self._usef = np.zeros((self.ng, 3))
        self.inner_solves = 0
        self.inner_iterations = 0

    def update_counts(self) -> dict:
        """Inner coarse solves and their iterations so far (nothing is factorised or updated)."""
        return {"coarse_inner_solves": self.inner_solves,
                "coarse_inner_iterations": self.inner_iterations}

    def _restored(self) -> None:
        """The mask of unknowns in use from the restored ``use``."""
        self._usef[:] = self._use

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``: the changed pillars' modes follow."""
        if self._follow_modes(att) is not None:
            self._valid = True
            self._usef[:] = self._use

    @property
    def coarse_inverse(self):
        """Not kept: this level solves its coarse system iteratively."""
        raise AttributeError("the lattice coarse level keeps no inverse")

    def coarse_apply(self, v, out=None) -> np.ndarray:
        """F v on the unknowns in use (zero elsewhere), v of shape (n_pillars, 3) and zero off
        the unknowns in use."""
        out = np.empty_like(v) if out is None else out
        return self.couplings.apply(v, self._fgg, self._usef, out)

    def coarse_solve(self, c) -> np.ndarray:
        """F^-1 c on the unknowns in use (preconditioned CG from zero; module docstring)."""
        d = self._d
        x = np.zeros_like(c)
        r = c * self._usef
        z = np.empty_like(c)
        q = np.empty_like(c)
        kern.block3_apply(d, r, z)
        rz = float(np.vdot(r, z))
        self.inner_solves += 1
        if rz <= 0.0:
            return x
        stop = rz * self.INNER_TOL**2
        p = z.copy()
        for _ in range(self.INNER_MAXITER):
            self.coarse_apply(p, q)
            a = rz / float(np.vdot(p, q))
            x += a * p
            r -= a * q
            kern.block3_apply(d, r, z)
            rz_new = float(np.vdot(r, z))
            self.inner_iterations += 1
            if rz_new <= stop:
                return x
            p *= rz_new / rz
            p += z
            rz = rz_new
        raise ValueError(f"the lattice coarse solve did not converge in {self.INNER_MAXITER} "
                         "iterations")

    def apply(self, r, att, z) -> float:
        """z <- (two-level preconditioner) r on the attached set; returns r.z."""
        self.block_jacobi.apply(r, att, z)
        c = self._moments(r)                                               # Zh^T r
        y = self.coarse_solve(c)
        dc = np.empty_like(c)
        kern.block3_apply(self._d, c, dc)
        y -= dc
        self._correct(y, z)
        return float(r @ z)

"""The non-periodic Boussinesq operator u = K * p restricted to the elements that can touch.

The object owns its FFT pair (plans + aligned buffers) and the transformed kernel, built once per
grid and reused for every product. A product scatters the active pressures into the input rows of the
zero-padded transform (entries outside the active set are never written and stay zero), runs one
(row-pruned) FFT pair with a real multiply by K^ in between, and gathers the active
displacements.
"""

from __future__ import annotations

import numpy as np

from ..geometry.scaling import E_STAR
from ..kernels import compiled as kern
from .fft import FFTPair
from .greens import BUILD_BLOCK, K00, kernel_spectrum, love, padded_size


class HalfSpace:
    """u_i = sum_j K(x_i - x_j) p_j over the active elements of a :class:`Geometry`.

    Parameters
    ----------
    geometry : Geometry
    backend, threads, planner :
        Passed to :class:`~fibril_hpc.elastic.fft.FFTPair`.
    m : int, optional
        Padded FFT size (default :func:`~fibril_hpc.elastic.greens.padded_size`); any ``m >= 2n - 1``
        gives the same product up to rounding (benchmarks compare sizes with it).
    """

    def __init__(self, geometry, backend="pyfftw", threads=1, planner="estimate", *,
                 m: int | None = None):
        self.geometry = geometry
        if m is not None and int(m) < 2 * geometry.n - 1:
            raise ValueError(f"padded size m={m} is below 2n-1 = {2 * geometry.n - 1}")
        self.m = padded_size(geometry.n) if m is None else int(m)
        rows = np.unique(geometry.iy)
        self.pair = FFTPair(self.m, rows, backend=backend, threads=threads, planner=planner)
        # the kernel transform is held once, by the pair (cut into its column blocks); its
        # least and largest values are kept for the certificates' eigenvalue bound
        kernel = kernel_spectrum(geometry.n, self.m, geometry.h)
        self.kernel_min, self.kernel_max = float(kernel.min()), float(kernel.max())
        self.pair.load_kernel(kernel)
        del kernel
        rank = np.zeros(geometry.n, dtype=np.int64)
        rank[rows] = np.arange(len(rows))
        self._idx = (rank[geometry.iy] * self.m + geometry.ix).astype(np.int64)
        self._rin = self.pair.real_in.reshape(-1)
        self._rout = self.pair.real_out.reshape(-1)
        self.c0 = K00 * geometry.h / E_STAR   # self-influence K(0, 0)
        self._table = None
        n = max(geometry.n_active, 1)
        # a direct sum costs ~n_active per load; an FFT pair ~m^2 log2(m)/2: break-even
        self.max_direct = max(8, int(self.m * self.m * np.log2(max(self.m, 2)) / (2 * n)))

    @classmethod
    def from_options(cls, geometry, options, *, m: int | None = None) -> HalfSpace:
        """The operator a :class:`~fibril_hpc.inputs.options.SolverOptions` asks for."""
        return cls(geometry, **options.operator_settings(), m=m)

    def work_arrays(self) -> dict:
        """The arrays this operator owns besides its FFT pair's (see ``pair.work_arrays()``)."""
        out = {"index": self._idx}
        if self._table is not None:
            out["table"] = self._table
        return out

    @property
    def kernel_hat(self) -> np.ndarray:
        """The kernel transform K^ (real, (m, m//2 + 1)): a new copy from the pair's column
        blocks (4 bytes per m^2 while it lives; for tests and benchmarks, not the solver)."""
        return self.pair.kernel_transform()

    @property
    def table(self) -> np.ndarray:
        """Real-space influence coefficients K[|dy|, |dx|] on the n x n offsets (built lazily)."""
        if self._table is None:
            n, h = self.geometry.n, self.geometry.h
            off = np.arange(n) * h
            table = np.empty((n, n))
            for a in range(0, n, BUILD_BLOCK):      # rows at a time: no n x n temporaries
                table[a:a + BUILD_BLOCK] = love(off[a:a + BUILD_BLOCK, None], off[None, :], h)
            self._table = table
        return self._table

    def add_point_loads(self, u: np.ndarray, idx: np.ndarray, vals: np.ndarray,
                        exact: bool = True) -> bool:
        """u += K[:, idx] vals by a direct sum when that is cheaper than an FFT pair.

        Returns False (and leaves u alone) when an FFT product would be cheaper. (``exact``:
        the sum is always exact here; an approximate operator takes it.)
        """
        if len(idx) > self.max_direct:
            return False
        if len(idx):
            kern.point_loads(u, self.geometry.iy, self.geometry.ix, idx, vals, self.table)
        return True

    @property
    def n_pairs(self) -> int:
        """FFT pairs executed so far (the operator products)."""
        return self.pair.n_pairs

    def apply(self, p: np.ndarray, out: np.ndarray) -> np.ndarray:
        """out <- K p on the active elements (one FFT pair)."""
        self._rin[self._idx] = p
        self.pair.convolve()
        np.take(self._rout, self._idx, out=out)
        return out

    #: the product CG iterates with: here the exact one (an approximate operator, e.g.
    #: :class:`fibril_hpc.solve.farfield.MultipoleField`, iterates with its own)
    apply_increment = apply

    #: increments (CG products, direct sums) are exact: the load path's refresh of u after
    #: ``refresh_every`` incrementally kept solves only guards against rounding drift (as
    #: after ``exact_refresh_every`` exact solves under an approximate operator)
    exact_increments = True
    refresh_every = exact_refresh_every = loading_refresh_every = 64

    def dense(self) -> np.ndarray:
        """Dense influence matrix on the active elements (small grids, tests only)."""
        g = self.geometry
        x = g.ix * g.h
        y = g.iy * g.h
        return love(x[:, None] - x[None, :], y[:, None] - y[None, :], g.h)

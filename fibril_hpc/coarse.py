"""A coarse pillar-level second level for the block-Jacobi preconditioner (experiment, issue 8).

One unknown per pillar in contact: Z_g = M_g^-1 1 on pillar g's attached elements (M the exact
block-Jacobi preconditioner of :mod:`fibril_hpc.precond`, so Z_g is the block-Jacobi shape of a
unit force on the pillar), E = Z^T A Z with the exact diagonal E_gg = 1^T M_g^-1 1 and point-force
off-diagonals E_gh = W_g W_h K(c_g - c_h), W_g the sum of Z_g and K Love's coefficient at the
offset of the pillar centres. Applied as

    z = M^-1 r + Z (E^-1 - D^-1) Z^T r,   D = diag E.

Per pillar, M_g^-1 - Z_g D_g^-1 Z_g^T is M_g^-1 with its force mode projected out (positive
semidefinite), so the block-Jacobi's own answer for the force mode is replaced by the coupled one
and the preconditioner stays SPD. (The plain additive form M^-1 + Z E^-1 Z^T counts the force
mode twice and took more iterations than block Jacobi alone: benchmarks/NOTES.md.)

No extra FFT pair; E is rebuilt and inverted (n_contact x n_contact) whenever the set changes.
"""

from __future__ import annotations

import numpy as np

from .greens import love
from .precond import BlockPreconditioner

#: most pillars of a two-level scene: the coarse matrix is dense and inverted per set change
MAX_PILLARS = 1024


class TwoLevelPreconditioner:
    """Block Jacobi plus a coarse pillar-force correction (see the module docstring)."""

    #: relative change of a pillar's W that triggers a new E^-1 (see ``update``)
    REFRESH = 0.1

    def __init__(self, geometry, alpha):
        self.block_jacobi = BlockPreconditioner(geometry, alpha)
        m = self.block_jacobi.m
        self.m = m
        self.ng = geometry.n_groups
        h = geometry.h
        cy = geometry.iy.reshape(self.ng, m).mean(axis=1) * h
        cx = geometry.ix.reshape(self.ng, m).mean(axis=1) * h
        self._far = love(cx[:, None] - cx[None, :], cy[:, None] - cy[None, :], h)
        self._att = np.zeros(geometry.n_active, dtype=np.uint8)
        self._w = np.zeros(geometry.n_active)
        self._groups = np.zeros(0, dtype=np.int64)
        self._einv = np.zeros((0, 0))
        self._inv_d = np.zeros(0)
        self._w_built = np.zeros(0)
        self.updates = 0
        self.factorisations = 0

    @property
    def one_level(self):
        """The preconditioner without its coarse level (the local cascade's trust test)."""
        return self.block_jacobi

    def work_arrays(self) -> dict:
        """The arrays this preconditioner owns (its block-Jacobi level's included), by name."""
        out = {f"block_{k}": v for k, v in self.block_jacobi.work_arrays().items()}
        out.update({k: v for k, v in vars(self).items() if isinstance(v, np.ndarray)})
        return out

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``.

        Z and D follow every change of the set; E^-1 is rebuilt only when the pillars in contact
        change or some W_g has moved by more than ``REFRESH`` (relative) since it was built. Any
        SPD E^-1 on the same pillars keeps the preconditioner SPD, so a slightly stale one only
        costs iterations, never correctness, and most set changes (a ring of elements of one
        pillar) move W little.
        """
        self.block_jacobi.update(att)
        if np.array_equal(att, self._att) and self.updates:
            return
        self.updates += 1
        self._att[:] = att
        ones = (att != 0).astype(np.float64)
        self.block_jacobi.apply(ones, att, self._w)           # Z = M^-1 1_S
        W = self._w.reshape(self.ng, self.m).sum(axis=1)
        g = np.flatnonzero(W > 0.0)
        self._inv_d = 1.0 / W[g]
        if np.array_equal(g, self._groups) and self.factorisations and \
                np.all(np.abs(W[g] - self._w_built) <= self.REFRESH * self._w_built):
            return
        E = self._far[np.ix_(g, g)] * np.outer(W[g], W[g])
        E[np.diag_indices(len(g))] = W[g]
        self._einv = np.linalg.inv(E) if len(g) else np.zeros((0, 0))
        self._w_built = W[g]
        self._groups = g
        self.factorisations += 1

    def apply(self, r, att, z) -> float:
        """z <- (two-level preconditioner) r on the attached set; returns r.z."""
        self.block_jacobi.apply(r, att, z)
        g = self._groups
        if len(g):
            w2 = self._w.reshape(self.ng, self.m)
            c = np.einsum("ij,ij->i", w2[g], r.reshape(self.ng, self.m)[g])   # Z^T r
            z.reshape(self.ng, self.m)[g] += (self._einv @ c - c * self._inv_d)[:, None] * w2[g]
        return float(r @ z)

"""A coarse pillar-level second level for the block-Jacobi preconditioner (issue 8).

One unknown per pillar in contact: Z_g = M_g^-1 1 on pillar g's attached elements (M the exact
block-Jacobi preconditioner of :mod:`fibril_hpc.solve.precond`, so Z_g is the block-Jacobi shape of a
unit force on the pillar), W_g = 1^T Z_g, and the normalised shapes Zh_g = Z_g / W_g (unit force).
The coarse matrix in force unknowns is F = Zh^T A Zh with the exact diagonal F_gg = 1 / W_g and
point-force off-diagonals F_gh = K(c_g - c_h), K Love's coefficient at the offset of the pillar
centres. Applied as

    z = M^-1 r + Zh (F^-1 - W) Zh^T r,   W = diag(W_g).

Per pillar, M_g^-1 - Zh_g W_g Zh_g^T = M_g^-1 - Z_g Z_g^T / W_g is M_g^-1 with its force mode
projected out (positive semidefinite), so the block-Jacobi's own answer for the force mode is
replaced by the coupled one and the preconditioner stays SPD. (The plain additive form
M^-1 + Zh F^-1 Zh^T counts the force mode twice and took more iterations than block Jacobi
alone: benchmarks/NOTES.md.)

No extra FFT pair. F^-1 is kept over all pillars (rows and columns of pillars out of contact are
zero) and follows every set change exactly by O(n^2) updates instead of a new O(n^3) inverse:
a pillar whose W_g changes is a rank-one change of F's diagonal (Sherman-Morrison), a pillar
that leaves drops its row and column (Schur complement on the inverse:
F^-1 - F^-1[:, g] F^-1[g, :] / F^-1[g, g]), a pillar that joins borders the matrix (its Schur
complement s = 1/W_g - b^T F^-1 b, b its point-force column). Each update is symmetric by
construction; F^-1 is rebuilt with a dense inverse every ``REBUILD_EVERY`` updates, when one set
change moves many pillars, or when a pivot is not safely positive (an update that would lose
positive definiteness is never applied).
"""

from __future__ import annotations

import numpy as np

from ..elastic.greens import love
from .precond import BlockPreconditioner

#: most pillars of a scene with a dense coarse level (the force level here, the dense moment
#: level of :mod:`fibril_hpc.solve.moments`: their inverses are pillar x pillar). Above it
#: ``auto`` takes the lattice level (:mod:`fibril_hpc.solve.lattice`, no cap), or block Jacobi
#: for pillars off any lattice. 36 x 36 was measured to pay with the force level (13 269 FFT
#: pairs and 409 CPU s against block Jacobi's 33 138 and 570 s, benchmarks/NOTES.md)
MAX_PILLARS = 1296


class CoarseLevel:
    """What the coarse levels share (this module's force level, :mod:`fibril_hpc.solve.moments`):
    the block-Jacobi level underneath (``block_jacobi``), the attached set the coarse level was
    built on, the dense coarse inverse ``_finv`` (read through ``coarse_inverse``), its rebuild
    bookkeeping and the saving of all that (``state``; the arrays named in ``_STATE``).
    Subclasses give ``update_counts()``."""

    #: the arrays ``state()`` copies (besides the rebuild bookkeeping)
    _STATE: tuple = ()

    def __init__(self, geometry, alpha):
        self.block_jacobi = BlockPreconditioner(geometry, alpha)
        self.m = self.block_jacobi.m
        self.ng = geometry.n_groups
        self._att = np.zeros(geometry.n_active, dtype=np.uint8)
        self._since_rebuild = 0
        self._valid = False                           # F^-1 built (else: rebuild at next update)
        self.updates = 0
        self.factorisations = 0

    def state(self) -> dict:
        """A copy of what the coarse level carries from one set to the next. F^-1 follows the
        set by updates, so it holds the rounding of its history: a path that must be repeatable
        bit for bit (a preload snapshot taken ahead and put back) saves and restores it."""
        out = {k: getattr(self, k).copy() for k in self._STATE}
        out["since"], out["valid"] = self._since_rebuild, self._valid
        return out

    def set_state(self, state) -> None:
        """Restore a ``state()``; None forgets the history (F^-1 is rebuilt densely from the set
        at the next update, a function of the set alone)."""
        if state is None:
            self._valid = False
            return
        for k in self._STATE:
            getattr(self, k)[...] = state[k]
        self._since_rebuild, self._valid = state["since"], state["valid"]
        self._restored()

    def _restored(self) -> None:
        """Recompute what derives from the restored arrays (nothing here)."""

    def _install_inverse(self, idx, f) -> None:
        """A dense rebuild: F^-1 = inv(f) (symmetrised) on the unknowns ``idx``, zero elsewhere."""
        inv = np.zeros((0, 0))
        if len(idx):
            inv = np.linalg.inv(f)
            inv += inv.T
            inv *= 0.5
        self._store_inverse(idx, inv)
        self._since_rebuild = 0
        self._valid = True
        self.factorisations += 1

    def _store_inverse(self, idx, inv) -> None:
        """Keep ``inv`` as F^-1 on the unknowns ``idx`` (zero elsewhere)."""
        self._finv[:] = 0.0
        self._finv[np.ix_(idx, idx)] = inv

    @property
    def one_level(self):
        """The preconditioner without its coarse level."""
        return self.block_jacobi

    @property
    def trust_estimate(self) -> tuple:
        """(estimator, safety) of the local cascade's trust test: the block level alone, with
        the safety of block Jacobi. The force level corrects each far pillar's mean but not the
        gradient of the field across it, which made it a *worse* estimate of single elements'
        changes (largest true/estimate ratio 4.5 against 3.4 for block Jacobi on the default
        scene; benchmarks/NOTES.md §20)."""
        return self.block_jacobi.trust_estimate

    def work_arrays(self) -> dict:
        """The arrays this preconditioner owns (its block-Jacobi level's included), by name."""
        out = {f"block_{k}": v for k, v in self.block_jacobi.work_arrays().items()}
        out.update({k: v for k, v in vars(self).items() if isinstance(v, np.ndarray)})
        return out

    def cache_stats(self) -> dict:
        """The block level's cache statistics plus the coarse level's update counts."""
        out = self.block_jacobi.cache_stats()
        out.update(self.update_counts())
        return out

    @property
    def coarse_inverse(self) -> np.ndarray:
        """F^-1 as kept (zero rows and columns for unknowns not in use), read-only."""
        v = self._finv.view()
        v.flags.writeable = False
        return v

    def update_counts(self) -> dict:
        """Counts of the coarse level's dense rebuilds and updates so far."""
        raise NotImplementedError


class TwoLevelPreconditioner(CoarseLevel):
    """Block Jacobi plus a coarse pillar-force correction (see the module docstring)."""

    #: the ``solver.preconditioner`` value that builds this one (``auto`` reports its choice)
    kind = "two_level"

    #: rank-one updates of F^-1 between two dense rebuilds (bounds the rounding they accumulate)
    REBUILD_EVERY = 64
    #: a set change moving more pillars than this (and than an eighth of those in contact) is
    #: a dense rebuild: it costs less than that many updates
    MAX_UPDATES_PER_CHANGE = 8
    #: an update whose pivot is below this times its natural scale (W_g, 1/W_g or 1) rebuilds
    PIVOT_TOL = 1e-8

    _STATE = ("_att", "_w", "_W", "_finv")

    def __init__(self, geometry, alpha):
        super().__init__(geometry, alpha)
        m = self.m
        h = geometry.h
        cy = geometry.iy.reshape(self.ng, m).mean(axis=1) * h
        cx = geometry.ix.reshape(self.ng, m).mean(axis=1) * h
        self._far = love(cx[:, None] - cx[None, :], cy[:, None] - cy[None, :], h)
        np.fill_diagonal(self._far, 0.0)              # F's diagonal is 1/W_g (exact)
        self._w = np.zeros(geometry.n_active)         # Z, element by element
        self._W = np.zeros(self.ng)                   # W_g (0: pillar out of contact)
        self._inv_w = np.zeros(self.ng)               # 1/W_g (0: out of contact)
        self._finv = np.zeros((self.ng, self.ng))     # F^-1 on the pillars in contact
        self._c = np.zeros(self.ng)
        self.rank_one_updates = 0

    def update_counts(self) -> dict:
        """Dense rebuilds and rank-one updates of F^-1 so far."""
        return {"coarse_factorisations": self.factorisations,
                "coarse_rank_one_updates": self.rank_one_updates}

    def _restored(self) -> None:
        """1/W_g from the restored W."""
        self._inv_w = np.divide(1.0, self._W, out=np.zeros_like(self._W), where=self._W > 0.0)

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``: Z, W and F^-1 follow it exactly."""
        self.block_jacobi.update(att)
        if self._valid and np.array_equal(att, self._att):
            return
        self.updates += 1
        ng, m = self.ng, self.m
        # only pillars whose attached elements changed get new weights: Z_g and W_g depend on
        # pillar g's set alone, and recomputing the others can move them by an ulp (the block
        # products' rounding depends on memory alignment), which would be a spurious update
        moved = np.arange(ng) if not self._valid else np.flatnonzero(
            (att != self._att).reshape(ng, m).any(axis=1))
        self._att[:] = att
        ones = (att != 0).astype(np.float64)
        z = np.empty_like(self._w)
        self.block_jacobi.apply(ones, att, z)                 # Z = M^-1 1_S
        w2 = self._w.reshape(ng, m)
        w2[moved] = z.reshape(ng, m)[moved]
        W = self._W.copy()
        W[moved] = w2[moved].sum(axis=1)
        W[W <= 0.0] = 0.0
        changed = moved[W[moved] != self._W[moved]]
        n_in = int(np.count_nonzero(W))
        if not self._valid or len(changed) > max(self.MAX_UPDATES_PER_CHANGE, n_in // 8) \
                or self._since_rebuild + len(changed) > self.REBUILD_EVERY \
                or not self._follow(changed, W):
            self._rebuild(W)
        self._W = W
        self._inv_w = np.divide(1.0, W, out=np.zeros_like(W), where=W > 0.0)

    def coarse_matrix(self, W=None) -> tuple:
        """(pillars in contact, F on them) for the weights W (default: the current ones)."""
        W = self._W if W is None else W
        g = np.flatnonzero(W > 0.0)
        F = self._far[np.ix_(g, g)]
        F[np.diag_indices(len(g))] = 1.0 / W[g]
        return g, F

    def _rebuild(self, W) -> None:
        self._install_inverse(*self.coarse_matrix(W))

    def _follow(self, changed, W) -> bool:
        """Update F^-1 for the pillars in ``changed`` (old W: ``self._W``, new: ``W``) one at a
        time; False (F^-1 then to be rebuilt) at the first pivot that is not safely positive."""
        finv = self._finv
        for g in changed:
            old, new = self._W[g], W[g]
            if new == 0.0:                                  # the pillar leaves: drop g
                v = finv[:, g].copy()
                if not v[g] > self.PIVOT_TOL * old:     # F^-1_gg >= W_g when SPD
                    return False
                finv -= np.outer(v, v) * (1.0 / v[g])
                finv[g, :] = 0.0
                finv[:, g] = 0.0
            elif old == 0.0:                                # the pillar joins: border by g
                u = finv @ self._far[:, g]
                s = 1.0 / new - float(self._far[:, g] @ u)
                if not s > self.PIVOT_TOL / new:
                    return False
                finv += np.outer(u, u) * (1.0 / s)
                finv[:, g] = -u / s
                finv[g, :] = finv[:, g]
                finv[g, g] = 1.0 / s
            else:                                           # F_gg: 1/old -> 1/new
                delta = 1.0 / new - 1.0 / old
                v = finv[:, g].copy()
                den = 1.0 + delta * v[g]
                if not den > self.PIVOT_TOL:
                    return False
                finv -= np.outer(v, v) * (delta / den)
            self._since_rebuild += 1
            self.rank_one_updates += 1
        return True

    def apply(self, r, att, z) -> float:
        """z <- (two-level preconditioner) r on the attached set; returns r.z."""
        self.block_jacobi.apply(r, att, z)
        w2 = self._w.reshape(self.ng, self.m)
        c = np.einsum("ij,ij->i", w2, r.reshape(self.ng, self.m), out=self._c)   # Z^T r
        ch = c * self._inv_w                                                      # Zh^T r
        coef = (self._finv @ ch - c) * self._inv_w
        z.reshape(self.ng, self.m)[:] += coef[:, None] * w2
        return float(r @ z)

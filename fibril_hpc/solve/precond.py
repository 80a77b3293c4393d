"""Preconditioners of the attached-set operator A = K_SS + alpha B B^T (docs/model.md §4).

* :class:`DiagonalPreconditioner` -- P = c0 I + alpha B B^T, inverted per pillar by
  Sherman-Morrison (O(n), any geometry).
* :class:`BlockPreconditioner` -- block Jacobi with the *exact* dense pillar block
  P_n = K_nn + alpha 1 1^T restricted to the pillar's attached elements. It captures the stress
  concentration at the pillar edge, which dominates the conditioning, so CG needs a few iterations
  nearly independent of the resolution (measurements: ``benchmarks/NOTES.md``).
  Used when all groups share one footprint (pillar brushes) of at most ``max_block`` elements.
  Fully attached pillars share one inverse and are applied as one matrix product; partly attached
  ones get their own inverse, cached by attachment pattern and rebuilt only when it changes.

Both expose ``update(att)`` (called at the start of every solve), ``apply(r, att, z) -> r.z``,
``one_level`` (themselves) and ``state()`` / ``set_state(state)`` (None for both: they are
functions of the attached set alone). ``"two_level"`` adds a coarse pillar-force level to the
block one (:mod:`fibril_hpc.solve.coarse`), ``"moments"`` a coarse level of force and two tilts per
pillar (:mod:`fibril_hpc.solve.moments`); their ``one_level`` is the block one. Which one a
scene gets is decided in :mod:`fibril_hpc.solve.factory`, above every level. The block level
also solves its blocks for chosen pillars and several right-hand sides (``apply_groups``, the
moment level's modes).
"""

from __future__ import annotations

import numpy as np

from ..elastic.greens import love
from ..kernels import compiled as kern


class DiagonalPreconditioner:
    """P = c0 I + alpha B B^T on the attached set, inverted per pillar by Sherman-Morrison.

    Works on any geometry (docs/model.md §4).
    """

    #: the ``solver.preconditioner`` value that builds this one (``auto`` reports its choice)
    kind = "diagonal"

    def __init__(self, geometry, alpha: float, c0: float):
        self.starts = geometry.starts
        self.alpha = alpha if isinstance(alpha, np.ndarray) else float(alpha)
        self.c0 = float(c0)

    @property
    def one_level(self):
        """This preconditioner (it has no coarse level)."""
        return self

    @property
    def trust_estimate(self) -> tuple:
        """(estimator, safety) of the local cascade's trust test: one application of this
        preconditioner estimates the far pillars' response, and a decision is trusted when its
        margin exceeds 4 times the estimate (:class:`~fibril_hpc.solve.cascade.LocalCascade`)."""
        return self, 4.0

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``."""
        pass

    def state(self):
        """None: this preconditioner is a function of the attached set alone."""
        return None

    def set_state(self, state) -> None:
        """Nothing to restore (see ``state``)."""

    def apply(self, r, att, z) -> float:
        """z <- P^-1 r on the attached set; returns r.z."""
        return kern.precondition(r, att, self.starts, self.alpha, self.c0, z)


def uniform_footprint(geometry):
    """Group size m if every group has the same relative element layout, else None."""
    sizes = np.diff(geometry.starts)
    if len(sizes) == 0 or np.any(sizes != sizes[0]):
        return None
    m = int(sizes[0])
    iy = geometry.iy.reshape(-1, m)
    ix = geometry.ix.reshape(-1, m)
    if np.array_equal(iy - iy[:, :1], np.broadcast_to(iy[0] - iy[0, 0], iy.shape)) and \
            np.array_equal(ix - ix[:, :1], np.broadcast_to(ix[0] - ix[0, 0], ix.shape)):
        return m
    return None


class BlockPreconditioner:
    """Block Jacobi with the exact dense pillar block on its attached elements.

    Needs groups that share one footprint (docs/model.md §4).
    """

    #: the ``solver.preconditioner`` value that builds this one (``auto`` reports its choice)
    kind = "block"

    def __init__(self, geometry, alpha: float, cache_bytes: int = 64 * 2**20):
        m = uniform_footprint(geometry)
        if m is None:
            raise ValueError("block preconditioner needs groups with one shared footprint")
        self.m = m
        self.ng = geometry.n_groups
        h = geometry.h
        x = geometry.ix[:m] * h
        y = geometry.iy[:m] * h
        block = love(x[:, None] - x[None, :], y[:, None] - y[None, :], h)
        # per-pillar stiffness: the blocks are inverted without the spring term, which each
        # pillar adds as a rank-one (Sherman-Morrison) correction in apply
        self.alpha_g = alpha if isinstance(alpha, np.ndarray) else None
        if self.alpha_g is None and alpha != 0.0:
            block = block + alpha
        self.block = block
        self.full_inv = np.linalg.inv(block)
        if self.alpha_g is not None:
            self._w_full = self.full_inv.sum(axis=1)        # B^-1 1
            self._c_full = float(self._w_full.sum())        # 1^T B^-1 1
        # partial-pattern inverses are m x m float64: bound the cache by memory, not count
        self.max_cache = max(8, cache_bytes // (8 * m * m))
        self._cache: dict = {}
        self._att = np.zeros(geometry.n_active, dtype=np.uint8)
        self._counts = np.zeros(self.ng, dtype=np.int64)
        self._full = np.zeros(self.ng, dtype=bool)
        self._n_full = 0
        self._partial: dict = {}          # group -> (local indices, inverse)
        self.updates = 0

    @property
    def one_level(self):
        """This preconditioner (it has no coarse level)."""
        return self

    @property
    def trust_estimate(self) -> tuple:
        """(estimator, safety) of the local cascade's trust test: one block-Jacobi step (each
        far pillar's exact block, the others held) with a safety factor of 4; the largest ratio
        of a true change to this estimate measured on the default scene was 3.4
        (benchmarks/NOTES.md §20)."""
        return self, 4.0

    def work_arrays(self) -> dict:
        """The arrays this preconditioner owns, cached partial inverses included, by name (for
        read-only use, e.g. memory accounting)."""
        out = {k: v for k, v in vars(self).items() if isinstance(v, np.ndarray)}
        for i, (_, inv) in enumerate(self._cache.values()):
            out[f"cached_inverse_{i}"] = inv
        return out

    def state(self):
        """None: this preconditioner is a function of the attached set alone (its cache holds
        inverses that depend only on their pattern)."""
        return None

    def set_state(self, state) -> None:
        """Nothing to restore (see ``state``)."""

    def cache_stats(self) -> dict:
        """Size of the partial-inverse cache: entries held, the bound, block size, updates."""
        return {"cached_partial_inverses": len(self._cache), "max_cache": self.max_cache,
                "block_elements": int(self.m), "updates": self.updates}

    def _inverse(self, pattern: np.ndarray):
        key = pattern.tobytes()
        inv = self._cache.get(key)
        if inv is None:
            idx = np.flatnonzero(pattern)
            inv = (idx, np.linalg.inv(self.block[np.ix_(idx, idx)]))
            if len(self._cache) >= self.max_cache:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = inv
        return inv

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``."""
        if np.array_equal(att, self._att):
            return
        self.updates += 1
        m = self.m
        changed = np.flatnonzero((att != self._att).reshape(self.ng, m).any(axis=1))
        self._att[:] = att
        a2 = self._att.reshape(self.ng, m)
        counts = a2.sum(axis=1)
        self._full = counts == m
        self._n_full = int(np.count_nonzero(self._full))
        for g in changed:
            self._partial.pop(int(g), None)
            if 0 < counts[g] < m:
                self._partial[int(g)] = self._inverse(a2[g] != 0)

    def apply(self, r, att, z) -> float:
        """z <- P^-1 r on the attached set; returns r.z."""
        m = self.m
        r2 = r.reshape(self.ng, m)
        z2 = z.reshape(self.ng, m)
        z2[:] = 0.0
        if self._n_full == self.ng:
            np.matmul(r2, self.full_inv, out=z2)        # the block is symmetric
        elif self._n_full:
            z2[self._full] = r2[self._full] @ self.full_inv
        for g, (idx, inv) in self._partial.items():
            z2[g, idx] = inv @ r2[g, idx]
        if self.alpha_g is not None:
            self._springs(r2, z2)
        return float(r @ z)

    def apply_groups(self, groups, rhs) -> np.ndarray:
        """M_g^-1 rhs[i] for pillar g = groups[i] on the attached set of the last ``update``.

        ``rhs`` is (len(groups), m, k): k right-hand sides per pillar in its element order;
        entries on free elements are ignored and the result is zero there (as in ``apply``).
        """
        out = np.zeros_like(rhs)
        full = self._full[groups]
        if full.any():
            out[full] = np.matmul(self.full_inv, rhs[full])
        for i in np.flatnonzero(~full):
            part = self._partial.get(int(groups[i]))
            if part is not None:
                idx, inv = part
                out[i, idx] = inv @ rhs[i, idx]
        if self.alpha_g is not None:
            for i, g in enumerate(groups):
                if full[i]:
                    w, c = self._w_full, self._c_full
                elif int(g) in self._partial:
                    idx, inv = self._partial[int(g)]
                    w = np.zeros(self.m)
                    w[idx] = inv.sum(axis=1)
                    c = float(w.sum())
                else:
                    continue
                a = self.alpha_g[g]
                out[i] -= (a / (1.0 + a * c)) * w[:, None] * out[i].sum(axis=0)[None, :]
        return out

    def _springs(self, r2, z2):
        """(B + a 1 1^T)^-1 r = B^-1 r - a w (1^T B^-1 r) / (1 + a 1^T w), w = B^-1 1, per pillar."""
        a = self.alpha_g
        full = self._full
        if full.any():
            w = self._w_full
            t = z2[full].sum(axis=1)
            z2[full] -= (a[full] * t / (1.0 + a[full] * self._c_full))[:, None] * w[None, :]
        for g, (idx, inv) in self._partial.items():
            w = inv.sum(axis=1)
            z2[g, idx] -= a[g] * w * z2[g, idx].sum() / (1.0 + a[g] * w.sum())

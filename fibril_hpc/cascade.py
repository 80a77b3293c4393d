"""Local solves on a few pillars with the far field held fixed (the ``cascade: local`` path).

A contact event at fixed plate displacement d changes the attached set of one or a few pillars.
Re-solving the whole grid after every ring of a detaching pillar pays for a change confined to a
small fraction of the unknowns. The local path instead solves the pillars whose sets changed
*directly*, with their exact dense blocks, while the pressure on every other pillar is held:

    (K_SS + alpha B B^T) p_S = b_S - u_far_S,   u_far = K p  restricted to the local elements
                                                 minus the local pillars' own contribution,

where S is the attached part of the local pillars, K_SS their dense influence matrix (the same
Love coefficients as the FFT product, read from the real-space table) and alpha B B^T the spring
coupling of elements of one pillar (alpha = h^2/k, 0 for rigid pillars). The contact set of the
local pillars is updated with the same rule as the global cascade (detach p < -sigma_c, attach a
closed gap) and the local solve repeated until it stops changing. The caller then confirms with a
global solve, which restores the coupling to the rest of the grid; only if that solve flips more
elements does a new local round start (on the pillars that flipped). The fixed point is the one of
the global cascade: the final state is always a global solve at full tolerance on a set that the
update rule leaves unchanged.
"""

from __future__ import annotations

import numpy as np

from .kernels import compiled as kern


class LocalCascade:
    """Dense local solves on groups of one model (built lazily, no state between calls).

    Parameters
    ----------
    model : Model
        Supplies geometry, operator (its real-space influence table), spring stiffness.
    max_elements : int
        Largest number of elements (attached or not) of the local pillars handled directly; a
        larger change returns ``None`` from :meth:`elements` and the caller falls back to global
        solves.
    """

    def __init__(self, model, max_elements: int = 1200):
        self.model = model
        g = model.geometry
        self.starts = g.starts
        self.iy = g.iy
        self.ix = g.ix
        self.z0 = g.z0
        self.h2 = g.h * g.h
        self.alpha = 0.0 if model.rigid else g.h * g.h / model.k
        self.inv_k = 0.0 if model.rigid else 1.0 / model.k
        self.max_elements = int(max_elements)
        self.local_solves = 0

    def elements(self, groups):
        """(element indices, local starts) of ``groups``, or None if there are too many."""
        groups = np.asarray(groups, dtype=np.int64)
        sizes = self.starts[groups + 1] - self.starts[groups]
        if sizes.sum() > self.max_elements:
            return None
        idx = np.concatenate([np.arange(self.starts[q], self.starts[q + 1]) for q in groups])
        lstarts = np.zeros(len(groups) + 1, dtype=np.int64)
        np.cumsum(sizes, out=lstarts[1:])
        return idx, lstarts

    def _matrix(self, idx):
        table = self.model.operator.table
        iy, ix = self.iy[idx], self.ix[idx]
        return table[np.abs(iy[:, None] - iy[None, :]), np.abs(ix[:, None] - ix[None, :])]

    def _solve_set(self, K, same, att_l, rhs):
        s = np.flatnonzero(att_l)
        x = np.zeros(len(att_l))
        if len(s):
            M = K[np.ix_(s, s)]
            if self.alpha != 0.0:
                M = M + self.alpha * same[np.ix_(s, s)]
            x[s] = np.linalg.solve(M, rhs[s])
        self.local_solves += 1
        return x

    def solve(self, groups, b, x, x_ref, u, att) -> np.ndarray | None:
        """x <- exact solution on ``groups`` (attached elements) with the rest of x held.

        ``u`` holds K x_ref on every element, and x differs from x_ref only on ``groups``. Only
        ``x`` is changed (the caller's next global solve corrects u from x - x_ref). Returns
        the element indices or None when the groups are too large for a dense solve.
        """
        el = self.elements(groups)
        if el is None:
            return None
        idx, lstarts = el
        K = self._matrix(idx)
        lab = np.repeat(np.arange(len(lstarts) - 1), np.diff(lstarts))
        same = (lab[:, None] == lab[None, :]).astype(np.float64)
        u_far = u[idx] - K @ x_ref[idx]
        x[idx] = self._solve_set(K, same, att[idx] != 0, b[idx] - u_far)
        return idx

    def cascade(self, groups, d, b, p, p_ref, u, att, sigma_c, tol_p, tol_g, worst_only,
                max_passes: int = 10_000):
        """Local detachment/attachment cascade at plate displacement d on ``groups``.

        Solves, updates the local contact set with the global rule, repeats until it stops
        changing; writes p and att of the local elements. Returns the number of local passes,
        or None (nothing changed) when the groups are too large for a dense solve.
        """
        el = self.elements(groups)
        if el is None:
            return None
        idx, lstarts = el
        K = self._matrix(idx)
        lab = np.repeat(np.arange(len(lstarts) - 1), np.diff(lstarts))
        same = (lab[:, None] == lab[None, :]).astype(np.float64)
        u_far = u[idx] - K @ p_ref[idx]
        rhs = b[idx] - u_far
        att_l = att[idx].copy()
        z0 = self.z0[idx]
        ng = len(lstarts) - 1
        f = np.zeros(ng)
        dl = np.zeros(ng)
        g = np.empty(len(idx))
        for n in range(1, max_passes + 1):
            p_l = self._solve_set(K, same, att_l != 0, rhs)
            u_l = u_far + K @ p_l
            kern.group_sums(p_l, att_l, lstarts, f)
            np.multiply(f, self.h2 * self.inv_k, out=dl)
            kern.gaps(u_l, lstarts, z0, 1.0, d, dl, g)
            nd, na = kern.update_contact_set(p_l, g, att_l, lstarts, sigma_c, tol_p, tol_g,
                                             worst_only)
            if nd == 0 and na == 0:
                break
        p[idx] = p_l
        att[idx] = att_l
        return n

"""Local solves on a few pillars with the far field held fixed (the ``cascade: local`` path).

A contact event at fixed plate displacement d changes the attached set of one or a few pillars.
Re-solving the whole grid after every ring of a detaching pillar pays for a change confined to a
small fraction of the unknowns. The local path instead solves the pillars whose sets changed
*directly*, with their exact dense blocks, while the pressure on every other pillar is held:

    (K_SS + alpha B B^T) p_S = b_S - u_far_S,   u_far = K p  restricted to the local elements
                                                 minus the local pillars' own contribution,

where S is the attached part of the local pillars, K_SS their dense influence matrix (the same
Love coefficients as the FFT product, read from the real-space table) and alpha B B^T the spring
coupling of elements of one pillar (alpha = h^2/k, 0 for rigid pillars; with per-pillar
stiffnesses alpha_n = h^2/k_n on the pairs of elements of pillar n). The contact set of the
local pillars is updated with the same rule as the global cascade (detach p < -sigma_c, attach a
closed gap) and the local solve repeated until it stops changing. The caller then confirms with a
global solve, which restores the coupling to the rest of the grid; only if that solve flips more
elements does a new local round start (on the pillars that flipped). The fixed point is the one of
the global cascade: the final state is always a global solve at full tolerance on a set that the
update rule leaves unchanged.
"""

from __future__ import annotations

import numpy as np

from ..geometry.scaling import E_STAR
from ..kernels import compiled as kern


class LocalCascade:
    """Dense local solves on groups of one model (labels cached on first use; no solver state
    kept between calls).

    Parameters
    ----------
    model : Model
        Supplies geometry, operator (its real-space influence table), spring stiffness.
    max_elements : int or None
        Largest number of elements (attached or not) of the local pillars handled directly; a
        larger change returns ``None`` from :meth:`elements` and the caller falls back to global
        solves. Default: where a dense solve (s^3/3 multiply-adds) costs about as much as 3 FFT
        pairs (~5 m^2 log2 m each), but at least two pillars.
    """

    def __init__(self, model, max_elements: int | None = None):
        self.model = model
        g = model.geometry
        self.starts = g.starts
        self.iy = g.iy
        self.ix = g.ix
        self.z0 = g.z0
        self.h2 = g.h * g.h
        # per-pillar stiffnesses: one alpha_n and 1/k_n per pillar (arrays), else numbers
        self.alpha = 0.0 if model.rigid else g.h * g.h / model.k
        self.inv_k = 0.0 if model.rigid else 1.0 / model.k
        self.per_pillar = model.per_pillar
        if max_elements is None:
            m = model.operator.m
            biggest = int(np.diff(self.starts).max()) if len(self.starts) > 1 else 1
            max_elements = max(2 * biggest, int((45.0 * m * m * np.log2(m)) ** (1.0 / 3.0)))
        self.max_elements = int(max_elements)
        self._lab = None
        self._cen = None

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

    def _coupling(self, groups, lstarts):
        """alpha B B^T of the local elements (None for rigid pillars): alpha (alpha_n of pillar
        n with per-pillar stiffnesses) on every pair of elements of one pillar."""
        if not self.per_pillar and self.alpha == 0.0:
            return None
        lab = np.repeat(np.arange(len(lstarts) - 1), np.diff(lstarts))
        same = (lab[:, None] == lab[None, :]).astype(np.float64)
        if not self.per_pillar:
            return self.alpha * same
        return same * self.alpha[np.asarray(groups)[lab]][:, None]

    def _inv_k_of(self, groups):
        """1/k of the local pillars: the number, or the per-pillar values of ``groups``."""
        return self.inv_k[np.asarray(groups)] if self.per_pillar else self.inv_k

    def _solve_set(self, K, C, att_l, rhs):
        s = np.flatnonzero(att_l)
        x = np.zeros(len(att_l))
        if len(s):
            M = K[np.ix_(s, s)]
            if C is not None:
                M = M + C[np.ix_(s, s)]
            x[s] = np.linalg.solve(M, rhs[s])
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
        C = self._coupling(groups, lstarts)
        u_far = u[idx] - K @ x_ref[idx]
        x[idx] = self._solve_set(K, C, att[idx] != 0, b[idx] - u_far)
        return idx

    def cascade(self, groups, d, b, p, p_ref, u, g, att, sigma_c, tol_p, tol_g, worst_only,
                precond, max_passes: int = 10_000):
        """Local detachment/attachment cascade at plate displacement d on ``groups``.

        Each pass solves the local pillars with the rest held and proposes the flips of the
        global update rule on them. The proposal is *trusted* only if the coupling the held far
        field would add cannot change any decision: the change of u everywhere caused by the
        local pressure change since the last global solve is summed directly, the far pillars'
        response to it estimated by one application of the estimator that the CG preconditioner
        ``precond`` names (``precond.trust_estimate``: block Jacobi, exact per pillar, or the
        moment level's whole preconditioner, which also couples the far pillars' forces and
        tilts), and that response's feedback on the local pillars by their exact blocks; every
        element's distance to its threshold (``p = -sigma_c - tol_p`` attached, ``g = -tol_g``
        free) must exceed the estimator's safety factor times its estimated change (the factors
        come from measured ratios of true changes to estimated ones, benchmarks/NOTES.md). A
        trusted proposal is applied and the next pass runs; an untrusted one is dropped (its
        pressures are kept as the next global solve's start) and the caller's global solve
        decides, as in the reference cascade. ``p`` and ``att`` of the local elements are
        written; ``u`` (= K p_ref) and ``g`` (the far elements' gaps) are only read.

        Returns (passes applied, reached a local fixed point) or None when the groups are too
        large for a dense solve.
        """
        groups = np.asarray(groups, dtype=np.int64)
        el = self.elements(groups)
        if el is None:
            return None
        idx, lstarts = el
        n = len(p)
        K = self._matrix(idx)
        C = self._coupling(groups, lstarts)
        inv_k_l = self._inv_k_of(groups)
        hk = self.h2 * inv_k_l
        u_far = u[idx] - K @ p_ref[idx]
        rhs = b[idx] - u_far
        att_l = att[idx].copy()
        z0 = self.z0[idx]
        ng = len(lstarts) - 1
        f = np.zeros(ng)
        dl = np.zeros(ng)
        g_l = np.empty(len(idx))
        thr = -(sigma_c + tol_p)
        far = np.ones(n, dtype=bool)
        far[idx] = False
        far_att = np.flatnonzero(far & (att != 0))
        far_free = np.flatnonzero(far & (att == 0))
        m_far_att = p[far_att] - thr
        m_far_free = g[far_free] + tol_g
        table = self.model.operator.table
        applied = 0
        fixed = False
        p_l = p[idx].copy()
        for _ in range(max_passes):
            p_l = self._solve_set(K, C, att_l != 0, rhs)
            u_l = u_far + K @ p_l
            kern.group_sums(p_l, att_l, lstarts, f)
            np.multiply(f, hk, out=dl)
            kern.gaps(u_l, lstarts, z0, 1.0, d, dl, g_l)
            p_try, att_try = p_l.copy(), att_l.copy()
            nd, na = kern.update_contact_set(p_try, g_l, att_try, lstarts, sigma_c, tol_p, tol_g,
                                             worst_only)
            if nd == 0 and na == 0:
                fixed = True
                break
            if not self._trusted(groups, idx, lstarts, K, C, inv_k_l, att_l, p_l, g_l, p_ref, att,
                                 far_att, far_free, m_far_att, m_far_free, thr, tol_g, precond,
                                 table):
                break
            p_l, att_l = p_try, att_try
            applied += 1
        p[idx] = p_l
        att[idx] = att_l
        return applied, fixed

    #: pillars whose centre lies within this many pillar radii of a local pillar's centre get the
    #: exact direct sums in the trust test; farther ones the point-force (monopole) field
    NEAR = 10.0

    def _centres(self):
        if self._cen is None:
            lab = self._labels()
            cnt = np.maximum(np.bincount(lab, minlength=len(self.starts) - 1), 1)
            cy = np.bincount(lab, weights=self.iy, minlength=len(cnt)) / cnt
            cx = np.bincount(lab, weights=self.ix, minlength=len(cnt)) / cnt
            rad = np.sqrt((self.iy - cy[lab]) ** 2 + (self.ix - cx[lab]) ** 2)
            rmax = float(rad.max()) + 1.0 if len(rad) else 1.0
            self._cen = (cy, cx, rmax)
        return self._cen

    def _monopole(self, tgt, cy, cx, forces):
        """Point-force field sum_b forces[b] h^2 / (pi E* r) at the elements ``tgt`` (centres
        (cy, cx) in element units)."""
        out = np.zeros(len(tgt))
        if len(forces) and len(tgt):
            kern.point_forces_at(out, tgt, self.iy, self.ix, cy, cx, forces)
            out *= self.model.geometry.h / (np.pi * E_STAR)
        return out

    def _trusted(self, groups, idx, lstarts, K, C, inv_k_l, att_l, p_l, g_l, p_ref, att, far_att,
                 far_free, m_far_att, m_far_free, thr, tol_g, precond, table) -> bool:
        n = len(p_ref)
        iy, ix = self.iy, self.ix
        lab = self._labels()
        cy, cx, rmax = self._centres()
        ng = len(self.starts) - 1
        # groups near the local ones: exact direct sums; the others: monopole fields
        dist = np.full(ng, np.inf)
        for q in groups:
            dist = np.minimum(dist, np.hypot(cy - cy[q], cx - cx[q]))
        local = np.zeros(ng, dtype=bool)
        local[groups] = True
        near_g = ~local & (dist <= self.NEAR * rmax)
        far_g = ~local & ~near_g
        near_el = np.flatnonzero(near_g[lab])
        far_el = np.flatnonzero(far_g[lab])
        dp = p_l - p_ref[idx]
        src = np.flatnonzero(dp)
        du = np.zeros(n)
        if len(near_el):
            tmp = np.zeros(len(near_el))
            kern.point_loads_at(tmp, near_el, iy, ix, idx[src], dp[src], table)
            du[near_el] = tmp
        if len(far_el):
            lg = np.repeat(np.arange(len(groups)), np.diff(lstarts))
            dF = np.bincount(lg, weights=dp, minlength=len(groups))
            du[far_el] = self._monopole(far_el, cy[groups], cx[groups], dF)
        # far pillars' first-order response (their exact blocks, the rest held)
        r = np.zeros(n)
        r[far_att] = -du[far_att]
        dp_far = np.zeros(n)
        estimator, S = precond.trust_estimate
        estimator.update(att)
        estimator.apply(r, att, dp_far)
        dp_far[idx] = 0.0
        fsum = np.zeros(ng)
        kern.group_sums(dp_far, att, self.starts, fsum)
        dg_far = du[far_free] + (fsum * self.h2 * self.inv_k)[lab[far_free]]
        if np.any(np.abs(m_far_att) <= S * np.abs(dp_far[far_att])) or \
                np.any(np.abs(m_far_free) <= S * np.abs(dg_far)):
            return False
        # feedback of that response on the local pillars (their exact blocks again)
        du_l = np.zeros(len(idx))
        srcn = near_el[dp_far[near_el] != 0.0]
        if len(srcn):
            kern.point_loads_at(du_l, idx, iy, ix, srcn, dp_far[srcn], table)
        fg = np.flatnonzero(far_g)
        if len(fg):
            du_l += self._monopole(idx, cy[fg], cx[fg],
                                   np.bincount(lab, weights=dp_far, minlength=ng)[fg])
        on = att_l != 0
        dpl = np.zeros(len(idx))
        s = np.flatnonzero(on)
        if len(s):
            M = K[np.ix_(s, s)]
            if C is not None:
                M = M + C[np.ix_(s, s)]
            dpl[s] = -np.linalg.solve(M, du_l[s])
        f = np.zeros(len(lstarts) - 1)
        kern.group_sums(dpl, att_l, lstarts, f)
        dgl = du_l + K @ dpl + np.repeat(f * self.h2 * inv_k_l, np.diff(lstarts))
        m_att = p_l[on] - thr
        m_free = g_l[~on] + tol_g
        return not (np.any(np.abs(m_att) <= S * np.abs(dpl[on]))
                    or np.any(np.abs(m_free) <= S * np.abs(dgl[~on])))

    def _labels(self):
        if self._lab is None:
            self._lab = np.repeat(np.arange(len(self.starts) - 1), np.diff(self.starts))
        return self._lab

"""A coarse level of three moments per pillar (force and two tilts) for the block-Jacobi
preconditioner (``solver.preconditioner: moments``; what ``auto`` picks where the FFT is dear
relative to the pillar count, :func:`fibril_hpc.solve.factory.prefers_moments`).

The force-only coarse level (:mod:`fibril_hpc.solve.coarse`) couples the pillars through their total
forces; what the block-Jacobi level then still gets wrong is mostly the *tilt* a neighbour's
field imposes across a pillar's footprint (its gradient), which the force level cannot carry.
Here each pillar in contact has three coarse unknowns, its moments

    q_g = C_g^T p_g,   C_g = [1, x - x_g, y - y_g] on the attached elements of pillar g,

(its force and its two first moments about the footprint centre), with the modes of the exact
block-Jacobi level M_g = A_gg: Z_g = M_g^-1 C_g, D_g = C_g^T Z_g (3 x 3, SPD) and the
unit-moment shapes Zh_g = Z_g D_g^-1 (C_g^T Zh_g = I). In moment unknowns the coarse matrix
F = Zh^T A Zh has the exact diagonal blocks F_gg = D_g^-1, and off-diagonal blocks from the
multipole expansion of the half-space Green's function G(r) = h^2 / (pi E* r) between the
footprint centres (R = c_h - c_g), to the dipole-dipole term:

    F_gh = [[G,    G_x,   G_y  ],
            [-G_x, -G_xx, -G_xy],
            [-G_y, -G_xy, -G_yy]](R),

the force-force entry being Love's exact coefficient as in the force level. The blocks depend on
the pillars' positions only, so a set change on pillar g changes F only in its diagonal block.
Applied as

    z = M^-1 r + Zh (F^-1 - D) Zh^T r,   D = blockdiag(D_g),

where per pillar M_g^-1 - Zh_g D_g Zh_g^T = M_g^-1 - Z_g D_g^-1 Z_g^T is M_g^-1 with the three
modes projected out (positive semidefinite), so the preconditioner stays SPD for any SPD F^-1.
A pillar whose attached elements do not span the tilts (one or two elements, or one line of
them: D_g ill conditioned) keeps the force unknown only.

F^-1 is kept on the unknowns in use only (a compact (3 n_contact)^2 block of a (3 n_pillars)^2
buffer, with the map between positions and unknowns; ``coarse_inverse`` expands it) and follows
each set change exactly by O(n^2) block updates: a change of the diagonal blocks of pillars that
keep their unknowns is a Woodbury update, pillars whose unknowns change are dropped (Schur
complement on the inverse) and bordered back. It is rebuilt with a dense inverse every
``REBUILD_EVERY`` pillar updates, when one change moves many pillars, or when a pivot is not
safely positive.
"""

from __future__ import annotations

import numpy as np

from ..elastic.greens import love
from ..geometry.scaling import E_STAR
from .coarse import CoarseLevel


def multipole_kernel(rx, ry, h) -> np.ndarray:
    """The coupling block F_gh of the module docstring for offsets R = c_h - c_g = (rx, ry)
    (arrays of one shape S, no zero offset): an array of shape S + (3, 3)."""
    c = h * h / (np.pi * E_STAR)
    r2 = rx * rx + ry * ry
    r = np.sqrt(r2)
    r3 = r2 * r
    r5 = r3 * r2
    gx, gy = -c * rx / r3, -c * ry / r3
    hxx = c * (3.0 * rx * rx - r2) / r5
    hyy = c * (3.0 * ry * ry - r2) / r5
    hxy = 3.0 * c * rx * ry / r5
    t = np.empty(np.shape(rx) + (3, 3))
    t[..., 0, 0] = love(rx, ry, h)
    t[..., 0, 1], t[..., 0, 2] = gx, gy
    t[..., 1, 0], t[..., 2, 0] = -gx, -gy
    t[..., 1, 1], t[..., 1, 2] = -hxx, -hxy
    t[..., 2, 1], t[..., 2, 2] = -hxy, -hyy
    return t


def multipole_couplings(cx, cy, h) -> np.ndarray:
    """F's off-diagonal blocks, (3 n, 3 n) with zero diagonal blocks, for footprint centres
    (cx, cy) and element side h (see the module docstring)."""
    n = len(cx)
    rx = cx[None, :] - cx[:, None]
    ry = cy[None, :] - cy[:, None]
    i = np.arange(n)
    rx[i, i] = 1.0                                  # any nonzero offset: zeroed below
    t = multipole_kernel(rx, ry, h)                 # (n, n, 3, 3)
    t[i, i] = 0.0
    return np.ascontiguousarray(t.transpose(0, 2, 1, 3)).reshape(3 * n, 3 * n)


class MomentModes(CoarseLevel):
    """What the moment coarse levels share (the dense one here, the lattice one of
    :mod:`fibril_hpc.solve.lattice`): per pillar its unit-moment shapes Zh_g, D_g, F_gg = D_g^-1
    and which of its three unknowns are in use, following the attached set pillar by pillar
    (only pillars whose attached elements changed are recomputed)."""

    #: a D_g with a relative eigenvalue below this keeps the force unknown only
    TILT_TOL = 1e-6

    def __init__(self, geometry, alpha):
        super().__init__(geometry, alpha)
        m, ng = self.m, self.ng
        h = geometry.h
        x = (geometry.ix * h).reshape(ng, m)
        y = (geometry.iy * h).reshape(ng, m)
        cx, cy = x.mean(axis=1), y.mean(axis=1)
        self._centres = (cx, cy)
        self._xr = x - cx[:, None]
        self._yr = y - cy[:, None]
        self._zh = np.zeros((ng, m, 3))           # unit-moment shapes (zero for unused modes)
        self._d = np.zeros((ng, 3, 3))            # D_g on the used modes (zero elsewhere)
        self._fgg = np.zeros((ng, 3, 3))          # F_gg = D_g^-1 on the used modes
        self._use = np.zeros((ng, 3), dtype=bool)  # unknowns in use
        self.pillar_updates = 0

    @property
    def trust_estimate(self) -> tuple:
        """(estimator, safety) of the local cascade's trust test: this whole preconditioner (the
        far pillars respond through their blocks *and* their coupled forces and tilts), with a
        safety factor of 2. Measured against true global solves, its largest true/estimate ratio
        was 1.37 on the default scene and 1.08 on a stiff smooth 8 x 8 path, against 3.4 for
        block Jacobi alone (benchmarks/NOTES.md §20)."""
        return self, 2.0

    def centres(self) -> tuple:
        """(x, y) of the footprint centres, one per pillar (physical units)."""
        return self._centres

    def coarse_unknowns(self) -> np.ndarray:
        """(n_pillars, 3) booleans: which of force, x- and y-moment are coarse unknowns now."""
        return self._use.copy()

    def unit_moment_shapes(self) -> np.ndarray:
        """(n_pillars, m, 3) copy of the unit-moment shapes Zh (zero for unknowns not in use)."""
        return self._zh.copy()

    def coarse_diagonal(self, g: int) -> np.ndarray:
        """F_gg = D_g^-1 of pillar g on its unknowns in use."""
        u = np.flatnonzero(self._use[g])
        return self._fgg[g][np.ix_(u, u)]

    # -- the per-pillar level -----------------------------------------------------------------
    def _pillars(self, att, groups):
        """(Zh, D, F_gg, use) of ``groups`` on the attached set ``att``."""
        ng, m = self.ng, self.m
        on = (att != 0).reshape(ng, m)[groups].astype(np.float64)
        cmat = np.stack((on, on * self._xr[groups], on * self._yr[groups]), axis=2)
        z = self.block_jacobi.apply_groups(groups, cmat)
        d = np.matmul(np.swapaxes(cmat, 1, 2), z)
        d = 0.5 * (d + np.swapaxes(d, 1, 2))
        use = np.zeros((len(groups), 3), dtype=bool)
        use[:, 0] = d[:, 0, 0] > 0.0
        s = np.sqrt(np.maximum(np.einsum("gaa->ga", d), 1e-300))
        dn = d / (s[:, :, None] * s[:, None, :])
        tilt = use[:, 0] & (np.linalg.eigvalsh(dn)[:, 0] > self.TILT_TOL)
        use[:, 1:] = tilt[:, None]
        d = d * (use[:, :, None] & use[:, None, :])
        fgg = np.zeros_like(d)
        zh = np.zeros_like(z)
        for k in range(len(groups)):
            u = np.flatnonzero(use[k])
            if len(u):
                inv = np.linalg.inv(d[k][np.ix_(u, u)])
                inv = 0.5 * (inv + inv.T)
                fgg[k][np.ix_(u, u)] = inv
                zh[k][:, u] = z[k][:, u] @ inv
        return zh, d, fgg, use

    def _follow_modes(self, att):
        """Bring the modes to the attached set ``att`` (the block level first): None if nothing
        is to be done, else (pillars recomputed, their old ``use``, their old F_gg)."""
        self.block_jacobi.update(att)
        if self._valid and np.array_equal(att, self._att):
            return None
        self.updates += 1
        ng, m = self.ng, self.m
        changed = np.arange(ng) if not self._valid else np.flatnonzero(
            (att != self._att).reshape(ng, m).any(axis=1))
        self._att[:] = att
        zh, d, fgg, use = self._pillars(att, changed)
        old_use = self._use[changed].copy()
        old_fgg = self._fgg[changed].copy()
        self._zh[changed], self._d[changed] = zh, d
        self._fgg[changed], self._use[changed] = fgg, use
        return changed, old_use, old_fgg

    def _moments(self, r) -> np.ndarray:
        """c = Zh^T r, (n_pillars, 3) (batched over the pillars: matmul is several times faster
        than einsum here)."""
        return np.matmul(r.reshape(self.ng, 1, self.m), self._zh)[:, 0]

    def _correct(self, y, z) -> None:
        """z <- z + Zh y for coarse coefficients y (n_pillars, 3)."""
        z.reshape(self.ng, self.m)[:] += np.matmul(self._zh, y[:, :, None])[:, :, 0]


class MomentTwoLevelPreconditioner(MomentModes):
    """Block Jacobi plus a coarse level of three moments per pillar, its inverse kept dense
    (module docstring)."""

    #: the ``solver.preconditioner`` value that builds this one (``auto`` reports its choice)
    kind = "moments"

    #: pillar updates of F^-1 between two dense rebuilds (bounds the rounding they accumulate)
    REBUILD_EVERY = 256
    #: a change moving more pillars than this (and than an eighth of those in contact) rebuilds
    MAX_UPDATES_PER_CHANGE = 8
    #: a Schur pivot below this (relative) rebuilds
    PIVOT_TOL = 1e-8

    _STATE = ("_att", "_zh", "_d", "_fgg", "_use", "_fc", "_unk", "_pos", "_nu")

    def __init__(self, geometry, alpha):
        super().__init__(geometry, alpha)
        ng = self.ng
        self._t = multipole_couplings(*self._centres, geometry.h)
        # F^-1 on the unknowns in use only, kept compact: _fc[:n, :n] with n = _nu[0], position
        # i holding unknown _unk[i] (_pos: the position of an unknown, -1 if not in use), so its
        # products and updates cost (3 n_contact)^2, not (3 n_pillars)^2
        self._fc = np.zeros((3 * ng, 3 * ng))
        self._unk = np.zeros(3 * ng, dtype=np.int64)
        self._pos = np.full(3 * ng, -1, dtype=np.int64)
        self._nu = np.zeros(1, dtype=np.int64)
        self._buf = np.empty(9 * ng * ng)         # work space of the low-rank updates

    def update_counts(self) -> dict:
        """Dense rebuilds and pillar block updates of F^-1 so far."""
        return {"coarse_factorisations": self.factorisations,
                "coarse_pillar_updates": self.pillar_updates}

    def update(self, att) -> None:
        """Prepare for a solve on the attached set ``att``: the modes and F^-1 follow it."""
        moved = self._follow_modes(att)
        if moved is None:
            return
        changed, old_use, old_fgg = moved
        n_in = int(np.count_nonzero(self._use[:, 0]))
        if not self._valid or len(changed) > max(self.MAX_UPDATES_PER_CHANGE, n_in // 8) \
                or self._since_rebuild + len(changed) > self.REBUILD_EVERY \
                or not self._follow(changed, old_use, old_fgg):
            self._rebuild()

    def coarse_matrix(self) -> tuple:
        """(indices of the unknowns in use, F on them) of the current set."""
        return self._unknowns_block(np.arange(self.ng))

    def _unknowns_block(self, groups) -> tuple:
        """(indices j of the unknowns in use of ``groups``, pillar by pillar, F[j, j]): the
        multipole couplings plus the diagonal blocks F_gg."""
        j = [3 * g + np.flatnonzero(self._use[g]) for g in groups]
        j = np.concatenate(j) if j else np.zeros(0, dtype=np.int64)
        f = self._t[np.ix_(j, j)]
        pos = 0
        for g in groups:
            u = np.flatnonzero(self._use[g])
            f[pos:pos + len(u), pos:pos + len(u)] += self._fgg[g][np.ix_(u, u)]
            pos += len(u)
        return j, f

    def _rebuild(self) -> None:
        self._install_inverse(*self.coarse_matrix())

    def _store_inverse(self, idx, inv) -> None:
        """Keep ``inv`` as the compact F^-1, position i holding unknown idx[i]."""
        n = len(idx)
        self._pos[:] = -1
        self._unk[:n] = idx
        self._pos[idx] = np.arange(n)
        self._nu[0] = n
        self._fc[:n, :n] = inv

    @property
    def coarse_inverse(self) -> np.ndarray:
        """F^-1 on all 3 n_pillars unknowns (zero rows and columns for those not in use), a
        read-only copy of the compact matrix kept."""
        n = int(self._nu[0])
        out = np.zeros((3 * self.ng, 3 * self.ng))
        u = self._unk[:n]
        out[np.ix_(u, u)] = self._fc[:n, :n]
        out.flags.writeable = False
        return out

    def _work(self, n: int) -> np.ndarray:
        """An n x n contiguous view of the update work space."""
        return self._buf[:n * n].reshape(n, n)

    def _drop(self, pj) -> None:
        """Remove the positions ``pj`` from the compact F^-1: the last positions in use move
        into the holes (rows, then columns), so nothing else moves."""
        n = int(self._nu[0])
        k = len(pj)
        holes = np.zeros(n, dtype=bool)
        holes[pj] = True
        movers = np.flatnonzero(~holes[n - k:]) + (n - k)
        targets = np.flatnonzero(holes[:n - k])
        fc = self._fc
        self._pos[self._unk[pj]] = -1
        if len(movers):
            fc[targets, :n] = fc[movers, :n]
            fc[:n, targets] = fc[:n, movers]
            self._unk[targets] = self._unk[movers]
            self._pos[self._unk[targets]] = targets
        self._nu[0] = n - k

    def _follow(self, changed, old_use, old_fgg) -> bool:
        """Update F^-1 for the pillars in ``changed``; False (then rebuilt) at a pivot that is
        not safely positive."""
        if len(changed) == 0:
            return True
        fc, pos = self._fc, self._pos
        same = np.all(old_use == self._use[changed], axis=1)
        # pillars keeping their unknowns whose F_gg changed: a Woodbury update
        moved = np.any((self._fgg[changed] != old_fgg).reshape(len(changed), 9), axis=1)
        keep = changed[same & moved]
        if len(keep):
            j = np.concatenate([3 * g + np.flatnonzero(self._use[g]) for g in keep]) \
                if self._use[keep].any() else np.zeros(0, dtype=np.int64)
            if len(j):
                delta = np.zeros((len(j), len(j)))
                at = 0
                for k, g in zip(np.flatnonzero(same & moved), keep):
                    u = np.flatnonzero(self._use[g])
                    blk = self._fgg[g][np.ix_(u, u)] - old_fgg[k][np.ix_(u, u)]
                    delta[at:at + len(u), at:at + len(u)] = blk
                    at += len(u)
                n = int(self._nu[0])
                pj = pos[j]
                v = fc[:n, pj]
                mid = np.eye(len(j)) + v[pj] @ delta
                try:
                    x = delta @ np.linalg.inv(mid)
                except np.linalg.LinAlgError:
                    return False
                x = 0.5 * (x + x.T)
                fc[:n, :n] -= np.matmul(v @ x, v.T, out=self._work(n))
                if not np.all(fc[pj, pj] > 0.0):
                    return False
        # pillars whose unknowns change: drop their old unknowns, border the new ones
        move = changed[~same]
        if len(move):
            jo = np.concatenate([3 * g + np.flatnonzero(ou) for g, ou in
                                 zip(move, old_use[~same])])
            if len(jo):
                n = int(self._nu[0])
                pjo = pos[jo]
                v = fc[:n, pjo]
                try:
                    vjj = np.linalg.cholesky(v[pjo])
                except np.linalg.LinAlgError:
                    return False
                w = np.linalg.solve(vjj, v.T)            # L^-1 V^T
                fc[:n, :n] -= np.matmul(w.T, w, out=self._work(n))
                self._drop(pjo)
            jn, g_new = self._unknowns_block(move)
            if len(jn):
                n = int(self._nu[0])
                k = len(jn)
                b = self._t[np.ix_(self._unk[:n], jn)]
                u = fc[:n, :n] @ b
                s = g_new - b.T @ u
                s = 0.5 * (s + s.T)
                try:
                    ls = np.linalg.cholesky(s)
                except np.linalg.LinAlgError:
                    return False
                if np.min(np.diag(ls)) ** 2 <= self.PIVOT_TOL * np.max(np.diag(s)):
                    return False
                sinv = np.linalg.inv(s)
                sinv = 0.5 * (sinv + sinv.T)
                us = u @ sinv
                fc[:n, :n] += np.matmul(us, u.T, out=self._work(n))
                fc[:n, n:n + k] = -us
                fc[n:n + k, :n] = -us.T
                fc[n:n + k, n:n + k] = sinv
                self._unk[n:n + k] = jn
                pos[jn] = np.arange(n, n + k)
                self._nu[0] = n + k
        done = np.concatenate([keep, move])
        self._since_rebuild += len(done)
        self.pillar_updates += len(done)
        return True

    def apply(self, r, att, z) -> float:
        """z <- (two-level preconditioner) r on the attached set; returns r.z."""
        self.block_jacobi.apply(r, att, z)
        c = self._moments(r)                                               # Zh^T r
        y = -np.einsum("gab,gb->ga", self._d, c)
        n = int(self._nu[0])
        if n:
            u = self._unk[:n]
            y.reshape(-1)[u] += self._fc[:n, :n] @ c.reshape(-1)[u]
        self._correct(y, z)
        return float(r @ z)

"""Numba kernels (one jit policy: nopython, cache=True, no fastmath: float64 reference-exact).

See :mod:`fibril_hpc.kernels.reference` for the NumPy twin of each kernel and its documentation.
"""

from __future__ import annotations

import numba as nb
import numpy as np

jit = nb.njit(cache=True, nogil=True, fastmath=False)


def alpha_of(alpha, g):
    """The spring coefficient h^2/k of group g: ``alpha`` itself when it is one number (every
    pillar alike: no per-pillar array exists), ``alpha[g]`` for per-pillar stiffnesses."""
    return alpha if np.ndim(alpha) == 0 else alpha[g]


@nb.extending.overload(alpha_of, jit_options={"cache": True})
def _alpha_of_nb(alpha, g):
    if isinstance(alpha, nb.types.Array):
        return lambda alpha, g: alpha[g]
    return lambda alpha, g: alpha


@jit
def group_sums(x, att, starts, out):
    """out[g] = sum of x over the attached elements of group g."""
    for g in range(len(starts) - 1):
        s = 0.0
        for i in range(starts[g], starts[g + 1]):
            if att[i]:
                s += x[i]
        out[g] = s


@jit
def group_counts(att, starts, out):
    """out[g] = number of attached elements of group g."""
    for g in range(len(starts) - 1):
        c = 0
        for i in range(starts[g], starts[g + 1]):
            if att[i]:
                c += 1
        out[g] = c


@jit
def residual(b, u, x, att, starts, alpha, r):
    """r = b - (u + alpha B B^T x) on S, 0 elsewhere. Returns ||r||^2 (alpha = 0: rigid)."""
    rr = 0.0
    for g in range(len(starts) - 1):
        s = 0.0
        a = alpha_of(alpha, g)
        if a != 0.0:
            for i in range(starts[g], starts[g + 1]):
                if att[i]:
                    s += x[i]
        s *= a
        for i in range(starts[g], starts[g + 1]):
            if att[i]:
                v = b[i] - u[i] - s
                r[i] = v
                rr += v * v
            else:
                r[i] = 0.0
    return rr


@jit
def apply_springs(kd, d, att, starts, alpha, q):
    """q = (K d + alpha B B^T d) on S, 0 elsewhere. Returns d.q."""
    dq = 0.0
    for g in range(len(starts) - 1):
        s = 0.0
        a = alpha_of(alpha, g)
        if a != 0.0:
            for i in range(starts[g], starts[g + 1]):
                if att[i]:
                    s += d[i]
        s *= a
        for i in range(starts[g], starts[g + 1]):
            if att[i]:
                v = kd[i] + s
                q[i] = v
                dq += d[i] * v
            else:
                q[i] = 0.0
    return dq


@jit
def precondition(r, att, starts, alpha, c0, z):
    """z = P^-1 r, P = c0 I + alpha B B^T (Sherman-Morrison per group). Returns r.z."""
    rz = 0.0
    inv = 1.0 / c0
    for g in range(len(starts) - 1):
        corr = 0.0
        a = alpha_of(alpha, g)
        if a != 0.0:
            s = 0.0
            m = 0
            for i in range(starts[g], starts[g + 1]):
                if att[i]:
                    s += r[i]
                    m += 1
            if m > 0:
                corr = a * s / (c0 * (c0 + a * m))
        for i in range(starts[g], starts[g + 1]):
            if att[i]:
                v = r[i] * inv - corr
                z[i] = v
                rz += r[i] * v
            else:
                z[i] = 0.0
    return rz


@jit
def cg_step(x, u, r, d, kd, q, a, att):
    """x += a d, u += a K d (every element), r -= a q (on S). Returns (||r||^2, ||u_S||^2)."""
    rr = 0.0
    uu = 0.0
    for i in range(len(x)):
        u[i] += a * kd[i]
        if att[i]:
            x[i] += a * d[i]
            v = r[i] - a * q[i]
            r[i] = v
            rr += v * v
            uu += u[i] * u[i]
    return rr, uu


@jit
def cg_direction(z, d, beta):
    """d = z + beta d."""
    for i in range(len(d)):
        d[i] = z[i] + beta * d[i]


@jit
def masked_norm2(v, att):
    """||v_S||^2."""
    s = 0.0
    for i in range(len(v)):
        if att[i]:
            s += v[i] * v[i]
    return s


@jit
def gaps(u, starts, z0, zcoef, d, dl, g):
    """g_i = u_i - (d - zcoef z0_i - dl[group(i)]): the gap between surface and tip."""
    for grp in range(len(starts) - 1):
        t = d - dl[grp]
        for i in range(starts[grp], starts[grp + 1]):
            g[i] = u[i] - (t - zcoef * z0[i])


@jit
def event_distance(p, p1, g, g1, att, sigma_c, sgn):
    """Smallest distance D >= 0 along d -> d + sgn D at which, on the current set S,
    an attached element reaches p = -sigma_c or a free element's gap closes. inf if none."""
    best = np.inf
    for i in range(len(p)):
        if att[i]:
            rate = sgn * p1[i]
            if rate < 0.0:
                dist = (p[i] + sigma_c) / (-rate)
                if dist < best:
                    best = dist
        else:
            rate = sgn * g1[i]
            if rate < 0.0:
                dist = g[i] / (-rate)
                if dist < best:
                    best = dist
    if best < 0.0:
        best = 0.0
    return best


@jit
def last_event_within(p, p1, g, g1, att, sigma_c, sgn, limit):
    """Largest event distance that is <= limit (0 if none): the end of a batch of events."""
    last = 0.0
    for i in range(len(p)):
        if att[i]:
            rate = sgn * p1[i]
            num = p[i] + sigma_c
        else:
            rate = sgn * g1[i]
            num = g[i]
        if rate < 0.0 and num <= limit * (-rate):
            dist = num / (-rate)
            if dist > last:
                last = dist
    return last


@jit
def flip_events(p, p1, g, g1, att, sigma_c, sgn, limit):
    """Flip every element whose event distance is <= limit: attached ones detach (p = 0), free
    ones attach (p = 0). Returns (n_detached, n_attached)."""
    nd = 0
    na = 0
    for i in range(len(p)):
        if att[i]:
            rate = sgn * p1[i]
            if rate < 0.0 and (p[i] + sigma_c) <= limit * (-rate):
                att[i] = 0
                p[i] = 0.0
                nd += 1
        else:
            rate = sgn * g1[i]
            if rate < 0.0 and g[i] <= limit * (-rate):
                att[i] = 1
                p[i] = 0.0
                na += 1
    return nd, na


@jit
def update_contact_set(p, g, att, starts, sigma_c, tol_p, tol_g, worst_only):
    """One pass of the contact-set update at fixed d.

    Attached elements with p < -(sigma_c + tol_p) detach (all of them, or with ``worst_only`` the
    most supercritical one per group); free elements with g < -tol_g attach at zero stress.
    Returns (n_detached, n_attached).
    """
    nd = 0
    na = 0
    thr = -(sigma_c + tol_p)
    for grp in range(len(starts) - 1):
        worst = -1
        wv = thr
        for i in range(starts[grp], starts[grp + 1]):
            if att[i]:
                if p[i] < thr:
                    if worst_only:
                        if p[i] < wv:
                            wv = p[i]
                            worst = i
                    else:
                        att[i] = 0
                        p[i] = 0.0
                        nd += 1
            elif g[i] < -tol_g:
                att[i] = 2      # mark: attach after the scan (do not detach it in this pass)
                na += 1
        if worst >= 0:
            att[worst] = 0
            p[worst] = 0.0
            nd += 1
        for i in range(starts[grp], starts[grp + 1]):
            if att[i] == 2:
                att[i] = 1
                p[i] = 0.0
    return nd, na


@jit
def point_loads(u, iy, ix, idx, vals, table):
    """u_j += sum_k vals[k] K(x_j - x_idx[k]) over every active j, with K read from the real-space
    table K[|dy|, |dx|] (exact: the same influence coefficients as the FFT product)."""
    for k in range(len(idx)):
        i = idx[k]
        v = vals[k]
        yi = iy[i]
        xi = ix[i]
        for j in range(len(u)):
            dy = iy[j] - yi
            dx = ix[j] - xi
            if dy < 0:
                dy = -dy
            if dx < 0:
                dx = -dx
            u[j] += v * table[dy, dx]


@jit
def point_loads_at(out, tgt, iy, ix, idx, vals, table):
    """out[t] += sum_k vals[k] K(x_tgt[t] - x_idx[k]) for the target elements ``tgt`` only."""
    for t in range(len(tgt)):
        j = tgt[t]
        yj = iy[j]
        xj = ix[j]
        s = 0.0
        for k in range(len(idx)):
            i = idx[k]
            dy = iy[i] - yj
            dx = ix[i] - xj
            if dy < 0:
                dy = -dy
            if dx < 0:
                dx = -dx
            s += vals[k] * table[dy, dx]
        out[t] += s


@jit
def point_forces_at(out, tgt, iy, ix, cy, cx, forces):
    """out[t] += sum_b forces[b] / max(r_tb, 0.5), r_tb the distance (in elements) from element
    tgt[t] to the point (cy[b], cx[b]): the 1/r point-force field, without its constant."""
    for t in range(len(tgt)):
        j = tgt[t]
        yj = iy[j]
        xj = ix[j]
        s = 0.0
        for b in range(len(forces)):
            dy = yj - cy[b]
            dx = xj - cx[b]
            r = np.sqrt(dy * dy + dx * dx)
            if r < 0.5:
                r = 0.5
            s += forces[b] / r
        out[t] += s


@jit
def block3_apply(blocks, v, out):
    """out[g] = blocks[g] @ v[g] for (n, 3, 3) blocks and (n, 3) vectors."""
    for g in range(blocks.shape[0]):
        for a in range(3):
            out[g, a] = blocks[g, a, 0] * v[g, 0] + blocks[g, a, 1] * v[g, 1] \
                + blocks[g, a, 2] * v[g, 2]


@jit
def lattice_scatter(v, ib, ia, grid):
    """grid[a, ib[g], ia[g]] = v[g, a] (the other nodes of ``grid`` are left as they are)."""
    for g in range(v.shape[0]):
        for a in range(3):
            grid[a, ib[g], ia[g]] = v[g, a]


@jit
def spectral3_sym(ks, vh):
    """vh[:, j] <- K(j) vh[:, j] in place, for the lattice couplings' 3 x 3 spectra stored by
    their symmetry as six real (n,) rows ``ks`` = (K00, K11, K22, K12, Im K01, Im K02): K00,
    K11, K22 and K12 = K21 real, K01 = -K10 and K02 = -K20 imaginary (solve/lattice.py)."""
    for j in range(vh.shape[1]):
        v0 = vh[0, j]
        v1 = vh[1, j]
        v2 = vh[2, j]
        a01 = ks[4, j]
        a02 = ks[5, j]
        k12 = ks[3, j]
        vh[0, j] = ks[0, j] * v0 + 1j * (a01 * v1 + a02 * v2)
        vh[1, j] = ks[1, j] * v1 + k12 * v2 - 1j * (a01 * v0)
        vh[2, j] = ks[2, j] * v2 + k12 * v1 - 1j * (a02 * v0)


@jit
def lattice_gather(grid, ib, ia, blocks, v, use, out):
    """out[g, a] = use[g, a] (grid[a, ib[g], ia[g]] + (blocks[g] @ v[g])[a]): the lattice
    couplings read back at the pillars plus each pillar's own block, on the unknowns in use."""
    for g in range(v.shape[0]):
        for a in range(3):
            s = grid[a, ib[g], ia[g]] + blocks[g, a, 0] * v[g, 0] + blocks[g, a, 1] * v[g, 1] \
                + blocks[g, a, 2] * v[g, 2]
            out[g, a] = s * use[g, a]


@jit
def scale_block(hat_ri, kernel):
    """hat_ri[j, c, :] *= kernel[j, c]: a complex (m, B) block, seen as its (m, B, 2) real
    view, times a real (m, B) one (the real and imaginary parts alike)."""
    for j in range(hat_ri.shape[0]):
        for c in range(hat_ri.shape[1]):
            s = kernel[j, c]
            hat_ri[j, c, 0] *= s
            hat_ri[j, c, 1] *= s

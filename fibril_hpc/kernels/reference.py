"""NumPy float64 twins of :mod:`fibril_hpc.kernels.compiled` (same signatures, same results).

Vectors are over the active elements, grouped contiguously (``starts``); ``att`` is a uint8 mask of
the attached set S. These are slower but obviously correct; the property tests compare them with the
compiled kernels.
"""

from __future__ import annotations

import numpy as np


def _labels(starts):
    return np.repeat(np.arange(len(starts) - 1), np.diff(starts))


def _gsum(x, att, starts):
    return np.bincount(_labels(starts), weights=np.where(att != 0, x, 0.0),
                       minlength=len(starts) - 1)


def group_sums(x, att, starts, out):
    out[:] = _gsum(x, att, starts)


def group_counts(att, starts, out):
    out[:] = np.bincount(_labels(starts), weights=(att != 0).astype(float),
                         minlength=len(starts) - 1).astype(out.dtype)


def residual(b, u, x, att, starts, alpha, r):
    s = (alpha * _gsum(x, att, starts))[_labels(starts)]
    r[:] = np.where(att != 0, b - u - s, 0.0)
    return float(r @ r)


def apply_springs(kd, d, att, starts, alpha, q):
    s = (alpha * _gsum(d, att, starts))[_labels(starts)]
    q[:] = np.where(att != 0, kd + s, 0.0)
    return float(d[att != 0] @ q[att != 0])


def precondition(r, att, starts, alpha, c0, z):
    lab = _labels(starts)
    m = np.bincount(lab, weights=(att != 0).astype(float), minlength=len(starts) - 1)
    s = _gsum(r, att, starts)
    corr = (np.where(m > 0, alpha * s / (c0 * (c0 + alpha * m)), 0.0) if np.any(alpha != 0)
            else 0 * s)
    z[:] = np.where(att != 0, r / c0 - corr[lab], 0.0)
    return float(r[att != 0] @ z[att != 0])


def cg_step(x, u, r, d, kd, q, a, att):
    on = att != 0
    u += a * kd
    x[on] += a * d[on]
    r[on] -= a * q[on]
    return float(r[on] @ r[on]), float(u[on] @ u[on])


def cg_direction(z, d, beta):
    d[:] = z + beta * d


def masked_norm2(v, att):
    on = att != 0
    return float(v[on] @ v[on])


def gaps(u, starts, z0, zcoef, d, dl, g):
    g[:] = u - (d - zcoef * z0 - dl[_labels(starts)])


def _rates(p, p1, g, g1, att, sigma_c, sgn):
    on = att != 0
    rate = np.where(on, sgn * p1, sgn * g1)
    num = np.where(on, p + sigma_c, g)
    return on, rate, num


def event_distance(p, p1, g, g1, att, sigma_c, sgn):
    on, rate, num = _rates(p, p1, g, g1, att, sigma_c, sgn)
    neg = rate < 0
    if not neg.any():
        return np.inf
    return max(0.0, float(np.min(num[neg] / -rate[neg])))


def last_event_within(p, p1, g, g1, att, sigma_c, sgn, limit):
    on, rate, num = _rates(p, p1, g, g1, att, sigma_c, sgn)
    hit = (rate < 0) & (num <= limit * -rate)
    if not hit.any():
        return 0.0
    return max(0.0, float(np.max(num[hit] / -rate[hit])))


def flip_events(p, p1, g, g1, att, sigma_c, sgn, limit):
    on, rate, num = _rates(p, p1, g, g1, att, sigma_c, sgn)
    hit = (rate < 0) & (num <= limit * -rate)
    det = hit & on
    new = hit & ~on
    att[det] = 0
    att[new] = 1
    p[hit] = 0.0
    return int(det.sum()), int(new.sum())


def update_contact_set(p, g, att, starts, sigma_c, tol_p, tol_g, worst_only):
    on = att != 0
    thr = -(sigma_c + tol_p)
    sup = on & (p < thr)
    if worst_only:
        lab = _labels(starts)
        keep = np.zeros_like(sup)
        for grp in np.unique(lab[sup]):
            idx = np.flatnonzero(sup & (lab == grp))
            keep[idx[np.argmin(p[idx])]] = True
        sup = keep
    new = ~on & (g < -tol_g)
    att[sup] = 0
    att[new] = 1
    p[sup | new] = 0.0
    return int(sup.sum()), int(new.sum())


def point_loads(u, iy, ix, idx, vals, table):
    for i, v in zip(idx, vals):
        u += v * table[np.abs(iy - iy[i]), np.abs(ix - ix[i])]


def point_loads_at(out, tgt, iy, ix, idx, vals, table):
    """out[t] += sum_k vals[k] K(x_tgt[t] - x_idx[k]) for the target elements ``tgt`` only."""
    for t, j in enumerate(tgt):
        out[t] += np.dot(vals, table[np.abs(iy[idx] - iy[j]), np.abs(ix[idx] - ix[j])])


def point_forces_at(out, tgt, iy, ix, cy, cx, forces):
    r = np.hypot(iy[tgt][:, None] - cy[None, :], ix[tgt][:, None] - cx[None, :])
    out += (forces[None, :] / np.maximum(r, 0.5)).sum(axis=1)


def block3_apply(blocks, v, out):
    out[:] = np.einsum("gab,gb->ga", blocks, v)


def lattice_scatter(v, ib, ia, grid):
    grid[:, ib, ia] = v.T


def spectral3_sym(ks, vh):
    k = np.empty((3, 3, ks.shape[1]), np.complex128)
    k[0, 0], k[1, 1], k[2, 2] = ks[0], ks[1], ks[2]
    k[1, 2] = k[2, 1] = ks[3]
    k[0, 1], k[1, 0] = 1j * ks[4], -1j * ks[4]
    k[0, 2], k[2, 0] = 1j * ks[5], -1j * ks[5]
    vh[:] = np.einsum("abj,bj->aj", k, vh)


def lattice_gather(grid, ib, ia, blocks, v, use, out):
    out[:] = use * (grid[:, ib, ia].T + np.einsum("gab,gb->ga", blocks, v))


def scale_block(hat_ri, kernel):
    hat_ri *= kernel[:, :, None]

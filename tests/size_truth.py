"""Synthetic brushes of several sizes with a known intensive loss, for :mod:`.laws.size_loss`.

Per (n_side, sigma~, seed) one loading path: F~_A = max(floor, P tanh(c F~_P / P)) at the
preloads of ``F_P: auto``'s first round and one plateau round, with the plateau

    P(sigma~, N) = P_inf(sigma~) + A N^(-p),  P_inf = top max(0, 1 - sigma~ / sigma_inf)^shape

(adhesion per area fades to 0 at ``sigma_inf``; with p = 3/4, A N^(-3/4) is ``pillars``
pillars' pull-off, so a finite brush keeps its tallest few pillars beyond sigma_inf). With
``pillar_ref`` (an n_side) the loss is instead at a fixed pillar-scale roughness sigma / d_c1:
size n fades at sigma_inf (n / pillar_ref)^(2 loss_drift): with loss_drift = -1/4 the sigma~
of the same sigma / d_c1 (sigma / d_c1 = sigma~ (phi N)^(1/4)), with -3/4 that of the same
k sigma / F_c1 at fixed k~; its crossings drift as N^loss_drift. Seeds
scatter P_inf and A by relative normal deviates drawn once per (size, seed) and used at every
sigma~ (a seed is one height pattern at every sigma~; sizes are different brushes).
"""

from __future__ import annotations

import math

import numpy as np

from fibril_hpc.campaign.laws.reading import pillar_floor

PHI = 0.16
PRELOADS = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0, 16.0)


def p_inf(sigma, sigma_inf=0.6, top=0.9, shape=1.5):
    """The true plateau of an infinite brush."""
    return top * max(0.0, 1.0 - sigma / sigma_inf) ** shape


def sigma_at(level, sigma_inf=0.6, top=0.9, shape=1.5):
    """The true sigma~ where P_inf falls to ``level`` (> 0)."""
    return sigma_inf * (1.0 - (level / top) ** (1.0 / shape))


def amplitude(pillars=4.0, phi=PHI):
    """The finite-size term's A: ``pillars`` pillars' pull-off times N^(3/4)."""
    return pillars * phi ** 0.25


def plateau(sigma, n_side, pillars=4.0, exponent=0.75, **kw):
    """The true seed-mean plateau at one size."""
    return p_inf(sigma, **kw) + amplitude(pillars) * (n_side * n_side) ** -exponent


def brushes(sizes=(8, 12, 16), sigmas=(0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0), seeds=4,
            sd_inf=0.06, sd_a=0.2, c=5.0, rng=0, pillars=4.0, exponent=0.75, pillar_ref=None,
            loss_drift=-0.25, **kw):
    """{n_side: {sigma~: (seed, preload, F_P, F_A) arrays}} of one k~ (``exponent``: the
    finite-size term's power of N, 3/4 for a fixed number of pillars)."""
    rng = np.random.default_rng(rng)
    out = {}
    for n in sizes:
        floor = pillar_floor(n, PHI)
        z = rng.standard_normal((seeds, 2))          # per seed, shared by every sigma~
        kn = dict(kw)
        if pillar_ref is not None:
            kn["sigma_inf"] = kw.get("sigma_inf", 0.6) * (n / pillar_ref) ** (2 * loss_drift)
        g = {}
        for s in sigmas:
            rows = []
            for seed in range(seeds):
                P = (p_inf(s, **kn) * (1 + sd_inf * z[seed, 0])
                     + amplitude(pillars) * (1 + sd_a * z[seed, 1]) * (n * n) ** -exponent)
                for fp in PRELOADS:
                    fa = max(floor, P * math.tanh(c * fp / P))
                    rows.append((seed, fp, fp, fa))
            a = np.array(rows, float)
            g[float(s)] = (a[:, 0].astype(int), a[:, 1], a[:, 2], a[:, 3])
        out[n] = g
    return out

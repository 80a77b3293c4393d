"""Synthetic campaigns of known truth, for testing the report's readings (not our own runs).

A group (k~, sigma~) has a true state, plateau P, adhesion coefficient c (eq. 15: F~_A = c F~_P
on the linear stage) and one pillar's pull-off ``floor``; each seed scatters c and P by
independent relative normal deviates. Curve shapes:

* ``sharp``: F~_A = min(max(floor, c F~_P), P) - a linear stage with a clean bend;
* ``smooth``: F~_A = max(floor, P tanh(c F~_P / P)) - initial slope c, bending early (the
  report's c, the secant through the origin to half the plateau, is 0.5/atanh(0.5) = 0.910 c:
  :meth:`Truth.c_read`);
* ``instant``: the brush saturates at first contact: preloads below ``first_contact`` are reached
  there (the overshoot), F~_A = P at every preload;
* ``lost``: F~_A at the floor (one pillar, per-seed scatter) at every preload.

c(sigma~) may follow the paper's law max(alpha/sigma~ - beta, 0) (groups with c = 0 are lost).
``group``, ``law_campaign`` and ``loss_campaign`` draw each group's seed deviates afresh;
``fade_campaign`` draws them once per seed, so a seed is the same brush at every sigma~ (as the
real heights sigma~ (max xi - xi_n) are), and its plateau fades smoothly to the last pillar
(each seed its own fade), at any seed counts per sigma~ (``seeds: auto``'s 3-10).
Sampling: a fixed list of preloads, optionally with per-seed extra preloads (mixed seed sets per
level, as ``F_P: auto`` makes them) and per-seed plateau rounds (x 4 above the top).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fibril_hpc.campaign.laws import reading

FLOOR = reading.pillar_floor(18, 0.16)
START = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0)      # F_P: auto's first round
HALF_TANH = 0.5 / math.atanh(0.5)         # a tanh rise's secant to half over its initial slope


@dataclass
class Truth:
    """What a synthetic group is."""

    shape: str                  # sharp | smooth | instant | lost
    c: float                    # population c (NaN for instant: unbounded; 0 for lost)
    plateau: float
    floor: float = FLOOR
    first_contact: float = 0.0  # the smallest F~_P the path can reach
    c_sd: float = 0.1           # relative seed scatter of c
    P_sd: float = 0.03          # relative seed scatter of the plateau

    def c_read(self) -> float:
        """The report's c of the population curve: the secant through the origin to the point
        where F~_A reaches half the plateau."""
        return self.c * (HALF_TANH if self.shape == "smooth" else 1.0)

    def state(self, smallest_preload: float) -> str:
        """The state a correct reading reports for preloads from ``smallest_preload``."""
        if self.shape == "lost":
            return reading.LOST
        if self.shape == "instant":
            return reading.UNRESOLVED
        x0 = max(smallest_preload, self.first_contact)
        return reading.RESOLVED if self.fa(x0, self.c, self.plateau) < 0.5 * self.plateau \
            else reading.UNRESOLVED

    def fa(self, x, c, P, floor=None):
        """F~_A of one seed (its c, P) at reached preload x."""
        f = self.floor if floor is None else floor
        if self.shape == "sharp":
            return min(max(f, c * x), P)
        if self.shape == "smooth":
            return max(f, P * math.tanh(c * x / P))
        if self.shape == "instant":
            return P
        return f


def group(truth: Truth, seeds: int, preloads=START, extra: int = 0, rounds: int = 0,
          rng=None):
    """(seed, preload, F_P, F_A) arrays of one group: every seed at ``preloads``, plus ``extra``
    random preloads of its own (log-uniform inside the range) and up to ``rounds`` plateau rounds
    (x 4 above the largest preload) for a random subset of seeds."""
    rng = np.random.default_rng(rng)
    rows = []
    for s in range(seeds):
        c = truth.c * (1 + truth.c_sd * rng.standard_normal()) if truth.c > 0 else truth.c
        P = truth.plateau * (1 + truth.P_sd * rng.standard_normal())
        fl = truth.floor * (1 + 0.02 * rng.standard_normal())
        mine = list(preloads)
        if extra:
            lo, hi = math.log(min(preloads)), math.log(max(preloads))
            mine += [float(np.round(math.exp(v), 9)) for v in rng.uniform(lo, hi, extra)]
        if rounds and rng.random() < 0.5:
            top = max(mine)
            mine += [top * 4 ** (i + 1) for i in range(int(rng.integers(1, rounds + 1)))]
        for p in sorted(set(mine)):
            x = max(p, truth.first_contact)
            rows.append((s, p, x, truth.fa(x, c, P, fl)))
    return tuple(np.array(col) for col in zip(*rows))


def law_campaign(alpha, beta, sigmas, seeds, shape="smooth", plateau=1.5, preloads=None,
                 rng=None, c_sd=0.1):
    """{sigma~: points} of one k~ whose c (as the report reads it, :meth:`Truth.c_read`) follows
    max(alpha/sigma~ - beta, 0): groups with c = 0 lose adhesion; preloads default to a log grid
    (x 1.5 apart) from well below the rise to well above the plateau."""
    rng = np.random.default_rng(rng)
    out, truths = {}, {}
    for s in sigmas:
        c = max(alpha / s - beta, 0.0)
        slope = c / HALF_TANH if shape == "smooth" else c
        t = Truth("lost" if c == 0 else shape, slope, FLOOR if c == 0 else plateau, c_sd=c_sd)
        pre = preloads
        if pre is None:
            top = 4 * plateau / c if c > 0 else 4.0
            pre = tuple(float(v) for v in np.geomspace(top / 4000, top, 22).round(12))
        out[s] = group(t, seeds, pre, rng=rng)
        truths[s] = t
    return out, truths


#: the loss threshold of the synthetic campaigns (``FEW_PILLARS`` pillars' pull-off)
LOSS = reading.FEW_PILLARS * FLOOR


def loss_plateau(sigma, sigma_c, fade=3.0, top=1.5, after=None):
    """The plateau of a campaign losing adhesion at a known ``sigma_c``: a fade,
    min(top, LOSS (sigma_c/sigma)^fade), which crosses the loss threshold exactly at sigma_c
    (a power law: log-log interpolation is exact); or, with ``fade=None``, a sharp loss: ``top``
    below sigma_c and ``after`` (default 2.5 pillars' pull-off) from sigma_c on."""
    if fade is None:
        return top if sigma < sigma_c else (2.5 * FLOOR if after is None else after)
    return min(top, LOSS * (sigma_c / sigma) ** fade)


def loss_campaign(sigma_c, sigmas, seeds, alpha=None, beta=None, fade=3.0, top=1.5, rng=None,
                  c_sd=0.05, P_sd=0.03, creep=None):
    """{sigma~: points} of one k~ whose plateau is :func:`loss_plateau` (lost from ``sigma_c``
    on, known exactly) and whose c (as the report reads it) follows max(alpha/sigma~ - beta, 0)
    where the plateau holds adhesion (default alpha/beta = sigma_c, beta = 1: the law true).
    A lost group still creeps, from the floor to its plateau of one to three pillars at slope
    ``creep`` (default 10 x its plateau), so its plateau is the truth's; the creep's secant is how
    loosely its c = 0 holds the alpha/beta line. Sharp rises, preloads x 1.5 apart from well below
    the rise to well above the plateau. Returns (points, {sigma~: Truth})."""
    rng = np.random.default_rng(rng)
    beta = 1.0 if beta is None else beta
    alpha = sigma_c * beta if alpha is None else alpha
    out, truths = {}, {}
    for s in sigmas:
        P = loss_plateau(s, sigma_c, fade, top)
        c = max(alpha / s - beta, 0.0)
        if P <= LOSS or c == 0:
            c = 10.0 * P if creep is None else creep      # the few pillars' creep
        t = Truth("sharp", c, P, c_sd=c_sd, P_sd=P_sd)
        hi = 4 * P / c
        pre = tuple(float(v) for v in np.geomspace(hi / 4000, hi, 22).round(12))
        out[s] = group(t, seeds, pre, rng=rng)
        truths[s] = t
    return out, truths


def fade_plateau(sigma, sigma_h, m=4.0, top=1.5):
    """A plateau that fades smoothly to the last pillar's pull-off: FLOOR + (top - FLOOR) /
    (1 + (sigma / sigma_h)^m) (no clean step: it reaches FLOOR only as sigma~ -> inf)."""
    return FLOOR + (top - FLOOR) / (1.0 + (sigma / sigma_h) ** m)


_GH = np.polynomial.hermite_e.hermegauss(40)


def mean_fade(sigma, sigma_h, tau, m=4.0, top=1.5):
    """The seed-mean of :func:`fade_plateau` over seeds whose sigma_h is sigma_h e^(tau z), z
    standard normal (Gauss-Hermite quadrature)."""
    x, w = _GH
    return float(np.sum(w * np.array([fade_plateau(sigma, sigma_h * math.exp(tau * v), m, top)
                                      for v in x])) / np.sum(w))


def fade_campaign(sigma_c, sigmas, seeds, alpha=None, beta=1.0, tau=0.15, m=4.0, top=1.5,
                  c_sd=0.05, rho=1.0, P_noise=0.02, rng=None):
    """{sigma~: points} of one k~ whose plateau *fades* (:func:`fade_plateau`) with seeds that
    are the same brush at every sigma~, like the real heights sigma~ (max xi - xi_n): seed s has
    its own fade, sigma_h e^(tau z_s), and its own c deviate, (1 + c_sd zc_s) with zc_s the same
    at every sigma~ (``rho`` = 1; below 1 mixed with a fresh deviate per group as rho zc_s +
    sqrt(1 - rho^2) z); a small independent relative noise ``P_noise`` on each plateau above the
    floor. sigma_h is set so that the *seed-mean* plateau crosses the loss threshold exactly at
    ``sigma_c`` (the quantity the report measures). c follows alpha/sigma~ - beta (by default
    alpha/beta = sigma_c) where the seed-mean plateau holds adhesion, and the few pillars' creep
    (10 x the plateau) where it is lost. ``seeds``: a number, or {sigma~: number} (``seeds: auto``: labels
    0..n-1 of one population at every sigma~). Sharp rises, preloads x 1.5 apart. Returns
    (points, {sigma~: population plateau}, sigma_h)."""
    from scipy import optimize

    rng = np.random.default_rng(rng)
    alpha = sigma_c * beta if alpha is None else alpha
    sigma_h = optimize.brentq(lambda h: mean_fade(sigma_c, h, tau, m, top) - LOSS,
                              sigma_c * 1e-3, sigma_c * 1e3)
    n_of = seeds if isinstance(seeds, dict) else {s: seeds for s in sigmas}
    n_max = max(n_of.values())
    z = rng.standard_normal(n_max)               # each seed's brush: its fade ...
    zc = rng.standard_normal(n_max)              # ... and its c, at every sigma~
    out, truth = {}, {}
    for s in sigmas:
        Ppop = mean_fade(s, sigma_h, tau, m, top)
        cpop = alpha / s - beta if Ppop > LOSS and alpha / s > beta else 10.0 * Ppop
        hi = 4 * Ppop / cpop
        pre = tuple(float(v) for v in np.geomspace(hi / 4000, hi, 22).round(12))
        rows = []
        for k in range(n_of[s]):
            P = fade_plateau(s, sigma_h * math.exp(tau * z[k]), m, top)
            P = FLOOR + (P - FLOOR) * (1 + P_noise * rng.standard_normal())
            dev = rho * zc[k] + math.sqrt(max(1 - rho * rho, 0.0)) * rng.standard_normal()
            c = cpop * max(1 + c_sd * dev, 0.05)
            fl = FLOOR * (1 + 0.02 * rng.standard_normal())
            for p in pre:
                rows.append((k, p, p, min(max(fl, c * p), P)))
        out[s] = tuple(np.array(col) for col in zip(*rows))
        truth[s] = Ppop
    return out, truth, sigma_h


# -- brushes of fixed strength: the same seeds stronger or weaker at every sigma~ ----------------

def strength_campaign(groups: dict, weights: dict) -> dict:
    """{sigma~: points} of groups {sigma~: (P, seeds)} whose seeds are brushes of fixed strength:
    seed s holds weights[s] x P loss thresholds, after a resolved rise (F~_A = p_s / 0.1 F~_P up
    to the plateau, the pillar floor below), preloads 1e-3 .. 10 (13 levels)."""
    pre = tuple(float(v) for v in np.geomspace(1e-3, 10.0, 13))
    out = {}
    for s, (P, seeds) in groups.items():
        rows = []
        for seed in seeds:
            p_s = weights[seed] * P * LOSS
            rows += [(seed, x, x, min(max(FLOOR, p_s / 0.1 * x), p_s)) for x in pre]
        out[s] = tuple(np.array(c, dtype=float) for c in zip(*rows))
    return out


# -- whole pillars: the plateau of a finite brush near its loss ----------------------------------

_BRUSHES: dict = {}


def _gaps(n_side: int, n_brushes: int, seed: int, keep: int = 80):
    """Sorted height gaps (max xi - xi_n) of ``n_brushes`` brushes of n_side^2 standard normal
    heights: the tallest pillar first (gap 0)."""
    key = (n_side, n_brushes, seed)
    if key not in _BRUSHES:
        rng = np.random.default_rng(seed)
        xi = rng.standard_normal((n_brushes, n_side * n_side))
        g = np.sort(xi.max(axis=1, keepdims=True) - xi, axis=1)[:, :keep]
        _BRUSHES[key] = g
    return _BRUSHES[key]


def pillar_plateau(gaps, sigma, reach):
    """Plateaus (in pillars' pull-off) of brushes with height ``gaps``: each pillar whose gap is
    within the reach holds a share 1 - sigma gap / reach of one pillar's pull-off (the tallest
    holds one whole pillar): whole pillars near the loss, skewed across brushes."""
    return np.clip(1.0 - sigma * np.asarray(gaps) / reach, 0.0, None).sum(axis=-1)


def pillar_truth(n_side: int = 12, sigma_c: float = 1.0, n_pop: int = 20000):
    """(reach, mean plateau in pillars as a function of sigma~) of the population of n_side x
    n_side brushes whose seed-mean plateau falls to ``FEW_PILLARS`` pillars at ``sigma_c``
    (Monte Carlo over ``n_pop`` brushes)."""
    from scipy import optimize

    g = _gaps(n_side, n_pop, 12345)

    def mean(sigma, reach):
        return float(pillar_plateau(g, sigma, reach).mean())

    reach = optimize.brentq(lambda r: mean(sigma_c, r) - reading.FEW_PILLARS, 1e-3, 1e3)
    return reach, (lambda s: mean(s, reach))


def pillar_campaign(sigma_c, sigmas, seeds, n_side=12, alpha=None, beta=1.0, c_sd=0.05,
                    P_noise=0.02, first_seed=0, rng=None):
    """{sigma~: points} of one k~ whose seeds are whole brushes of n_side^2 pillars
    (:func:`pillar_plateau`): seed k's heights are the same at every sigma~, so its plateau is
    that brush's count of pillars within reach, skewed and nearly discrete near the loss, as the
    real plateaus are there; the seed-mean crosses ``FEW_PILLARS`` pillars at ``sigma_c``
    exactly (:func:`pillar_truth`). c follows alpha/sigma~ - beta where the population plateau
    holds adhesion, the few pillars' creep (10 x the plateau) where it is lost. ``seeds``: a
    number or {sigma~: number}; labels ``first_seed``.. (disjoint sets: another first_seed).
    Returns (points, {sigma~: population plateau}, floor)."""
    rng = np.random.default_rng(rng)
    floor = reading.pillar_floor(n_side, 0.16)
    reach, pop = pillar_truth(n_side, sigma_c)
    alpha = sigma_c * beta if alpha is None else alpha
    n_of = seeds if isinstance(seeds, dict) else {s: seeds for s in sigmas}
    n_max = max(n_of.values())
    xi = rng.standard_normal((n_max, n_side * n_side))
    gaps = np.sort(xi.max(axis=1, keepdims=True) - xi, axis=1)[:, :80]
    zc = rng.standard_normal(n_max)
    out, truth = {}, {}
    for s in sigmas:
        Ppop = floor * pop(s)
        cpop = alpha / s - beta if pop(s) > reading.FEW_PILLARS and alpha / s > beta \
            else 10.0 * Ppop
        hi = 4 * Ppop / cpop
        pre = tuple(float(v) for v in np.geomspace(hi / 4000, hi, 22).round(12))
        rows = []
        for k in range(n_of[s]):
            P = floor * pillar_plateau(gaps[k], s, reach)
            P = floor + (P - floor) * (1 + P_noise * rng.standard_normal())
            c = cpop * max(1 + c_sd * zc[k], 0.05)
            fl = floor * (1 + 0.02 * rng.standard_normal())
            for p in pre:
                rows.append((first_seed + k, p, p, min(max(fl, c * p), P)))
        out[s] = tuple(np.array(col) for col in zip(*rows))
        truth[s] = Ppop
    return out, truth, floor

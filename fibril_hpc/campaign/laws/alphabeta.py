"""c(sigma~) = alpha/sigma~ - beta for one k~ (He, Li & Popov), and sigma~_c = alpha/beta.

**Law.** The paper's line, cut at 0: c = max(alpha/sigma~ - beta, 0). A (k~, sigma~) whose F~_A
does not rise with preload has a measured c = 0 and enters the fit: it says nothing when the
line is already at or below 0 there, and pulls the line down when it is not. sigma~ = 0 (the
smooth limit) cannot enter a law in 1/sigma~; a group whose plateau was not reached has a
provisional c and is left out (the report names both).

**Fit.** ``scipy.optimize.least_squares`` on the residuals (model - c) / sd, sd the group's
seed standard deviation of c (bootstrap over seeds), at least the smallest c its scatter can tell
from 0 (``c_detect``), combined in quadrature with c's interpolation resolution (``c_res``, the
study passes it in); unweighted when a group has no sd (one seed). The start is the linear
least-squares line through the groups with c > 0.

**Quality.** chi^2 / dof with weights: a value above the 99 % point of chi^2 (``scipy.stats``)
means the residuals exceed the seed scatter: the law does not describe these c within their
errors (the fit is flagged *poor*; its covariance is then scaled by chi^2 / dof). With two
points the line passes through both and there is nothing to check.

**sigma~_c** = alpha/beta where beta > 0 (the line reaches 0 at a finite sigma~). With
beta <= 0 it does not, and the report says so in words: every c > 0 decreasing too slowly in
1/sigma~ to vanish. Independently of the law, the data bracket sigma~_c between the largest
sigma~ with c > 0 and the smallest sigma~ with c = 0 (when both exist).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: a weighted chi^2 above this quantile flags the fit as poor (residuals beyond the seed scatter)
POOR_QUANTILE = 0.99


@dataclass
class ABFit:
    """alpha, beta and sigma~_c of one k~ from its (sigma~, c) points."""

    alpha: float
    beta: float
    sigma_c: float
    alpha_se: float                 # standard errors from the fit's covariance
    beta_se: float
    n_points: int                   # points in the fit (c > 0 and c = 0)
    n_zero: int                     # of which c = 0
    sigmas: tuple
    residuals: tuple                # c - model, per point
    chi2_red: float                 # weighted chi^2 / dof (NaN: no dof or no weights)
    poor: bool
    weighted: bool
    bracket: tuple                  # (largest sigma~ with c > 0, smallest with c = 0)
    notes: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """alpha and beta were fitted."""
        return math.isfinite(self.alpha) and math.isfinite(self.beta)


def model(sigma, alpha, beta):
    """c of the law at ``sigma`` (arrays welcome): max(alpha/sigma - beta, 0)."""
    return np.maximum(alpha / np.asarray(sigma, dtype=float) - beta, 0.0)


def _empty(sigmas, n_zero, bracket, notes) -> ABFit:
    nan = math.nan
    return ABFit(nan, nan, nan, nan, nan, len(sigmas), n_zero, tuple(sigmas), (), nan, False,
                 False, bracket, notes)


def fit_alpha_beta(sigma, c, sd=None) -> ABFit:
    """Fit c = max(alpha/sigma~ - beta, 0) to points (sigma~ > 0, c >= 0 finite)."""
    from scipy import optimize, stats

    s = np.asarray(sigma, dtype=float)
    c = np.asarray(c, dtype=float)
    sd = np.full(s.size, np.nan) if sd is None else np.asarray(sd, dtype=float)
    ok = np.isfinite(s) & (s > 0) & np.isfinite(c)
    s, c, sd = s[ok], c[ok], sd[ok]
    pos, zero = c > 0, c == 0
    smax = float(s[pos].max()) if pos.any() else 0.0
    above = zero & (s > smax)
    bracket = (smax if pos.any() else math.nan, float(s[above].min()) if above.any() else math.nan)
    notes = []
    if int(pos.sum()) < 2:
        notes.append(f"{int(pos.sum())} sigma~ with c > 0: alpha and beta need at least 2")
        return _empty(s, int(zero.sum()), bracket, notes)
    weighted = bool(np.all(np.isfinite(sd) & (sd > 0)))
    w = 1.0 / sd if weighted else np.ones_like(s)
    A = np.column_stack([1.0 / s[pos], -np.ones(int(pos.sum()))])
    x0, *_ = np.linalg.lstsq(A * w[pos, None], c[pos] * w[pos], rcond=None)

    def resid(p):
        return (model(s, p[0], p[1]) - c) * w

    res = optimize.least_squares(resid, x0, method="trf", x_scale="jac")
    alpha, beta = (float(v) for v in res.x)
    r = c - model(s, alpha, beta)
    dof = s.size - 2
    chi2 = float(np.sum((r * w) ** 2))
    J = res.jac
    poor = False
    chi2_red = chi2 / dof if dof > 0 else math.nan
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((2, 2), np.nan)
    if weighted and dof > 0:
        poor = bool(chi2 > stats.chi2.ppf(POOR_QUANTILE, dof))
        if chi2_red > 1:
            cov = cov * chi2_red
        if poor:
            notes.append(f"poor fit: residuals exceed the seed scatter (chi^2/dof = "
                         f"{chi2_red:.3g} on {dof} dof)")
    elif dof > 0:
        cov = cov * chi2_red
        notes.append("unweighted (one seed: c has no scatter); covariance from the residuals")
    else:
        notes.append("two points: the line passes through both; no check of the law")
    se = np.sqrt(np.clip(np.diag(cov), 0, None)) if np.all(np.isfinite(cov)) else (math.nan,) * 2
    sigma_c = math.nan
    if beta > 0 and alpha > 0:
        sigma_c = alpha / beta
    elif beta <= 0:
        notes.append(f"beta = {beta:.3g} <= 0: the fitted line alpha/sigma~ - beta stays above 0 "
                     "at every sigma~, so it never predicts the loss of adhesion and sigma~_c = "
                     f"alpha/beta is not defined; every sigma~ run here up to {bracket[0]:g} "
                     "has c > 0 - larger sigma~ would bound sigma~_c")
    else:
        notes.append(f"alpha = {alpha:.3g} <= 0: c does not fall as 1/sigma~; sigma~_c not "
                     "defined")
    if zero.any():
        notes.append(f"{int(zero.sum())} sigma~ with c = 0 (adhesion lost: a plateau within a "
                     "few pillars' pull-off) in the fit")
    return ABFit(alpha, beta, sigma_c, float(se[0]), float(se[1]), int(s.size),
                 int(zero.sum()), tuple(float(v) for v in s), tuple(float(v) for v in r),
                 chi2_red, poor, weighted, bracket, notes)


def t_interval(value, se, dof, level=0.95) -> tuple[float, float]:
    """value -+ t quantile x se (Student t with ``dof`` degrees of freedom; NaN if dof < 1)."""
    from scipy import stats

    if not (math.isfinite(value) and math.isfinite(se)) or dof < 1:
        return math.nan, math.nan
    q = float(stats.t.ppf(0.5 + level / 2, dof))
    return value - q * se, value + q * se

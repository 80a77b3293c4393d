"""c(sigma~) = alpha/sigma~ - beta for one k~ (He, Li & Popov), and its zero alpha/beta.

**Law.** The paper's line, cut at 0: c = max(alpha/sigma~ - beta, 0), fitted to the groups
whose rise is resolved (c > 0). sigma~ = 0 (the smooth limit) cannot enter a law in 1/sigma~; a
group whose plateau was not reached has a provisional c and is left out (the report names both).

**Lost groups** (c = 0 by the few-pillar threshold, :mod:`.reading`) are *left out of the fit*
(``lost="out"``, the default): the line describes c where the brush still adheres, and its zero
alpha/beta is an extrapolation that the report sets beside the measured loss (:mod:`.loss`), a
check the lost groups did not already decide. Chosen on synthetic truth against a weight floored
at the smallest sd of the rising groups (``"floor"``) and against the line held at or below 0 at
the first lost sigma~ (``"censored"``, a one-sided constraint) (benchmarks/lost_groups.py;
benchmarks/NOTES.md, "Lost groups in the alpha/beta fit"). The weight a lost group had before
(its own sd: the secant of its creep, or the smallest c its scatter tells from 0 where F~_A is
flat) swung by 1e5 with whether F~_A creeps; no mode here depends on the creep.

**Fit.** ``scipy.optimize.least_squares`` on the residuals (model - c) / sd, sd the group's seed
standard deviation of c (the study passes it in, with c's interpolation resolution in
quadrature); unweighted when a group has no sd (one seed).

**Active points and dof.** A point is *active* when it shapes the line: every c > 0 point, and a
c = 0 point only where the fitted line is above 0 there (``"floor"``, ``"own"``) or the constraint binds
(``"censored"``); dof = active - 2. The line is a fit (:attr:`ABFit.enough`) with at least
three active points and one dof; with two it passes through both and says nothing of the law.

**Quality.** chi^2 / dof with weights: a value above the 99 % point of chi^2 (``scipy.stats``)
means the residuals exceed the seed scatter (*poor*; the covariance is then scaled by chi^2 /
dof).

**The zero** alpha/beta where alpha, beta > 0 (the line reaches 0 at a finite sigma~); with
beta <= 0 it never does. Independently of the law, the data bracket the loss between the
largest sigma~ with c > 0 and the smallest with c = 0 above it (when both exist).

Notes are codes (:class:`Note`); the words are the page's (``analysis/verdict_text.py``).
"""

from __future__ import annotations

import enum
import functools
import math
from dataclasses import dataclass, field

import numpy as np

#: a weighted chi^2 above this quantile flags the fit as poor (residuals beyond the seed scatter)
POOR_QUANTILE = 0.99
#: the least active points and degrees of freedom of a line that is a fit
MIN_ACTIVE, MIN_DOF = 3, 1
#: how lost groups (c = 0) enter the fit (module text); the first is the report's
#: (``"own"``: each lost group with its own sd, the weighting before issue 34, kept to measure
#: the others against: it swings by 1e5 with whether F~_A creeps)
LOST_MODES = ("out", "floor", "censored", "own")


class Note(enum.StrEnum):
    """What the fit says of itself (the numbers behind each are :class:`ABFit` fields)."""

    TOO_FEW_RISING = "too few c > 0"        # fewer than 2 c > 0: no line (n_points)
    TOO_FEW_ACTIVE = "too few active"       # a line, but < MIN_ACTIVE active or < MIN_DOF dof
    POOR = "poor"                           # chi2_red beyond the POOR_QUANTILE point
    UNWEIGHTED = "unweighted"               # one seed: covariance from the residuals
    BETA_NONPOS = "beta <= 0"               # the line never reaches 0 (bracket[0]: largest c > 0)
    ALPHA_NONPOS = "alpha <= 0"             # c does not fall as 1/sigma~
    LOST_OUT = "lost out"                   # n_zero lost groups left out of the fit
    LOST_IN = "lost in"                     # n_zero lost groups in the fit (floor / censored)


@dataclass
class ABFit:
    """alpha, beta and their zero alpha/beta of one k~ from its (sigma~, c) points."""

    alpha: float
    beta: float
    sigma_c: float                  # the line's zero alpha/beta (an extrapolation of c)
    alpha_se: float                 # standard errors from the fit's covariance
    beta_se: float
    n_points: int                   # points given (c > 0 and c = 0)
    n_zero: int                     # of which c = 0 (lost)
    sigmas: tuple
    residuals: tuple                # c - model, per point given
    chi2_red: float                 # weighted chi^2 / dof (NaN: no dof or no weights)
    poor: bool
    weighted: bool
    bracket: tuple                  # (largest sigma~ with c > 0, smallest with c = 0 above it)
    notes: list = field(default_factory=list)   # :class:`Note` codes
    n_active: int = 0               # points that shape the line (module text)
    dof: int = 0                    # n_active - 2
    lost: str = "out"               # how the lost groups entered (:data:`LOST_MODES`)

    @property
    def ok(self) -> bool:
        """alpha and beta were computed (a line exists; see :attr:`enough` for a fit)."""
        return math.isfinite(self.alpha) and math.isfinite(self.beta)

    @property
    def enough(self) -> bool:
        """The line is a fit: at least ``MIN_ACTIVE`` active points and ``MIN_DOF`` dof."""
        return self.ok and self.n_active >= MIN_ACTIVE and self.dof >= MIN_DOF


def model(sigma, alpha, beta):
    """c of the law at ``sigma`` (arrays welcome): max(alpha/sigma - beta, 0)."""
    return np.maximum(alpha / np.asarray(sigma, dtype=float) - beta, 0.0)


def _empty(sigmas, n_zero, bracket, notes, lost) -> ABFit:
    nan = math.nan
    return ABFit(nan, nan, nan, nan, nan, len(sigmas), n_zero, tuple(sigmas), (), nan, False,
                 False, bracket, notes, 0, 0, lost)


def _lost_sd(sd, pos, zero, lost):
    """The sd each point enters with: a lost point's own in no mode; ``floor``: the smallest sd
    of the rising points (the finest resolution a c of this k~ has)."""
    sd = sd.copy()
    if lost == "floor" and zero.any():
        rising = sd[pos][np.isfinite(sd[pos]) & (sd[pos] > 0)]
        sd[zero] = rising.min() if rising.size else math.nan
    return sd


def poor_threshold(dof: int, n_seeds, quantile: float = POOR_QUANTILE) -> float:
    """The ``quantile`` point of chi^2 for ``dof`` when each point's sd comes from its own few
    seeds (``n_seeds``, one per active point): residual / sd is then Student t with n - 1 dof,
    not normal, and the sum of squares is drawn as dof / m sum_i t_(n_i - 1)^2 over the m points
    (Monte Carlo, a fixed stream: deterministic). Points of 30 seeds or more (or unknown) count
    as normal; all of them normal gives the chi^2 quantile itself."""
    return _poor_threshold(int(dof), tuple(sorted(float(n) for n in n_seeds)), float(quantile))


@functools.lru_cache(maxsize=256)
def _poor_threshold(dof: int, n_seeds: tuple, quantile: float) -> float:
    from scipy import stats

    if dof < 1:
        return math.nan
    if not any(math.isfinite(n) and 2 <= n < 30 for n in n_seeds):
        return float(stats.chi2.ppf(quantile, dof))
    m = len(n_seeds)
    rng = np.random.default_rng(0)
    t2 = np.zeros(20000)
    for n in n_seeds:
        t2 += (rng.standard_t(n - 1, t2.size) if math.isfinite(n) and 2 <= n < 30
               else rng.standard_normal(t2.size)) ** 2
    return float(np.quantile(t2 * dof / m, quantile))


def fit_alpha_beta(sigma, c, sd=None, lost: str = "out", n_seeds=None) -> ABFit:
    """Fit c = max(alpha/sigma~ - beta, 0) to points (sigma~ > 0, c >= 0 finite); ``lost``: how
    c = 0 points enter (module text); ``n_seeds``: the seeds behind each point's sd (a plug-in
    bootstrap sd of n seeds is widened by sqrt(n / (n - 1)) and the poor-fit test takes
    :func:`poor_threshold`), None: the sd as given and the chi^2 quantile."""
    from scipy import optimize

    if lost not in LOST_MODES:
        raise ValueError(f"lost: {lost!r} is not one of {LOST_MODES}")
    s = np.asarray(sigma, dtype=float)
    c = np.asarray(c, dtype=float)
    sd = np.full(s.size, np.nan) if sd is None else np.asarray(sd, dtype=float)
    ok = np.isfinite(s) & (s > 0) & np.isfinite(c)
    ns = (np.full(s.size, np.nan) if n_seeds is None
          else np.asarray(n_seeds, dtype=float))[ok]
    s, c, sd = s[ok], c[ok], sd[ok]
    sd = np.where(ns >= 2, sd * np.sqrt(ns / np.maximum(ns - 1, 1)), sd)
    pos, zero = c > 0, c == 0
    smax = float(s[pos].max()) if pos.any() else 0.0
    above = zero & (s > smax)
    bracket = (smax if pos.any() else math.nan, float(s[above].min()) if above.any() else math.nan)
    n_zero = int(zero.sum())
    notes = [Note.LOST_OUT if lost == "out" else Note.LOST_IN] if n_zero else []
    if int(pos.sum()) < 2:
        return _empty(s, n_zero, bracket, [Note.TOO_FEW_RISING] + notes, lost)
    sd = _lost_sd(sd, pos, zero, lost)
    weigh = lost in ("floor", "own")
    use = pos | (zero if weigh else np.zeros_like(pos))
    weighted = bool(np.all(np.isfinite(sd[use]) & (sd[use] > 0)))
    w = np.where(use, 1.0 / sd if weighted else 1.0, 0.0)
    A = np.column_stack([1.0 / s[pos], -np.ones(int(pos.sum()))])
    x0, *_ = np.linalg.lstsq(A * w[pos, None], c[pos] * w[pos], rcond=None)
    s_cut = bracket[1] if lost == "censored" and math.isfinite(bracket[1]) else math.nan

    if math.isfinite(s_cut):
        # beta = alpha/s_cut + delta, delta >= 0: the line is at or below 0 from s_cut on
        def params(q):
            return q[0], q[0] / s_cut + q[1]

        q0 = np.array([x0[0], max(x0[1] - x0[0] / s_cut, 0.0)])
        bounds = ([-np.inf, 0.0], [np.inf, np.inf])
    else:
        def params(q):
            return q[0], q[1]

        q0, bounds = x0, (-np.inf, np.inf)

    def resid(q):
        a, b = params(q)
        return (model(s, a, b) - c) * w

    res = optimize.least_squares(resid, q0, method="trf", x_scale="jac", bounds=bounds)
    alpha, beta = (float(v) for v in params(res.x))
    r = c - model(s, alpha, beta)
    active = pos | (zero & weigh & (alpha / s - beta > 0))
    n_active = int(active.sum())
    binds = math.isfinite(s_cut) and res.x[1] <= 1e-12 * max(abs(beta), 1.0)
    n_active += int(binds)
    dof = n_active - 2
    chi2 = float(np.sum((r * w) ** 2))
    chi2_red = chi2 / dof if dof > 0 else math.nan
    # the covariance of (alpha, beta) from the Jacobian in (alpha, beta)
    J = np.column_stack([np.where(active & (alpha / s - beta > 0), w / s, 0.0),
                         np.where(active & (alpha / s - beta > 0), -w, 0.0)])
    poor = False
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((2, 2), np.nan)
    if weighted and dof > 0:
        poor = bool(chi2 > poor_threshold(dof, ns[active]))
        if chi2_red > 1:
            cov = cov * chi2_red
        if poor:
            notes.append(Note.POOR)
    elif dof > 0:
        cov = cov * chi2_red
        notes.append(Note.UNWEIGHTED)
    if n_active < MIN_ACTIVE or dof < MIN_DOF:
        notes.append(Note.TOO_FEW_ACTIVE)
    se = np.sqrt(np.clip(np.diag(cov), 0, None)) if np.all(np.isfinite(cov)) else (math.nan,) * 2
    sigma_c = math.nan
    if beta > 0 and alpha > 0:
        sigma_c = alpha / beta
    elif beta <= 0:
        notes.append(Note.BETA_NONPOS)
    else:
        notes.append(Note.ALPHA_NONPOS)
    return ABFit(alpha, beta, sigma_c, float(se[0]), float(se[1]), int(s.size), n_zero,
                 tuple(float(v) for v in s), tuple(float(v) for v in r), chi2_red, poor,
                 weighted, bracket, notes, n_active, dof, lost)


def t_interval(value, se, dof, level=0.95) -> tuple[float, float]:
    """value -+ t quantile x se (Student t with ``dof`` degrees of freedom; NaN if dof < 1)."""
    from scipy import stats

    if not (math.isfinite(value) and math.isfinite(se)) or dof < 1:
        return math.nan, math.nan
    q = float(stats.t.ppf(0.5 + level / 2, dof))
    return value - q * se, value + q * se

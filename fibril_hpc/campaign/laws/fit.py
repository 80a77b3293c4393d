"""Fits of a campaign: the "linear, then plateau" law per (k~, sigma~) and
c(sigma~) = alpha/sigma~ - beta.

Pure functions on plain numbers (no I/O, no plotting); :mod:`fibril_hpc.campaign.analysis.report`
orchestrates them.

**Law per (k~, sigma~).** F~_A(F~_P) rises linearly, F~_A = c F~_P, and then saturates at a
plateau P. Two laws with the same two parameters, the plateau P and the kink x_k = P / c
(where the linear stage would meet the plateau):

* ``"tanh"`` (a smooth saturation, the default): F~_A = P tanh(c F~_P / P);
* ``"min"`` (a hard kink): F~_A = min(c F~_P, P).

On an 18 x 18 campaign (README, "Report") tanh fitted every (k~, sigma~) at least as well as the
hard kink: F~_A bends over gradually, across about a decade of F~_P.

Both are fitted to every done job of the (k~, sigma~) (all seeds, all preloads) by least squares
in log F~_A (relative residuals: F~_A spans decades between the smallest preloads and the plateau,
and the scatter over seeds grows with F~_A). Written as log F~_A = log P + g(log F~_P - log x_k)
with g(t) = min(t, 0) or log tanh(e^t), the law is linear in log P for a fixed kink, so the fit
profiles log P out and minimises the residual over the kink (a grid, then golden section):
deterministic, no starting guess, no SciPy.

**Uncertainties.** With two or more seeds and ``n_boot > 0``: bootstrap over seeds (seeds are
the independent realisations; ``n_boot`` resamples with replacement, a fixed random seed); the
95 % interval is value x/÷ exp(t se), se the standard deviation of the log of the replicates
times sqrt(n/(n-1)), t the Student-t quantile for n - 1 degrees of freedom (n seeds: with three
seeds the percentile interval of the replicates would be far too narrow). With one seed, or
``n_boot = 0`` (the report's setting for the laws it only compares): the fit's covariance
(Gauss-Newton at the optimum, residual variance with n - 2 degrees of freedom, Student-t
quantile), as intervals in log (so they stay positive).

**Resolved.** The linear stage is *resolved* when at least two preload levels (seed-mean F~_P)
lie below the kink and the seed-mean F~_A rises across them at least as fast as sqrt(F~_P) (half
the log-slope of a linear stage; a flat run is the floor of the first contacts, where F~_A is the
pull-off of the few pillars that touch); otherwise the (k~, sigma~) is *unresolved*: its c is a
bound, not a measurement, and it does not enter alpha and beta. The plateau is *confirmed* when at least two
preload levels lie above the kink.

**alpha, beta.** Weighted least squares of c against 1/sigma~ over the resolved sigma~ > 0
(weights 1/var(c) from c's interval), the covariance scaled by the reduced chi^2 when it exceeds 1
(the scatter of c about the line is then larger than the seeds explain); sigma~_c = alpha / beta
with its interval from normal draws of (alpha, beta).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

LAWS = ("min", "tanh")
DEFAULT_LAW = "tanh"
N_BOOT = 400
#: two-sided 95 % Student-t quantiles for 1..30 degrees of freedom (larger: 1.96)
_T975 = (12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
         2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
         2.060, 2.056, 2.052, 2.048, 2.045, 2.042)


def t975(dof: int) -> float:
    """Two-sided 95 % Student-t quantile for ``dof`` degrees of freedom (NaN below 1)."""
    if dof < 1:
        return math.nan
    return _T975[dof - 1] if dof <= len(_T975) else 1.96


def _g(law: str, t):
    """log of the law's shape at t = log(F~_P / x_k) (0 on the plateau)."""
    t = np.asarray(t, dtype=float)
    if law == "min":
        return np.minimum(t, 0.0)
    # log tanh(e^t), stable for both tails
    e = np.exp(np.minimum(t, 50.0))
    return np.where(t < -20.0, t, np.log(np.tanh(e)))


def _dg(law: str, t):
    t = np.asarray(t, dtype=float)
    if law == "min":
        return (t < 0).astype(float)
    e = np.exp(np.minimum(t, 50.0))
    return np.where(t < -20.0, 1.0, e * 2.0 / np.sinh(np.minimum(2.0 * e, 700.0)))


def model(law: str, F_P, c: float, plateau: float):
    """F~_A of ``law`` at ``F_P`` (arrays welcome)."""
    x = np.asarray(F_P, dtype=float)
    if law == "min":
        return np.minimum(c * x, plateau)
    return plateau * np.tanh(c * x / plateau)


@dataclass
class LawFit:
    """A law fitted to points: c, plateau, kink (plateau / c) and the rms residual of log F~_A."""

    law: str
    c: float
    plateau: float
    kink: float
    rms_log: float                  # rms residual of log F~_A
    n_points: int


def fit_law(F_P, F_A, law: str = DEFAULT_LAW) -> LawFit:
    """Least-squares fit of ``law`` in log F~_A to points with F~_P > 0 and F~_A > 0."""
    if law not in LAWS:
        raise ValueError(f"law: {law!r} is not one of {LAWS}")
    x = np.asarray(F_P, dtype=float)
    y = np.asarray(F_A, dtype=float)
    ok = (x > 0) & (y > 0) & np.isfinite(x) & np.isfinite(y)
    u, v = np.log(x[ok]), np.log(y[ok])
    if u.size < 2:
        return LawFit(law, math.nan, math.nan, math.nan, math.nan, int(u.size))
    lo, hi = u.min() - 3.0, u.max() + 3.0

    def sse(tk):
        tk = np.atleast_1d(tk)
        gg = _g(law, u[None, :] - tk[:, None])
        lp = np.mean(v[None, :] - gg, axis=1)
        r = v[None, :] - lp[:, None] - gg
        return np.sum(r * r, axis=1), lp

    grid = np.linspace(lo, hi, 241)
    s, _ = sse(grid)
    i = int(np.argmin(s))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    gr = (math.sqrt(5.0) - 1.0) / 2.0
    m1, m2 = b - gr * (b - a), a + gr * (b - a)
    s1, s2 = sse(m1)[0][0], sse(m2)[0][0]
    for _ in range(60):                       # golden section on the bracketing cells
        if s1 <= s2:                          # keep [a, m2]; the old m1 is the new m2
            b, m2, s2 = m2, m1, s1
            m1 = b - gr * (b - a)
            s1 = sse(m1)[0][0]
        else:                                 # keep [m1, b]; the old m2 is the new m1
            a, m1, s1 = m1, m2, s2
            m2 = a + gr * (b - a)
            s2 = sse(m2)[0][0]
    tk = 0.5 * (a + b)
    if sse(grid[i])[0][0] < sse(tk)[0][0]:
        tk = grid[i]
    s_opt, lp = sse(tk)
    P, xk = math.exp(lp[0]), math.exp(tk)
    return LawFit(law, P / xk, P, xk, math.sqrt(s_opt[0] / u.size), int(u.size))


def _covariance_ci(F_P, F_A, f: LawFit) -> dict:
    """95 % intervals of c, plateau, kink from the Gauss-Newton covariance in (log P, log x_k)."""
    x = np.asarray(F_P, dtype=float)
    y = np.asarray(F_A, dtype=float)
    ok = (x > 0) & (y > 0)
    u, v = np.log(x[ok]), np.log(y[ok])
    n = u.size
    nan = (math.nan, math.nan)
    if n <= 2 or not math.isfinite(f.kink):
        return {"c": nan, "plateau": nan, "kink": nan}
    t = u - math.log(f.kink)
    r = v - math.log(f.plateau) - _g(f.law, t)
    J = np.column_stack([np.ones(n), -_dg(f.law, t)])      # d model / d(log P, log x_k)
    s2 = float(r @ r) / (n - 2)
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return {"c": nan, "plateau": nan, "kink": nan}
    q = t975(n - 2)
    out = {}
    for name, grad, val in (("plateau", (1.0, 0.0), f.plateau), ("kink", (0.0, 1.0), f.kink),
                            ("c", (1.0, -1.0), f.c)):
        g = np.array(grad)
        sd = math.sqrt(max(float(g @ cov @ g), 0.0))
        out[name] = (val * math.exp(-q * sd), val * math.exp(q * sd)) if np.isfinite(sd) else nan
    return out


@dataclass
class GroupFit:
    """The law fitted to one (k~, sigma~): values, 95 % intervals and flags."""

    k_tilde: float
    sigma_tilde: float
    law: str
    c: float
    plateau: float
    kink: float
    c_ci: tuple
    plateau_ci: tuple
    kink_ci: tuple
    ci_method: str                  # "bootstrap over N seeds" or "fit covariance (...)"
    n_seeds: int
    n_levels: int                   # preload levels (distinct requested preloads)
    n_below: int                    # preload levels whose seed-mean F~_P is below the kink
    n_above: int
    resolved: bool                  # linear stage resolved (n_below >= 2)
    plateau_confirmed: bool         # n_above >= 2
    rms_log: float
    rms_log_other: dict = field(default_factory=dict)   # the other laws' rms residuals
    note: str = ""
    c_boot: np.ndarray | None = None


def _levels(preload, F_P):
    """Seed-mean F~_P per requested preload level."""
    pre = np.asarray(preload, dtype=float)
    x = np.asarray(F_P, dtype=float)
    return np.array([np.mean(x[pre == p]) for p in np.unique(pre)])


def _boot_ci(value, boot, n_seeds):
    """95 % interval from bootstrap replicates in log: value x/÷ exp(t_{n-1} se), se the
    replicates' standard deviation x sqrt(n / (n - 1)) (the plain bootstrap spread is too narrow
    for a handful of seeds; the Student-t quantile with n - 1 degrees of freedom widens it)."""
    b = np.asarray(boot, dtype=float)
    b = b[np.isfinite(b) & (b > 0)]
    if b.size < 2 or not (math.isfinite(value) and value > 0):
        return (math.nan, math.nan)
    se = float(np.std(np.log(b))) * math.sqrt(n_seeds / (n_seeds - 1))
    q = t975(n_seeds - 1)
    return (value * math.exp(-q * se), value * math.exp(q * se))


def fit_group(seed, preload, F_P, F_A, *, law: str = DEFAULT_LAW, k_tilde=math.nan,
              sigma_tilde=math.nan, n_boot: int = N_BOOT, rng_seed: int = 0) -> GroupFit:
    """Fit one (k~, sigma~) from its done jobs (arrays of equal length, one entry per job)."""
    seed = np.asarray(seed)
    preload = np.asarray(preload, dtype=float)
    x = np.asarray(F_P, dtype=float)
    y = np.asarray(F_A, dtype=float)
    f = fit_law(x, y, law)
    others = {lw: fit_law(x, y, lw).rms_log for lw in LAWS if lw != law}
    seeds = np.unique(seed)
    lev = _levels(preload, x)
    below = int(np.sum(lev < f.kink)) if math.isfinite(f.kink) else 0
    above = int(lev.size - below) if math.isfinite(f.kink) else 0
    notes = []
    dropped = int(np.sum(~((x > 0) & (y > 0))))
    if dropped:
        notes.append(f"{dropped} job(s) with F~_A <= 0 or F~_P <= 0 left out of the log fit")
    c_boot = None
    if seeds.size >= 2 and n_boot > 0:
        rng = np.random.default_rng(rng_seed)
        idx = {s: np.flatnonzero(seed == s) for s in seeds}
        bs = []
        for _ in range(n_boot):
            pick = np.concatenate([idx[s] for s in rng.choice(seeds, size=seeds.size)])
            bf = fit_law(x[pick], y[pick], law)
            bs.append((bf.c, bf.plateau, bf.kink))
        bs = np.array(bs)
        cis = {n: _boot_ci(v, bs[:, i], seeds.size)
               for i, (n, v) in enumerate((("c", f.c), ("plateau", f.plateau),
                                           ("kink", f.kink)))}
        c_boot = bs[:, 0]
        method = f"bootstrap over {seeds.size} seeds"
    else:
        cis = _covariance_ci(x, y, f)
        method = ("fit covariance (one seed)" if seeds.size < 2
                  else "fit covariance (bootstrap off)")
    rising = True
    if below >= 2:
        fa_lev = _levels(preload, y)
        lo, hi = int(np.argmin(lev)), int(np.argmax(np.where(lev < f.kink, lev, -np.inf)))
        # a linear stage doubles F~_A when F~_P doubles; a floor (the pull-off of the few
        # pillars that touch first) stays flat: ask for at least half that log-slope
        rising = bool(fa_lev[lo] > 0 and fa_lev[hi] / fa_lev[lo] >= math.sqrt(lev[hi] / lev[lo]))
    resolved = below >= 2 and rising
    if below < 2:
        notes.append(f"unresolved: {below} preload level(s) below the kink F~_P = {f.kink:.3g} "
                     "(needs 2); c is a lower bound, left out of alpha and beta")
    elif not rising:
        notes.append("unresolved: below the kink F~_A rises less than sqrt(F~_P) (a floor of "
                     "first contacts, not a linear stage); left out of alpha and beta")
    if above < 2:
        notes.append(f"plateau not confirmed: {above} preload level(s) above the kink")
    return GroupFit(float(k_tilde), float(sigma_tilde), law, f.c, f.plateau, f.kink,
                    cis["c"], cis["plateau"], cis["kink"], method, int(seeds.size), int(lev.size),
                    below, above, resolved, above >= 2, f.rms_log, others, "; ".join(notes),
                    c_boot)


# ---------------------------------------------------------------------------- alpha, beta
@dataclass
class AlphaBeta:
    """c = alpha/sigma~ - beta fitted for one k~: values, 95 % intervals, residuals, notes."""

    k_tilde: float
    alpha: float
    beta: float
    sigma_c: float
    alpha_ci: tuple
    beta_ci: tuple
    sigma_c_ci: tuple
    n_sigma: int                    # resolved sigma~ values in the fit
    sigmas: tuple
    residuals: tuple                # c - (alpha/sigma~ - beta) per fitted sigma~
    rms_residual: float
    chi2_red: float
    note: str = ""


def fit_alpha_beta(k_tilde, groups, n_draws: int = 4000, rng_seed: int = 0) -> AlphaBeta:
    """alpha, beta of c = alpha/sigma~ - beta over the resolved groups with sigma~ > 0."""
    use = [g for g in groups if g.resolved and g.sigma_tilde > 0 and np.isfinite(g.c)]
    nan2 = (math.nan, math.nan)
    n = len(use)
    left = [g for g in groups if not (g.resolved and g.sigma_tilde > 0)]
    note = []
    if left:
        note.append("left out (unresolved or sigma~ = 0): sigma~ = "
                    + ", ".join(f"{g.sigma_tilde:g}" for g in left))
    if n < 2:
        note.append(f"{n} resolved sigma~ value(s): alpha and beta need 2")
        return AlphaBeta(float(k_tilde), math.nan, math.nan, math.nan, nan2, nan2, nan2, n,
                         tuple(g.sigma_tilde for g in use), (), math.nan, math.nan,
                         "; ".join(note))
    s = np.array([g.sigma_tilde for g in use])
    c = np.array([g.c for g in use])
    sd = np.array([(g.c_ci[1] - g.c_ci[0]) / (2 * 1.96) if np.all(np.isfinite(g.c_ci))
                   else math.nan for g in use])
    weighted = bool(np.all(np.isfinite(sd)) and np.all(sd > 0))
    w = 1.0 / sd**2 if weighted else np.ones(n)
    A = np.column_stack([1.0 / s, -np.ones(n)])
    Aw = A * np.sqrt(w)[:, None]
    cw = c * np.sqrt(w)
    (alpha, beta), *_ = np.linalg.lstsq(Aw, cw, rcond=None)
    res = c - (alpha / s - beta)
    dof = n - 2
    chi2 = float(np.sum(w * res**2))
    chi2_red = chi2 / dof if dof > 0 else math.nan
    cov = np.linalg.inv(Aw.T @ Aw)
    if weighted:
        scale = max(1.0, chi2_red) if dof > 0 else 1.0
        q = 1.96 if not (dof > 0 and chi2_red > 1) else t975(dof)
        how = "weights 1/var(c)" + (", covariance x reduced chi^2" if dof > 0 and chi2_red > 1
                                    else "")
    elif dof > 0:
        scale, q = chi2 / dof, t975(dof)
        how = "unweighted (c has no interval), covariance from the residuals"
    else:
        scale, q = math.nan, math.nan
        how = "no interval: 2 sigma~ values and c without intervals"
    cov = cov * scale
    note.append(how)
    a_sd, b_sd = (math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])) if np.all(np.isfinite(cov)) \
        else (math.nan, math.nan)
    alpha_ci = (alpha - q * a_sd, alpha + q * a_sd)
    beta_ci = (beta - q * b_sd, beta + q * b_sd)
    sigma_c, sc_ci = math.nan, nan2
    if beta > 0 and alpha > 0:
        sigma_c = alpha / beta
        if np.all(np.isfinite(cov)):
            rng = np.random.default_rng(rng_seed)
            d = rng.multivariate_normal([alpha, beta], cov * (q / 1.96) ** 2, size=n_draws)
            # a draw with beta <= 0 has no crossing: sigma~_c beyond every finite value
            big = 1e300
            r = np.where(d[:, 1] > 0, d[:, 0] / np.where(d[:, 1] > 0, d[:, 1], 1.0), big)
            lo, hi = (float(v) for v in np.percentile(np.minimum(r, big), [2.5, 97.5]))
            lo = lo if lo < big else math.nan
            if hi >= big:
                hi = math.nan
                note.append("beta's interval reaches 0: sigma~_c unbounded above "
                            "(upper limit left empty)")
            sc_ci = (lo, hi)
    elif beta <= 0:
        note.append(f"beta = {beta:.3g} <= 0: c does not fall to 0 at any sigma~ > 0 on this "
                    "line, so sigma~_c = alpha/beta is not defined (left empty)")
    else:
        note.append(f"alpha = {alpha:.3g} <= 0: sigma~_c not defined (left empty)")
    return AlphaBeta(float(k_tilde), float(alpha), float(beta), sigma_c, alpha_ci, beta_ci,
                     sc_ci, n, tuple(float(x) for x in s), tuple(float(r) for r in res),
                     float(math.sqrt(np.mean(res**2))), chi2_red, "; ".join(note))


# ---------------------------------------------------------------------------- whole campaign
def _get(j, name):
    return j[name] if isinstance(j, dict) else getattr(j, name)


def fit_campaign(jobs, law: str = DEFAULT_LAW, n_boot: int = N_BOOT) -> dict:
    """{k~: {"groups": [GroupFit per sigma~], "ab": AlphaBeta}} from done job records (dicts or
    objects with k_tilde, sigma_tilde, seed, preload, F_P, F_A, status)."""
    rows: dict = {}
    for j in jobs:
        if _get(j, "status") != "done":
            continue
        key = (float(_get(j, "k_tilde")), float(_get(j, "sigma_tilde")))
        rows.setdefault(key, []).append((_get(j, "seed"), _get(j, "preload"), _get(j, "F_P"),
                                         _get(j, "F_A")))
    out: dict = {}
    for (k, s), r in sorted(rows.items()):
        a = list(zip(*r))
        g = fit_group(*a, law=law, k_tilde=k, sigma_tilde=s, n_boot=n_boot)
        out.setdefault(k, {"groups": []})["groups"].append(g)
    for k, e in out.items():
        e["ab"] = fit_alpha_beta(k, e["groups"])
    return out

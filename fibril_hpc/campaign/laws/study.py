"""A campaign's science per k~: every (k~, sigma~) read (:mod:`.reading`), c(sigma~) fitted
(:mod:`.alphabeta`), and every number's seed interval from one bootstrap over seeds
(:mod:`.intervals`).

The bootstrap resamples seed labels *jointly* over the sigma~ of a k~ (a label picked twice
counts as two seeds), redoes every reading on the resample, then fits alpha and beta to the
resampled c with the weights of the full data: the intervals of the plateau, c, c0, alpha,
beta and sigma~_c come from the same replicates, each widened about its value for the small
number of seeds (:func:`.intervals.expanded`). Where the alpha/beta fit is poor (its residuals
exceed the seed scatter) the interval of alpha and beta is widened to hold the fit's own
Student-t interval (covariance scaled by chi^2/dof) as well.

**What the page may claim** (:func:`judge`). A k~ is *fitted* only when the fit exists, is not
poor and alpha's seed interval excludes 0; a poor fit is shown for orientation and named so; an
alpha consistent with 0 (interval reaching 0 or below) makes the law undefined for that k~.
sigma~_c = alpha/beta is *measured by the law* only when the k~ is fitted, beta's interval
excludes 0 and no sigma~ run lost adhesion (an extrapolation beyond the largest sigma~, with its
interval); with beta consistent with 0 it is undefined (the data do not show c reaching 0).
Where a sigma~ lost adhesion the model-free bracket (the largest sigma~ with c > 0, the smallest
with c = 0) is the measurement: alpha/beta inside it is *pinned* by the c = 0 point (it only says
where inside the line crosses), outside it (the line crossing 0 beyond the measured loss)
sigma~_c is undefined.

**The measured loss** (:mod:`.loss`): per k~ the sigma~ where the seed-mean plateau crosses the
loss threshold between the last group holding adhesion and the first lost one, its interval
from the same replicates (the plateaus of those two groups), and whether alpha/beta's sigma~_c
agrees with it (``loss_vs_law``) where the law is *fitted* (a poor or undefined line does not
describe c: its zero sits where the c = 0 points' weights put it, often exactly on a lost
sigma~); where beta is consistent with 0 the
law shows no sigma~_c and no agreement is claimed (an interval still wholly beyond the loss is
named).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .alphabeta import ABFit, fit_alpha_beta, t_interval
from . import loss as _loss
from .intervals import (coupled_replicates, expanded, percentile_interval, replicate_sd,
                        seed_replicates)
from .reading import FEW_PILLARS, HALF, LOST, UNDETERMINED, UNRESOLVED, Reading, read_group

N_BOOT = 400
NAN2 = (math.nan, math.nan)


@dataclass
class GroupResult:
    """One (k~, sigma~): its reading, seed intervals and whether c entered alpha and beta."""

    k_tilde: float
    sigma_tilde: float
    reading: Reading
    n_seeds: int
    plateau_ci: tuple = NAN2
    c_ci: tuple = NAN2
    c0_ci: tuple = NAN2
    c_sd: float = math.nan
    in_fit: bool = False
    why_out: str = ""


@dataclass
class KStudy:
    """One k~: its groups (ascending sigma~), the alpha/beta fit and its intervals."""

    k_tilde: float
    groups: list
    ab: ABFit
    alpha_ci: tuple = NAN2
    beta_ci: tuple = NAN2
    sigma_c_ci: tuple = NAN2
    ci_method: str = ""
    notes: list = field(default_factory=list)
    #: :func:`judge`'s verdicts: "fitted", "poor fit" or "undefined", with the reason
    status: str = "undefined"
    status_why: str = ""
    #: "measured", "pinned" (inside the data bracket) or "undefined", with the reason
    sigma_c_status: str = "undefined"
    sigma_c_why: str = ""
    #: the measured loss (:mod:`.loss`): its kind, bracket (lo, hi], sigma~_c where the plateau
    #: crosses the loss threshold, its seed interval and the page's sentence
    loss_kind: str = _loss.NOT_READ
    loss_bracket: tuple = NAN2
    sigma_loss: float = math.nan
    sigma_loss_ci: tuple = NAN2
    loss_note: str = ""
    #: alpha/beta's sigma~_c against the measured loss (:func:`.loss.compare`), with the reason
    loss_vs_law: str = ""
    loss_vs_law_why: str = ""


def _resample(pts, labels):
    """The points of the picked seed labels, each pick relabelled as its own seed."""
    seed, pre, x, y = pts
    idx = [np.flatnonzero(seed == lab) for lab in labels]
    new_seed = np.concatenate([np.full(i.size, j) for j, i in enumerate(idx)]) if idx else []
    sel = np.concatenate(idx) if idx else np.array([], dtype=int)
    return np.asarray(new_seed), pre[sel], x[sel], y[sel]


def _why_out(sigma: float, r: Reading) -> str:
    if sigma <= 0:
        return "sigma~ = 0 (the smooth limit) has no place in a law in 1/sigma~"
    if r.plateau_state == "no data":
        return "no finite points"
    if r.state == UNRESOLVED:
        return f"rise not resolved: c >= {r.c_lower:.3g} is a lower bound"
    if r.state == UNDETERMINED:
        return "state undetermined (too few levels, or no pillar floor to tell a loss)"
    if r.state == LOST:
        return ""
    if r.plateau_state == "not reached":
        return "plateau not reached: c is provisional"
    if not math.isfinite(r.c):
        return "c could not be read (the rise never reaches half the plateau)"
    return ""


def _ab_points(groups, cs=None):
    use = [g for g in groups if g.in_fit]
    s = [g.sigma_tilde for g in use]
    c = [g.reading.c for g in use] if cs is None else cs
    sd = [math.hypot(max(g.c_sd, g.reading.c_detect),
                     g.reading.c_res if math.isfinite(g.reading.c_res) else 0.0)
          if math.isfinite(g.c_sd) else math.nan for g in use]
    return s, c, sd


def study_k(k_tilde: float, points: dict, n_boot: int = N_BOOT, rng_seed: int = 0,
            half: float = HALF, floor: float = math.nan) -> KStudy:
    """``points``: {sigma~: (seed, preload, F_P, F_A) arrays of done jobs} of one k~; ``half``:
    the fraction of the rise of ``c_chord``; ``floor``: one pillar's pull-off
    (:func:`.reading.read_group`)."""
    pts = {float(s): tuple(np.asarray(a) for a in p) for s, p in sorted(points.items())}
    sigmas = list(pts)
    groups = []
    for s in sigmas:
        r = read_group(*pts[s], half=half, floor=floor)
        why = _why_out(s, r)
        groups.append(GroupResult(float(k_tilde), s, r, int(np.unique(pts[s][0]).size),
                                  in_fit=not why, why_out=why))
    labels = sorted(set().union(*(set(p[0].tolist()) for p in pts.values()))) if pts else []
    n = len(sigmas)

    sets = [sorted(set(pts[s][0].tolist())) for s in sigmas]
    uneven = any(x != sets[0] for x in sets)

    def stat(picked):               # one resample of the labels for every group, or one each
        out = []
        for i, s in enumerate(sigmas):
            r = read_group(*_resample(pts[s], picked[i] if uneven else picked), half=half,
                           floor=floor)
            out += [r.plateau, r.c, r.c0]
        return np.array(out)

    # groups with different seed sets (seeds: auto): each resamples its own seeds, coupled
    reps = None if not n else (coupled_replicates(sets, stat, n_boot, rng_seed) if uneven
                               else seed_replicates(labels, stat, n_boot, rng_seed))
    notes = []
    if reps is not None:
        for i, g in enumerate(groups):
            r, n_s = g.reading, g.n_seeds
            # non-negative numbers: the widened interval stops at 0
            g.plateau_ci = _nonneg(expanded(r.plateau, percentile_interval(reps[3 * i]), n_s))
            g.c_ci = _nonneg(expanded(r.c, percentile_interval(reps[3 * i + 1]), n_s))
            g.c0_ci = _nonneg(expanded(r.c0, percentile_interval(reps[3 * i + 2]), n_s))
            g.c_sd = replicate_sd(reps[3 * i + 1])
        method = (f"bootstrap over {len(labels)} seeds ({reps.shape[1]} resamples)" if not uneven
                  else f"bootstrap over each (k~, sigma~)'s own seeds, coupled across sigma~ "
                  f"({min(map(len, sets))} to {len(labels)} seeds; {reps.shape[1]} resamples)")
    else:
        method = ("one seed: no seed interval" if len(labels) < 2
                  else "bootstrap off: no seed interval")
    ab = fit_alpha_beta(*_ab_points(groups))
    st = KStudy(float(k_tilde), groups, ab, ci_method=method, notes=notes)
    _measure_loss(st, None if reps is None else reps[0::3], floor)
    if not ab.ok:
        return judge(st)
    dof = ab.n_points - 2
    cov_a, cov_b = t_interval(ab.alpha, ab.alpha_se, dof), t_interval(ab.beta, ab.beta_se, dof)
    if reps is None:
        st.alpha_ci, st.beta_ci = cov_a, cov_b
        st.ci_method += "; alpha, beta: the fit's covariance (Student t)"
        return judge(st)
    fit_idx = [i for i, g in enumerate(groups) if g.in_fit]
    s, _, sd = _ab_points(groups)
    ab_reps = []
    for b in range(reps.shape[1]):
        cb = [reps[3 * i + 1, b] for i in fit_idx]
        f = fit_alpha_beta(s, cb, sd)
        sc = (f.alpha / f.beta if f.beta > 0 and f.alpha > 0
              else (math.inf if f.ok and f.beta <= 0 else math.nan))
        ab_reps.append((f.alpha, f.beta, sc))
    ab_reps = np.array(ab_reps).T
    # alpha and beta rest on every group in the fit: widened for the fewest seeds among them
    n_l = min(g.n_seeds for g in groups if g.in_fit) if uneven else len(labels)
    st.alpha_ci = expanded(ab.alpha, percentile_interval(ab_reps[0]), n_l)
    st.beta_ci = expanded(ab.beta, percentile_interval(ab_reps[1]), n_l)
    st.sigma_c_ci = _nonneg(expanded(ab.sigma_c, percentile_interval(ab_reps[2]), n_l))
    if ab.poor:
        st.alpha_ci = (min(st.alpha_ci[0], cov_a[0]), max(st.alpha_ci[1], cov_a[1]))
        st.beta_ci = (min(st.beta_ci[0], cov_b[0]), max(st.beta_ci[1], cov_b[1]))
        notes.append("alpha, beta intervals widened to the fit's Student-t interval (poor fit)")
    unb = float(np.mean(np.isinf(ab_reps[2])))
    if unb > 0:
        notes.append(f"beta <= 0 in {100 * unb:.0f} % of the resamples: sigma~_c unbounded above")
    return judge(st)


def _measure_loss(st: KStudy, plateau_reps, floor: float) -> None:
    """Set the measured loss of ``st`` (:func:`.loss.measure`) from its groups and the bootstrap
    replicates of their plateaus (one row per group, or None)."""
    gs = st.groups
    m = _loss.measure([g.sigma_tilde for g in gs], [g.reading.state for g in gs],
                      [g.reading.plateau for g in gs], FEW_PILLARS * floor, plateau_reps,
                      [g.n_seeds for g in gs])
    st.loss_kind, st.loss_bracket, st.loss_note = m["kind"], m["bracket"], m["note"]
    st.sigma_loss, st.sigma_loss_ci = m["sigma"], m["ci"]


def _nonneg(ci: tuple) -> tuple:
    return tuple(max(v, 0.0) if math.isfinite(v) else v for v in ci)


def _consistent_with_zero(value: float, ci: tuple) -> bool:
    """The value is at or below 0, or its interval reaches 0 (an undefined interval says
    nothing: only the value is judged)."""
    if not math.isfinite(value) or value <= 0:
        return True
    return math.isfinite(ci[0]) and ci[0] <= 0


def beta_is_zero(st: KStudy) -> bool:
    """beta is at or below 0 or its interval reaches 0: only alpha is determined."""
    return _consistent_with_zero(st.ab.beta, st.beta_ci)


def judge(st: KStudy) -> KStudy:
    """Set what the page may claim of a k~ (the module text): ``status`` and ``sigma_c_status``
    with their reasons."""
    ab = st.ab
    lo, hi = ab.bracket
    br = (f"the data bracket sigma~_c in ({lo:g}, {hi:g}]" if math.isfinite(lo) and math.isfinite(hi)
          else (f"c > 0 up to the largest sigma~ run ({lo:g}): sigma~_c > {lo:g}"
                if math.isfinite(lo) else "no sigma~ with c > 0"))
    if not ab.ok:
        st.status, st.status_why = "undefined", (ab.notes[0] if ab.notes else "no fit")
    elif _consistent_with_zero(ab.alpha, st.alpha_ci):
        st.status = "undefined"
        st.status_why = (f"alpha = {ab.alpha:.3g} [{st.alpha_ci[0]:.3g}, {st.alpha_ci[1]:.3g}] "
                         "is consistent with 0: c does not fall as 1/sigma~ within the seed "
                         "scatter")
    elif ab.poor:
        st.status = "poor fit"
        st.status_why = (f"chi^2/dof = {ab.chi2_red:.3g}: c = alpha/sigma~ - beta does not "
                         "describe c within the seed scatter; alpha and beta for orientation only")
    else:
        st.status, st.status_why = "fitted", ""
    if st.status != "fitted":
        st.sigma_c_status = "undefined"
        st.sigma_c_why = f"the law is {st.status} for this k~; {br}"
    elif _consistent_with_zero(ab.beta, st.beta_ci) or not math.isfinite(ab.sigma_c):
        st.sigma_c_status = "undefined"
        st.sigma_c_why = (f"beta = {ab.beta:.3g} [{st.beta_ci[0]:.3g}, {st.beta_ci[1]:.3g}] is "
                          f"consistent with 0: the law does not show c reaching 0; {br}")
    elif math.isfinite(lo) and math.isfinite(hi) and lo <= ab.sigma_c <= hi * _loss.TOL:
        st.sigma_c_status = "pinned"
        st.sigma_c_why = (f"alpha/beta = {ab.sigma_c:.3g} lies in {br}: the line's zero is set "
                          f"by the c = 0 point at sigma~ = {hi:g}; the bracket is the measurement")
    elif math.isfinite(hi):
        st.sigma_c_status = "undefined"
        st.sigma_c_why = (f"alpha/beta = {ab.sigma_c:.3g} lies outside {br}: the line crosses 0 "
                          "beyond the sigma~ where adhesion was found lost; the bracket is the "
                          "measurement")
    else:
        st.sigma_c_status, st.sigma_c_why = "measured", ""
    st.loss_vs_law, st.loss_vs_law_why = _loss.compare(
        st.loss_kind, st.loss_bracket, st.sigma_loss, st.sigma_loss_ci,
        ab.sigma_c if ab.ok else math.nan, st.sigma_c_ci)
    if st.status != "fitted" and ab.ok:
        # a poor fit or alpha consistent with 0: the line does not describe c, and where its
        # zero falls is set by the c = 0 points' weights (it often sits exactly on a lost
        # sigma~, with a seed interval of zero width), not by the data: its failure is the finding
        st.loss_vs_law = ""
        st.loss_vs_law_why = (f"the law is {st.status} for this k~: its zero is not compared "
                              "with the measured loss")
    elif st.loss_vs_law == _loss.AGREE and beta_is_zero(st):
        # a zero the law does not show agrees with anything: say so instead of "agree" (a law
        # whose sigma~_c interval still lies wholly beyond the loss is named all the same)
        st.loss_vs_law = ""
        st.loss_vs_law_why = (f"beta = {ab.beta:.3g} [{st.beta_ci[0]:.3g}, {st.beta_ci[1]:.3g}]"
                              " is consistent with 0: alpha/beta shows no sigma~_c to agree "
                              "with the measured loss")
    return st


def study(points: dict, n_boot: int = N_BOOT, rng_seed: int = 0, half: float = HALF,
          floor: float = math.nan) -> dict:
    """``points``: {(k~, sigma~): (seed, preload, F_P, F_A)} -> {k~: :class:`KStudy`}, k~
    descending (stiff first, as the paper's figures); ``floor``: one pillar's pull-off
    (:func:`.reading.pillar_floor`)."""
    by_k: dict = {}
    for (k, s), p in points.items():
        by_k.setdefault(float(k), {})[float(s)] = p
    return {k: study_k(k, by_k[k], n_boot, rng_seed, half, floor)
            for k in sorted(by_k, reverse=True)}

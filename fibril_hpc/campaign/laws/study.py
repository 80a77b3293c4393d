"""A campaign's science per k~: every (k~, sigma~) read (:mod:`.reading`), c(sigma~) fitted
(:mod:`.alphabeta`), the loss of adhesion measured (:mod:`.loss`), every number's seed interval
from one bootstrap over seed labels (:mod:`.intervals`), and what the page may claim decided in
one place (:mod:`.verdict`).

**Seeds paired.** A seed is the same height pattern at every sigma~ (heights sigma~ (max xi -
xi_n), ``geometry/grid.py``), so numbers read across sigma~ (the crossing, alpha, beta) are
correlated through the seeds. The bootstrap resamples seed *labels*: one resample is one
multiset of labels, and a label drawn picks that seed in every group it is in (a label picked
twice counts as two seeds). Groups with different seed sets (``seeds: auto``) take the drawn
labels they hold (:func:`.intervals.paired_replicates`, which says what happens to a group left
with fewer than two). Every reading is redone on the resample, then alpha and beta are fitted to
the resampled c with the weights of the full data: the intervals of the plateau, c, c0, alpha,
beta, their zero and the crossing come from the same replicates, each widened about its value
for the small number of seeds (:func:`.intervals.expanded`; alpha and beta for the fewest seeds
of a rising group in the fit). Where the alpha/beta fit is poor the interval of alpha and beta
is widened to hold the fit's own Student-t interval (covariance scaled by chi^2/dof) as well.
An interval of zero width from seeds that scatter is no interval (NaN): it would claim a
certainty the seeds do not give.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

from . import loss as _loss
from . import verdict as _verdict
from .alphabeta import ABFit, fit_alpha_beta, t_interval
from .intervals import (expanded, paired_replicates, percentile_interval, replicate_sd,
                        seed_replicates)
from .reading import FEW_PILLARS, HALF, LOST, UNDETERMINED, UNRESOLVED, Reading, read_group

N_BOOT = 400
#: how lost groups enter the alpha/beta fit (:mod:`.alphabeta`: left out)
LOST_MODE = "out"
NAN2 = (math.nan, math.nan)


class OutReason(enum.StrEnum):
    """Why a group's c is not given to the alpha/beta fit (NONE: it is)."""

    NONE = ""
    SMOOTH_LIMIT = "sigma~ = 0"             # no place in a law in 1/sigma~
    NO_DATA = "no finite points"
    UNRESOLVED = "rise not resolved"        # c >= reading.c_lower, a lower bound
    UNDETERMINED = "state undetermined"     # too few levels, or no pillar floor
    NOT_REACHED = "plateau not reached"     # c provisional
    NO_C = "c not read"                     # the rise never reaches half the plateau


class CIKind(enum.StrEnum):
    """How the seed intervals of a k~ were made."""

    ONE_SEED = "one seed"                   # no interval
    OFF = "bootstrap off"                   # no interval (n_boot < 1)
    SAME_SEEDS = "same seeds"               # every group holds the same seeds: one multiset
    PAIRED_MIXED = "paired, mixed sets"     # seeds: auto: each group takes the labels it holds


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
    out: str = ""                   # why c is not given to the fit (:class:`OutReason`)


@dataclass
class KStudy:
    """One k~: its groups (ascending sigma~), the alpha/beta fit and its intervals, the measured
    loss and the verdict (:mod:`.verdict`)."""

    k_tilde: float
    groups: list
    ab: ABFit
    alpha_ci: tuple = NAN2
    beta_ci: tuple = NAN2
    sigma_c_ci: tuple = NAN2        # the interval of alpha/beta, the line's zero
    ci_kind: str = CIKind.OFF       # how the seed intervals were made (:class:`CIKind`)
    n_labels: int = 0               # seed labels of the k~ (the union)
    min_seeds: int = 0              # the fewest seeds of a group
    n_resamples: int = 0
    ab_from_cov: bool = False       # alpha, beta intervals from the fit's covariance (no bootstrap)
    widened_poor: bool = False      # alpha, beta widened to the fit's Student-t interval (poor)
    unbounded_share: float = 0.0    # share of resamples with beta <= 0 (alpha/beta unbounded)
    #: the measured loss (:class:`.loss.Loss`): the critical roughness of this brush
    loss: _loss.Loss = field(default_factory=_loss.Loss)
    verdict: _verdict.Verdict = field(default_factory=_verdict.Verdict)

    @property
    def status(self) -> str:
        """The law's state (:class:`.verdict.LawState`)."""
        return self.verdict.law

    @property
    def loss_vs_law(self) -> str:
        """Where alpha/beta's zero lies against the measured loss (:class:`.verdict.Relation`)."""
        return self.verdict.relation

    @property
    def loss_kind(self) -> str:
        """:attr:`.loss.Loss.kind`."""
        return self.loss.kind

    @property
    def loss_bracket(self) -> tuple:
        """:attr:`.loss.Loss.bracket`."""
        return self.loss.bracket

    @property
    def sigma_loss(self) -> float:
        """The measured sigma~_c (:attr:`.loss.Loss.sigma`)."""
        return self.loss.sigma

    @property
    def sigma_loss_ci(self) -> tuple:
        """Its seed interval (:attr:`.loss.Loss.ci`)."""
        return self.loss.ci


def _resample(pts, labels):
    """The points of the picked seed labels, each pick relabelled as its own seed."""
    seed, pre, x, y = pts
    idx = [np.flatnonzero(seed == lab) for lab in labels]
    new_seed = np.concatenate([np.full(i.size, j) for j, i in enumerate(idx)]) if idx else []
    sel = np.concatenate(idx) if idx else np.array([], dtype=int)
    return np.asarray(new_seed), pre[sel], x[sel], y[sel]


def _out(sigma: float, r: Reading) -> OutReason:
    if sigma <= 0:
        return OutReason.SMOOTH_LIMIT
    if r.plateau_state == "no data":
        return OutReason.NO_DATA
    if r.state == UNRESOLVED:
        return OutReason.UNRESOLVED
    if r.state == UNDETERMINED:
        return OutReason.UNDETERMINED
    if r.state == LOST:
        return OutReason.NONE
    if r.plateau_state == "not reached":
        return OutReason.NOT_REACHED
    if not math.isfinite(r.c):
        return OutReason.NO_C
    return OutReason.NONE


def _ab_points(groups, cs=None):
    use = [g for g in groups if g.in_fit]
    s = [g.sigma_tilde for g in use]
    c = [g.reading.c for g in use] if cs is None else cs
    sd = [math.hypot(max(g.c_sd, g.reading.c_detect),
                     g.reading.c_res if math.isfinite(g.reading.c_res) else 0.0)
          if math.isfinite(g.c_sd) else math.nan for g in use]
    return s, c, sd, [g.n_seeds for g in use]


def study_k(k_tilde: float, points: dict, n_boot: int = N_BOOT, rng_seed: int = 0,
            half: float = HALF, floor: float = math.nan, lost: str = LOST_MODE) -> KStudy:
    """``points``: {sigma~: (seed, preload, F_P, F_A) arrays of done jobs} of one k~; ``half``:
    the fraction of the rise of ``c_chord``; ``floor``: one pillar's pull-off
    (:func:`.reading.read_group`); ``lost``: how lost groups enter the alpha/beta fit
    (:data:`.alphabeta.LOST_MODES`)."""
    pts = {float(s): tuple(np.asarray(a) for a in p) for s, p in sorted(points.items())}
    sigmas = list(pts)
    groups = []
    for s in sigmas:
        r = read_group(*pts[s], half=half, floor=floor)
        why = _out(s, r)
        groups.append(GroupResult(float(k_tilde), s, r, int(np.unique(pts[s][0]).size),
                                  in_fit=why == OutReason.NONE, out=why))
    labels = sorted(set().union(*(set(p[0].tolist()) for p in pts.values()))) if pts else []
    n = len(sigmas)

    sets = [sorted(set(pts[s][0].tolist())) for s in sigmas]
    uneven = any(x != sets[0] for x in sets)
    match = _matched_pair(groups, sets)

    def stat(picked):               # one resample of the labels for every group, or one each
        out = []
        for i, s in enumerate(sigmas):
            r = read_group(*_resample(pts[s], picked[i] if uneven else picked), half=half,
                           floor=floor)
            out += [r.plateau, r.c, r.c0]
        if match is not None:       # the bracket's larger group read on each other's labels
            ref, others = match
            out += [read_group(*_resample(pts[sigmas[ref]], picked[o]), half=half,
                               floor=floor).plateau for o in others]
        return np.array(out)

    # groups with different seed sets (seeds: auto): the drawn labels each holds, paired
    reps = None if not n else (paired_replicates(sets, stat, n_boot, rng_seed) if uneven
                               else seed_replicates(labels, stat, n_boot, rng_seed))
    if reps is not None:
        for i, g in enumerate(groups):
            r, n_s = g.reading, g.n_seeds
            # non-negative numbers: the widened interval stops at 0
            g.plateau_ci = _nonneg(expanded(r.plateau, percentile_interval(reps[3 * i]), n_s))
            g.c_ci = _nonneg(expanded(r.c, percentile_interval(reps[3 * i + 1]), n_s))
            g.c0_ci = _nonneg(expanded(r.c0, percentile_interval(reps[3 * i + 2]), n_s))
            g.c_sd = replicate_sd(reps[3 * i + 1])
        kind = CIKind.PAIRED_MIXED if uneven else CIKind.SAME_SEEDS
    else:
        kind = CIKind.ONE_SEED if len(labels) < 2 else CIKind.OFF
    s0, c0, sd0, ns0 = _ab_points(groups)
    ab = fit_alpha_beta(s0, c0, sd0, lost=lost, n_seeds=ns0)
    st = KStudy(float(k_tilde), groups, ab, ci_kind=kind, n_labels=len(labels),
                min_seeds=min(map(len, sets)) if sets else 0,
                n_resamples=0 if reps is None else reps.shape[1])
    on_other = None
    if match is not None:           # the full data's: the larger group on each other's seeds
        on_other = [read_group(*_resample(pts[sigmas[match[0]]], sets[o]), half=half,
                               floor=floor).plateau for o in match[1]]
    _measure_loss(st, None if reps is None else reps[0:3 * n:3], floor, match, on_other,
                  None if reps is None or match is None else reps[3 * n:])
    _per_seed(st, pts, half, floor)
    if not ab.ok:
        return judge(st)
    cov_a, cov_b = t_interval(ab.alpha, ab.alpha_se, ab.dof), t_interval(ab.beta, ab.beta_se, ab.dof)
    if reps is None:
        st.alpha_ci, st.beta_ci, st.ab_from_cov = cov_a, cov_b, True
        return judge(st)
    fit_idx = [i for i, g in enumerate(groups) if g.in_fit]
    s, _, sd, ns = _ab_points(groups)
    ab_reps = []
    for b in range(reps.shape[1]):
        cb = [reps[3 * i + 1, b] for i in fit_idx]
        f = fit_alpha_beta(s, cb, sd, lost=lost, n_seeds=ns)
        sc = (f.alpha / f.beta if f.beta > 0 and f.alpha > 0
              else (math.inf if f.ok and f.beta <= 0 else math.nan))
        ab_reps.append((f.alpha, f.beta, sc))
    ab_reps = np.array(ab_reps).T
    # alpha and beta rest on the rising groups of the fit: widened for the fewest seeds there
    rising = [g.n_seeds for g in groups if g.in_fit and g.reading.c > 0]
    n_l = min(rising) if rising else len(labels)
    scatter = any(g.c_sd > 0 for g in groups if g.in_fit and g.reading.c > 0)
    st.alpha_ci = _spread(expanded(ab.alpha, percentile_interval(ab_reps[0]), n_l), scatter)
    st.beta_ci = _spread(expanded(ab.beta, percentile_interval(ab_reps[1]), n_l), scatter)
    st.sigma_c_ci = _spread(_nonneg(expanded(ab.sigma_c, percentile_interval(ab_reps[2]), n_l)),
                            scatter)
    if ab.poor:
        st.alpha_ci = (min(st.alpha_ci[0], cov_a[0]), max(st.alpha_ci[1], cov_a[1]))
        st.beta_ci = (min(st.beta_ci[0], cov_b[0]), max(st.beta_ci[1], cov_b[1]))
        st.widened_poor = True
    st.unbounded_share = float(np.mean(np.isinf(ab_reps[2])))
    return judge(st)


def _spread(ci: tuple, scatter: bool) -> tuple:
    """``ci``, or no interval (NaN) where it has zero width although the seeds scatter."""
    if scatter and all(math.isfinite(v) for v in ci) and ci[1] <= ci[0]:
        return NAN2
    return ci


def _matched_pair(groups, sets):
    """(larger, (other,)): the indices of the loss bracket's two groups where their seed sets
    differ and one holds the other's (``seeds: auto`` runs seeds first .. first + n - 1, so its
    sets are nested); None where they are equal, not nested, or there is no bracket. Only the
    bracket is carried: a brush's strength measured there says nothing of sigma~ far from it
    (at the floor every brush holds one pillar)."""
    pair = _loss.bracket_indices([g.sigma_tilde for g in groups],
                                 [g.reading.state for g in groups])
    if pair is None:
        return None
    i, j = pair
    a, b = set(sets[i]), set(sets[j])
    if b < a:
        return i, (j,)
    return (j, (i,)) if a < b else None


def _matched(other, larger, larger_on_other):
    """The other group's plateau carried to the larger group's seeds: its own seed mean times
    how the larger group's seeds stand to the other's seeds where both ran (a seed is the same
    brush in both groups). NaN where that ratio is not a positive number."""
    with np.errstate(all="ignore"):
        ratio = np.asarray(larger, dtype=float) / np.asarray(larger_on_other, dtype=float)
        out = np.asarray(other, dtype=float) * ratio
    return np.where(np.isfinite(ratio) & (ratio > 0), out, np.nan)


def _measure_loss(st: KStudy, plateau_reps, floor: float, match=None, on_other=None,
                  on_other_reps=None) -> None:
    """Set the measured loss of ``st`` (:func:`.loss.measure`) from its groups and the bootstrap
    replicates of their plateaus (one row per group, or None).

    **The same brushes at both ends of the bracket.** Where ``seeds: auto`` ran fewer seeds at
    one of the bracket's two groups (it stops adding seeds to a group whose state looks
    certain), their seed means are means over different brushes, and a crossing between them,
    or the smaller group's certainty, would mix the sigma~ step with which brushes each holds.
    The smaller group's plateau is carried to the larger group's seeds (``match`` = (larger,
    (other,)); :func:`_matched`, with ``on_other``: the larger group read on the other's seeds;
    in every replicate likewise, ``on_other_reps``), and its interval (for its state's
    certainty) comes from the carried replicates. The groups' own numbers (the plateau table)
    are unchanged."""
    gs = st.groups
    plateaus = [g.reading.plateau for g in gs]
    cis = [g.plateau_ci for g in gs]
    if match is not None:
        ref, others = match
        if plateau_reps is not None:
            plateau_reps = np.array(plateau_reps, dtype=float)
        for k, o in enumerate(others):
            plateaus[o] = float(_matched(plateaus[o], plateaus[ref], on_other[k]))
            if plateau_reps is not None and on_other_reps is not None:
                plateau_reps[o] = _matched(plateau_reps[o], plateau_reps[ref], on_other_reps[k])
                cis[o] = _nonneg(expanded(plateaus[o], percentile_interval(plateau_reps[o]),
                                          gs[o].n_seeds))
    st.loss = _loss.measure([g.sigma_tilde for g in gs], [g.reading.state for g in gs],
                            plateaus, FEW_PILLARS * floor, plateau_reps,
                            [g.n_seeds for g in gs], cis)
    pair = _loss.bracket_indices([g.sigma_tilde for g in gs], [g.reading.state for g in gs])
    if match is not None and pair is not None and set(pair) & set(match[1]):
        st.loss.matched = (gs[match[0]].n_seeds, min(gs[k].n_seeds for k in pair))
    ci = st.loss.ci
    # no zero-width interval where the two plateaus scatter
    pair = _loss.bracket_indices([g.sigma_tilde for g in gs], [g.reading.state for g in gs])
    if pair is not None and plateau_reps is not None:
        spread = any(np.nanstd(plateau_reps[k]) > 0 for k in pair)
        if _spread(ci, spread) != ci:
            st.loss.ci = st.loss.another = NAN2


def _per_seed(st: KStudy, pts: dict, half: float, floor: float) -> None:
    """Each seed's own crossing of the loss threshold between the two bracketing groups."""
    gs = st.groups
    pair = _loss.bracket_indices([g.sigma_tilde for g in gs], [g.reading.state for g in gs])
    if pair is None:
        return
    lo, hi = (pts[gs[k].sigma_tilde] for k in pair)
    out = []
    for lab in sorted(set(lo[0].tolist()) & set(hi[0].tolist())):
        p = [read_group(*_resample(g, [lab]), half=half, floor=floor).plateau for g in (lo, hi)]
        out.append((lab, _loss.crossing(gs[pair[0]].sigma_tilde, gs[pair[1]].sigma_tilde, *p,
                                        st.loss.threshold, clip=False)))
    st.loss.per_seed = tuple(out)


def _nonneg(ci: tuple) -> tuple:
    return tuple(max(v, 0.0) if math.isfinite(v) else v for v in ci)


def beta_is_zero(st: KStudy) -> bool:
    """beta is at or below 0 or its interval reaches 0: only alpha is determined."""
    return _verdict.consistent_with_zero(st.ab.beta, st.beta_ci)


def judge(st: KStudy) -> KStudy:
    """Set ``st.verdict`` (:func:`.verdict.judge`: the one place that decides)."""
    st.verdict = _verdict.judge(st.ab, st.alpha_ci, st.beta_ci, st.sigma_c_ci, st.loss)
    return st


def study(points: dict, n_boot: int = N_BOOT, rng_seed: int = 0, half: float = HALF,
          floor: float = math.nan, lost: str = LOST_MODE) -> dict:
    """``points``: {(k~, sigma~): (seed, preload, F_P, F_A)} -> {k~: :class:`KStudy`}, k~
    descending (stiff first, as the paper's figures); ``floor``: one pillar's pull-off
    (:func:`.reading.pillar_floor`)."""
    by_k: dict = {}
    for (k, s), p in points.items():
        by_k.setdefault(float(k), {})[float(s)] = p
    return {k: study_k(k, by_k[k], n_boot, rng_seed, half, floor, lost)
            for k in sorted(by_k, reverse=True)}

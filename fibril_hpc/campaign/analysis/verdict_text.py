"""The page's words for the states and numbers of the laws (:mod:`..laws.verdict`,
:mod:`..laws.loss`, :mod:`..laws.alphabeta`): the one place that turns them into sentences, for
the page, its tables and the CSV. Inputs: a :class:`..laws.study.KStudy`.
"""

from __future__ import annotations

import math

from ..laws import loss as _loss
from ..laws.alphabeta import MIN_ACTIVE, MIN_DOF, Note
from ..laws.reading import LOST
from ..laws.study import CIKind, OutReason
from ..laws.verdict import LawReason, Relation, RelationReason, ZeroReason

#: a table cell's words for where alpha/beta's zero lies against the measured span
#: (:attr:`..laws.loss.Loss.span`); keys :class:`..laws.verdict.Relation` (str values)
RELATION_WORDS = {
    Relation.WITHIN: "inside the measured span",
    Relation.ABOVE: "above the measured span (the line still gives c > 0 where adhesion is lost)",
    Relation.BELOW: "below the measured span (the line reaches 0 where the brush still holds)",
}
#: why a law is not *fitted*, in a figure legend's few words, per
#: :class:`..laws.verdict.LawReason`
LAW_REASON_WORDS = {
    LawReason.NO_LINE: "fewer than 2 sigma~ with c > 0",
    LawReason.TOO_FEW_ACTIVE: f"fewer than {MIN_ACTIVE} active points",
    LawReason.ALPHA_ZERO: "alpha consistent with 0",
    LawReason.CHI2: "poor fit",
    LawReason.NONE: "",
}
#: why the page shows no zero of the line, per :class:`..laws.verdict.ZeroReason` (short)
NO_ZERO_WORDS = {
    ZeroReason.LAW_NOT_FITTED: "law not fitted",
    ZeroReason.BETA_ZERO: "beta consistent with 0: the line may never reach 0, no zero shown",
    ZeroReason.NONE: "the line does not reach 0",
}


def fmt_ci(v: float, ci: tuple) -> str:
    """'v [lo, hi]' in three digits (the value alone without an interval; an infinite end as
    ∞)."""
    if not math.isfinite(v):
        return "—"
    if any(math.isnan(x) for x in ci):
        return f"{v:.3g}"

    def end(x):
        return "∞" if x == math.inf else ("−∞" if x == -math.inf else f"{x:.3g}")

    return f"{v:.3g} [{end(ci[0])}, {end(ci[1])}]"


def ab_notes(ab) -> list:
    """The alpha/beta fit's notes (:class:`..laws.alphabeta.Note`) in words."""
    out = []
    for n in ab.notes:
        if n == Note.TOO_FEW_RISING:
            out.append(f"{ab.n_points - ab.n_zero} sigma~ with c > 0: alpha and beta need at "
                       "least 2")
        elif n == Note.TOO_FEW_ACTIVE:
            out.append(f"{ab.n_active} active points, {ab.dof} dof: a line through "
                       f"{MIN_ACTIVE - 1} points is no fit of the law (at least {MIN_ACTIVE} "
                       f"points and {MIN_DOF} dof)")
        elif n == Note.POOR:
            out.append(f"poor fit: residuals exceed the seed scatter (chi^2/dof = "
                       f"{ab.chi2_red:.3g} on {ab.dof} dof)")
        elif n == Note.UNWEIGHTED:
            out.append("unweighted (one seed: c has no scatter); covariance from the residuals")
        elif n == Note.BETA_NONPOS:
            out.append(f"beta = {ab.beta:.3g} <= 0: the line alpha/sigma~ - beta stays above 0 "
                       "at every sigma~ and has no zero")
        elif n == Note.ALPHA_NONPOS:
            out.append(f"alpha = {ab.alpha:.3g} <= 0: c does not fall as 1/sigma~")
        elif n == Note.LOST_OUT:
            out.append(f"{ab.n_zero} sigma~ with adhesion lost (c = 0) left out of the fit: the "
                       "line describes c where the brush adheres")
        elif n == Note.LOST_IN:
            out.append(f"{ab.n_zero} sigma~ with c = 0 in the fit ({ab.lost})")
    return out


def law_why(st) -> str:
    """Why the law of a k~ is not *fitted* ("" when it is)."""
    ab, r = st.ab, st.verdict.law_reason
    if r == LawReason.NO_LINE:
        return ab_notes(ab)[0] if ab.notes else "no fit"
    if r == LawReason.TOO_FEW_ACTIVE:
        return (f"{ab.n_active} active points and {ab.dof} dof: at least {MIN_ACTIVE} and "
                f"{MIN_DOF} make a fit of the law")
    if r == LawReason.ALPHA_ZERO:
        return (f"alpha = {fmt_ci(ab.alpha, st.alpha_ci)} is consistent with 0: c does not fall "
                "as 1/sigma~ within the seed scatter")
    if r == LawReason.CHI2:
        return (f"chi^2/dof = {ab.chi2_red:.3g}: c = alpha/sigma~ - beta does not describe c "
                "within the seed scatter; alpha and beta for orientation only")
    return ""


def zero_why(st) -> str:
    """What alpha/beta's zero is for a k~: an extrapolation of c(sigma~), or why there is none."""
    v = st.verdict
    if v.zero_reason == ZeroReason.LAW_NOT_FITTED:
        return f"the law is {v.law} for this k~: its zero alpha/beta is not shown"
    if v.zero_reason == ZeroReason.BETA_ZERO:
        return (f"beta = {fmt_ci(st.ab.beta, st.beta_ci)} is consistent with 0: the line shows "
                "no zero")
    return (f"alpha/beta = {fmt_ci(st.ab.sigma_c, st.sigma_c_ci)}: where the line "
            "extrapolates c to 0 (an extrapolation, not a measurement)")


def _span(st) -> str:
    lo, hi = st.verdict.span
    return f"({lo:.3g}, {'∞' if hi == math.inf else f'{hi:.3g}'}]"


def relation_why(st) -> str:
    """Where alpha/beta's zero lies against the measured loss, in one clause ("" when the law is
    not fitted or the loss not measured: said elsewhere)."""
    v = st.verdict
    zero = f"alpha/beta's zero {fmt_ci(st.ab.sigma_c, v.zero_ci)}"
    if v.relation in RELATION_WORDS and v.zero_reason == ZeroReason.BETA_ZERO:
        # no zero shown (beta consistent with 0), but wherever the line could reach 0 is beyond
        # the measured loss: it still gives c > 0 where adhesion is lost
        a, b = v.zero_ci
        side = (f"above {a:.3g}" if v.relation == Relation.ABOVE else f"below {b:.3g}")
        what = ("it still gives c > 0 where adhesion is lost" if v.relation == Relation.ABOVE
                else "it reaches 0 where the brush still holds")
        return (f"the line shows no zero (beta consistent with 0); if it reaches 0 at all, it is "
                f"{side}, beyond the measured loss, span {_span(st)}: {what}")
    if v.relation in RELATION_WORDS:
        where = {Relation.WITHIN: "overlaps", Relation.ABOVE: "lies above",
                 Relation.BELOW: "lies below"}[v.relation]
        return f"{zero} {where} the measured loss, span {_span(st)}"
    if v.relation_reason == RelationReason.UNBOUNDED:
        return (f"{zero} and the measured loss, span {_span(st)}: an interval reaching ∞ "
                "cannot be told from the other")
    if v.relation_reason == RelationReason.NO_ZERO:
        return f"{zero}: beta is consistent with 0, so the line shows no zero to set beside it"
    if v.relation_reason == RelationReason.NO_INTERVAL:
        return f"{zero} has no seed interval: not set against the measured loss"
    return ""


def loss_note(st) -> str:
    """The measured loss of a k~ in one sentence (:class:`..laws.loss.Loss`)."""
    m = st.loss
    if m.kind == _loss.NOT_READ:
        return "no sigma~ whose state could be read: the loss is not measured"
    if m.kind == _loss.NO_LOSS:
        note = (f"no loss up to sigma~ = {m.bracket[0]:g} (the largest run): sigma~_c > "
                f"{m.bracket[0]:g}")
    elif m.kind == _loss.ALL_LOST:
        note = (f"lost at every sigma~ run (< {m.bracket[1]:g}): adhesion is already lost at the"
                f" smallest sigma~, sigma~_c < {m.bracket[1]:.3g}")
        if m.again:
            note += ("; adhesion is found again at sigma~ = " + ", ".join(f"{x:g}" for x in m.again)
                     + " (not monotone in sigma~)")
        return note + _uncertain(m)
    else:
        lo, hi = m.bracket
        note = (f"adhesion lost at sigma~ = {fmt_ci(m.sigma, m.ci)} (the plateau crosses the "
                f"loss threshold {m.threshold:.3g}; bracket {lo:.3g}-{hi:.3g})")
        own = [x for _, x in m.per_seed if not math.isnan(x)]
        if len(own) > 1:
            # a seed's own line crosses outside the bracket where it is lost (or holds) at both
            # groups: where beyond them is not measured, so it is counted, not extrapolated
            below = sum(x < lo for x in own)
            above = sum(x > hi for x in own)
            inside = [x for x in own if lo <= x <= hi]
            parts = ([f"{below} below {lo:.3g}"] if below else []) + (
                [f"{len(inside)} inside ({min(inside):.3g}-{max(inside):.3g})"] if inside
                else []) + ([f"{above} above {hi:.3g}"] if above else [])
            note += f"; each seed's own crossing: {', '.join(parts)} ({len(own)} seeds)"
        if m.matched:
            note += (f"; the two groups ran {m.matched[0]} and {m.matched[1]} seeds: the crossing "
                     f"compares the same {m.matched[0]} brushes (the smaller group's plateau "
                     "carried to them by how its seeds stand to them where both ran)")
        if m.again:
            note += ("; adhesion is found again above it at sigma~ = "
                     + ", ".join(f"{x:g}" for x in m.again) + " (not monotone in sigma~)")
    return note + _uncertain(m)


def _uncertain(m) -> str:
    if not m.uncertain:
        return ""
    lo, hi = m.span
    return ("; with their seeds the state of sigma~ = " + ", ".join(f"{x:g}" for x in m.uncertain)
            + " is not certain (plateau interval holds the threshold"
            + (", the smaller group's as carried to the same brushes" if m.matched else "")
            + f"): the loss lies in "
            f"({lo:.3g}, {'∞' if hi == math.inf else f'{hi:.3g}'}]")


def why_out(g) -> str:
    """Why a group's c is not in the alpha/beta fit ("" when it is)."""
    r, o = g.reading, g.out
    return {OutReason.NONE: "",
            OutReason.SMOOTH_LIMIT: "sigma~ = 0 (the smooth limit) has no place in a law in "
                                    "1/sigma~",
            OutReason.NO_DATA: "no finite points",
            OutReason.UNRESOLVED: f"rise not resolved: c >= {r.c_lower:.3g} is a lower bound",
            OutReason.UNDETERMINED: "state undetermined (too few levels, or no pillar floor to "
                                    "tell a loss)",
            OutReason.NOT_REACHED: "plateau not reached: c is provisional",
            OutReason.NO_C: "c could not be read (the rise never reaches half the plateau)",
            }.get(o, str(o))


def line_out(g, ab) -> str:
    """Why a group is not a point of the alpha/beta line ("" when it is): :func:`why_out`, or,
    for a lost group (c = 0) that the fit leaves out (``ab.lost == "out"``), that it is."""
    if g.in_fit and g.reading.state == LOST and ab.lost == "out":
        return "adhesion lost (c = 0): left out of the alpha/beta line"
    return why_out(g)


def ci_method(st) -> str:
    """How the seed intervals of a k~ were made, in words."""
    if st.ci_kind == CIKind.ONE_SEED:
        out = "one seed: no seed interval"
    elif st.ci_kind == CIKind.OFF:
        out = "bootstrap off: no seed interval"
    elif st.ci_kind == CIKind.SAME_SEEDS:
        out = f"bootstrap over {st.n_labels} seeds ({st.n_resamples} resamples)"
    else:
        out = (f"bootstrap over seed labels paired across sigma~, each (k~, sigma~) taking the "
               f"drawn labels it holds ({st.min_seeds} to {st.n_labels} seeds; "
               f"{st.n_resamples} resamples)")
    return out + ("; alpha, beta: the fit's covariance (Student t)" if st.ab_from_cov else "")


def study_notes(st) -> list:
    """The notes of a k~'s intervals, in words."""
    out = []
    if st.widened_poor:
        out.append("alpha, beta intervals widened to the fit's Student-t interval (poor fit)")
    if st.unbounded_share > 0:
        out.append(f"beta <= 0 in {100 * st.unbounded_share:.0f} % of the resamples: alpha/beta "
                   "unbounded above")
    return out


__all__ = ["RELATION_WORDS", "NO_ZERO_WORDS", "LAW_REASON_WORDS", "fmt_ci", "ab_notes", "law_why",
           "zero_why", "relation_why", "loss_note", "why_out", "line_out", "ci_method", "study_notes"]

"""What the report may claim of one k~, decided in one place: the state of the alpha/beta law,
of its zero, and where that zero lies against the measured loss. States and the numbers behind
them, no words (the page's are in ``analysis/verdict_text.py``).

**The law** (:class:`LawState`). *fitted* only when the line is a fit (at least three active
points and one degree of freedom, :attr:`.alphabeta.ABFit.enough`), it is not poor (chi^2/dof
within the seed scatter) and alpha's seed interval excludes 0; *poor fit* when its residuals
exceed the seed scatter (shown for orientation); *undefined* otherwise (:class:`LawReason`).

**Its zero** alpha/beta (:class:`ZeroState`) is an extrapolation of c(sigma~), never a second
critical roughness: *extrapolated* where the law is fitted and beta's interval excludes 0, else
*none*. The critical roughness is the measured one (:mod:`.loss`).

**Where the zero lies** (:class:`Relation`), a description: *above* when its whole interval
lies above the measured span (:attr:`.loss.Loss.span`: the bracket, widened by groups whose
state is not certain and by the crossing's interval), *below* when wholly below it, *within*
when they overlap and both are bounded; otherwise none, with the reason. An infinite end (of
the span or of the zero's interval) is the least certain case: a side reaching infinity is
never above or below anything on that side, and an overlap with an unbounded interval is not
*within*. A zero without an interval (one seed, or no bootstrap) is not compared. So widening
any interval can move the relation only from above/below/within towards none, never the other
way (tests/test_report_verdict.py checks it as a property).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from . import loss as _loss
from .alphabeta import ABFit

NAN2 = (math.nan, math.nan)


class LawState(enum.StrEnum):
    """The alpha/beta law of a k~ (values: the CSV's ``status``)."""

    FITTED = "fitted"
    POOR = "poor fit"
    UNDEFINED = "undefined"


class LawReason(enum.StrEnum):
    """Why the law is not *fitted*."""

    NONE = ""
    NO_LINE = "no line"                     # fewer than two c > 0
    TOO_FEW_ACTIVE = "too few active"       # < 3 active points or < 1 dof
    ALPHA_ZERO = "alpha consistent with 0"  # alpha's interval reaches 0
    CHI2 = "residuals beyond the scatter"   # poor: chi^2/dof beyond its 99 % point


class ZeroState(enum.StrEnum):
    """alpha/beta, the line's zero: an extrapolation of c(sigma~)."""

    EXTRAPOLATED = "extrapolated"
    NONE = "none"


class ZeroReason(enum.StrEnum):
    """Why the line shows no zero."""

    NONE = ""
    LAW_NOT_FITTED = "law not fitted"
    BETA_ZERO = "beta consistent with 0"


class Relation(enum.StrEnum):
    """Where alpha/beta's zero lies against the measured loss (values: the CSV's
    ``loss_vs_law``)."""

    WITHIN = "within"
    ABOVE = "above"
    BELOW = "below"
    NONE = ""


class RelationReason(enum.StrEnum):
    """Why the zero is not set against the measured loss."""

    NONE = ""
    NOT_MEASURED = "loss not measured"
    LAW_NOT_FITTED = "law not fitted"
    NO_ZERO = "no zero"                     # the line shows none (beta consistent with 0)
    NO_INTERVAL = "no interval"             # the zero has no seed interval
    UNBOUNDED = "unbounded"                 # an overlap where an interval reaches infinity


@dataclass(frozen=True)
class Verdict:
    """What the page may claim of a k~ and the numbers behind it."""

    law: LawState = LawState.UNDEFINED
    law_reason: LawReason = LawReason.NO_LINE
    zero: ZeroState = ZeroState.NONE
    zero_reason: ZeroReason = ZeroReason.LAW_NOT_FITTED
    relation: Relation = Relation.NONE
    relation_reason: RelationReason = RelationReason.LAW_NOT_FITTED
    span: tuple = NAN2                      # the measured span the zero was set against
    zero_ci: tuple = NAN2                   # the zero's interval as compared


def consistent_with_zero(value: float, ci: tuple) -> bool:
    """The value is at or below 0, or its interval reaches 0 (an undefined interval says
    nothing: only the value is judged; a lower end at -inf reaches 0)."""
    if not math.isfinite(value) or value <= 0:
        return True
    return bool(ci[0] <= 0)          # False for a NaN end


def law_state(ab: ABFit, alpha_ci: tuple) -> tuple:
    """(:class:`LawState`, :class:`LawReason`) of a fit and alpha's interval."""
    if not ab.ok:
        return LawState.UNDEFINED, LawReason.NO_LINE
    if not ab.enough:
        return LawState.UNDEFINED, LawReason.TOO_FEW_ACTIVE
    if consistent_with_zero(ab.alpha, alpha_ci):
        return LawState.UNDEFINED, LawReason.ALPHA_ZERO
    if ab.poor:
        return LawState.POOR, LawReason.CHI2
    return LawState.FITTED, LawReason.NONE


def relation(span: tuple, zero_ci: tuple) -> tuple:
    """(:class:`Relation`, :class:`RelationReason`) of the zero's interval ``zero_ci`` against
    the measured ``span`` (module text; NaN ends: no interval)."""
    a, b = zero_ci
    m_lo, m_hi = span
    if math.isnan(a) or math.isnan(b):
        return Relation.NONE, RelationReason.NO_INTERVAL
    if math.isnan(m_lo) or math.isnan(m_hi):
        return Relation.NONE, RelationReason.NOT_MEASURED
    if a > m_hi:
        return Relation.ABOVE, RelationReason.NONE
    if b < m_lo:
        return Relation.BELOW, RelationReason.NONE
    if not all(math.isfinite(v) for v in (a, b, m_lo, m_hi)):
        return Relation.NONE, RelationReason.UNBOUNDED
    return Relation.WITHIN, RelationReason.NONE


def judge(ab: ABFit, alpha_ci: tuple, beta_ci: tuple, zero_ci: tuple,
          measured: _loss.Loss) -> Verdict:
    """The :class:`Verdict` of one k~ (module text)."""
    law, why = law_state(ab, alpha_ci)
    if law != LawState.FITTED:
        zero, zero_why = ZeroState.NONE, ZeroReason.LAW_NOT_FITTED
    elif consistent_with_zero(ab.beta, beta_ci) or not math.isfinite(ab.sigma_c):
        zero, zero_why = ZeroState.NONE, ZeroReason.BETA_ZERO
    else:
        zero, zero_why = ZeroState.EXTRAPOLATED, ZeroReason.NONE
    span = measured.span
    if measured.kind == _loss.NOT_READ:
        rel, rel_why = Relation.NONE, RelationReason.NOT_MEASURED
    elif law != LawState.FITTED:
        rel, rel_why = Relation.NONE, RelationReason.LAW_NOT_FITTED
    else:
        rel, rel_why = relation(span, zero_ci)
        if rel == Relation.WITHIN and zero == ZeroState.NONE:
            # a zero the line does not show lies "within" anything: not a statement
            rel, rel_why = Relation.NONE, RelationReason.NO_ZERO
    return Verdict(law, why, zero, zero_why, rel, rel_why, span, tuple(zero_ci))


__all__ = ["LawState", "LawReason", "ZeroState", "ZeroReason", "Relation", "RelationReason",
           "Verdict", "judge", "relation", "law_state", "consistent_with_zero"]

"""laws.verdict, pinned so that its one-line mutations fail (issue 34, item 6;
benchmarks/mutation.py): what "consistent with 0" means at its edges, the order of the law's
states (no line, too few active points, alpha consistent with 0, poor, fitted), where the zero's
interval lies against the measured span at every boundary (touching is an overlap; an infinite
end is never a side), and which statement the verdict of a k~ may make in each case."""

import math

import numpy as np

from fibril_hpc.campaign.laws import loss
from fibril_hpc.campaign.laws.alphabeta import ABFit, fit_alpha_beta
from fibril_hpc.campaign.laws.verdict import (
    LawReason,
    LawState,
    Relation,
    RelationReason,
    Verdict,
    ZeroReason,
    ZeroState,
    consistent_with_zero,
    judge,
    law_state,
    relation,
)

INF, NAN = math.inf, math.nan
S = [0.2, 0.3, 0.45, 0.6, 0.8]


def _fit(alpha=1.0, beta=0.9, **kw):
    """An ABFit of the given numbers (a line that is a fit unless told otherwise)."""
    f = dict(alpha=alpha, beta=beta, sigma_c=alpha / beta if alpha > 0 < beta else NAN,
             alpha_se=0.01, beta_se=0.01, n_points=5, n_zero=0, sigmas=tuple(S),
             residuals=(0.0,) * 5, chi2_red=0.5, poor=False, weighted=True, bracket=(0.8, NAN),
             notes=[], n_active=5, dof=3)
    f.update(kw)
    return ABFit(**f)


MEASURED = loss.Loss(kind=loss.BRACKET, bracket=(1.0, 1.2), span=(0.95, 1.3), sigma=1.1)


def test_consistent_with_zero_at_its_edges():
    for v, ci in ((0.0, (1.0, 2.0)), (-0.5, (1.0, 2.0)), (NAN, (1.0, 2.0)), (1.0, (0.0, 2.0)),
                  (1.0, (-0.1, 2.0)), (1.0, (-INF, 2.0)), (INF, (1.0, 2.0))):
        assert consistent_with_zero(v, ci) is True, (v, ci)
    for v, ci in ((1.0, (0.1, 2.0)), (1.0, (NAN, NAN)), (1.0, (NAN, 2.0)), (1e-9, (1e-10, 1))):
        assert consistent_with_zero(v, ci) is False, (v, ci)


def test_the_law_state_in_its_order():
    assert law_state(_fit(), (0.5, 1.5)) == (LawState.FITTED, LawReason.NONE)
    assert law_state(_fit(alpha=NAN), (0.5, 1.5)) == (LawState.UNDEFINED, LawReason.NO_LINE)
    assert law_state(_fit(beta=NAN), (0.5, 1.5)) == (LawState.UNDEFINED, LawReason.NO_LINE)
    # too few active points comes before alpha and before poor
    few = _fit(n_active=2, dof=0, poor=True)
    assert law_state(few, (-1.0, 1.5)) == (LawState.UNDEFINED, LawReason.TOO_FEW_ACTIVE)
    assert law_state(_fit(n_active=3, dof=0), (0.5, 1.5))[1] == LawReason.TOO_FEW_ACTIVE
    assert law_state(_fit(n_active=3, dof=1), (0.5, 1.5))[0] == LawState.FITTED
    # alpha consistent with 0 comes before poor
    assert law_state(_fit(poor=True), (-0.1, 1.5)) == (LawState.UNDEFINED, LawReason.ALPHA_ZERO)
    assert law_state(_fit(alpha=-0.2, beta=-1.0), (-0.3, -0.1)) == (LawState.UNDEFINED,
                                                                   LawReason.ALPHA_ZERO)
    assert law_state(_fit(poor=True), (0.5, 1.5)) == (LawState.POOR, LawReason.CHI2)
    assert law_state(_fit(poor=True), (NAN, NAN)) == (LawState.POOR, LawReason.CHI2)


def test_where_the_zero_lies_against_the_span_at_every_boundary():
    span = (1.0, 2.0)
    assert relation(span, (2.0001, 3.0)) == (Relation.ABOVE, RelationReason.NONE)
    assert relation(span, (2.0, 3.0)) == (Relation.WITHIN, RelationReason.NONE)   # touching
    assert relation(span, (0.5, 0.9999)) == (Relation.BELOW, RelationReason.NONE)
    assert relation(span, (0.5, 1.0)) == (Relation.WITHIN, RelationReason.NONE)
    assert relation(span, (1.2, 1.4)) == (Relation.WITHIN, RelationReason.NONE)
    assert relation(span, (0.0, 9.0)) == (Relation.WITHIN, RelationReason.NONE)
    # an interval end missing: no interval, whichever end, before the span is looked at
    for z in ((NAN, 3.0), (3.0, NAN), (NAN, NAN)):
        assert relation(span, z) == (Relation.NONE, RelationReason.NO_INTERVAL), z
        assert relation((NAN, NAN), z) == (Relation.NONE, RelationReason.NO_INTERVAL), z
    for sp in ((NAN, 2.0), (1.0, NAN), (NAN, NAN)):
        assert relation(sp, (1.2, 1.4)) == (Relation.NONE, RelationReason.NOT_MEASURED), sp
    # an infinite end is never a side, and an overlap with it is not "within"
    assert relation((1.0, INF), (2.0, 3.0)) == (Relation.NONE, RelationReason.UNBOUNDED)
    assert relation((1.0, INF), (0.2, 0.5)) == (Relation.BELOW, RelationReason.NONE)
    assert relation((1.0, 2.0), (1.5, INF)) == (Relation.NONE, RelationReason.UNBOUNDED)
    assert relation((1.0, 2.0), (2.5, INF)) == (Relation.ABOVE, RelationReason.NONE)
    assert relation((1.0, 2.0), (-INF, 1.5)) == (Relation.NONE, RelationReason.UNBOUNDED)
    assert relation((-INF, 2.0), (1.5, 1.7)) == (Relation.NONE, RelationReason.UNBOUNDED)


def test_the_verdict_of_a_fitted_law_with_a_zero():
    ab = fit_alpha_beta(S, [1.0 / s - 0.9 for s in S], [0.05] * 5)
    v = judge(ab, (0.5, 1.5), (0.5, 1.3), (1.05, 1.2), MEASURED)
    assert v == Verdict(LawState.FITTED, LawReason.NONE, ZeroState.EXTRAPOLATED, ZeroReason.NONE,
                        Relation.WITHIN, RelationReason.NONE, (0.95, 1.3), (1.05, 1.2))
    above = judge(ab, (0.5, 1.5), (0.5, 1.3), [1.4, 1.6], MEASURED)
    assert above.relation == Relation.ABOVE and above.zero_ci == (1.4, 1.6)
    assert isinstance(above.zero_ci, tuple)
    assert judge(ab, (0.5, 1.5), (0.5, 1.3), (0.5, 0.9), MEASURED).relation == Relation.BELOW
    # the span as measured, not the bare bracket
    wide = loss.Loss(kind=loss.BRACKET, bracket=(1.0, 1.2), span=(0.95, INF), sigma=1.1)
    v = judge(ab, (0.5, 1.5), (0.5, 1.3), (1.4, 1.6), wide)
    assert v.span == (0.95, INF) and v.relation == Relation.NONE
    assert v.relation_reason == RelationReason.UNBOUNDED
    # other kinds of measured loss are compared by their span as well
    none = loss.Loss(kind=loss.NO_LOSS, bracket=(0.8, INF), span=(0.8, INF))
    assert judge(ab, (0.5, 1.5), (0.5, 1.3), (0.5, 0.7), none).relation == Relation.BELOW


def test_the_verdict_when_the_zero_is_not_shown():
    ab = fit_alpha_beta(S, [1.0 / s - 0.9 for s in S], [0.05] * 5)
    # beta consistent with 0: no zero; an overlap says nothing, a side still does
    v = judge(ab, (0.5, 1.5), (0.0, 1.3), (1.05, 1.2), MEASURED)
    assert (v.zero, v.zero_reason) == (ZeroState.NONE, ZeroReason.BETA_ZERO)
    assert (v.relation, v.relation_reason) == (Relation.NONE, RelationReason.NO_ZERO)
    assert v.law == LawState.FITTED
    assert judge(ab, (0.5, 1.5), (0.0, 1.3), (1.4, 1.6), MEASURED).relation == Relation.ABOVE
    # a line whose zero is not finite shows none either
    flat = _fit(alpha=1.0, beta=0.5, sigma_c=INF)
    v = judge(flat, (0.5, 1.5), (0.2, 0.8), (1.05, 1.2), MEASURED)
    assert v.zero_reason == ZeroReason.BETA_ZERO and v.relation_reason == RelationReason.NO_ZERO
    # the zero's interval is missing: no relation, the zero still extrapolated
    v = judge(ab, (0.5, 1.5), (0.5, 1.3), (NAN, NAN), MEASURED)
    assert v.zero == ZeroState.EXTRAPOLATED
    assert (v.relation, v.relation_reason) == (Relation.NONE, RelationReason.NO_INTERVAL)


def test_the_verdict_of_a_law_not_fitted_or_a_loss_not_measured():
    ab = fit_alpha_beta(S, [1.0 / s - 0.9 for s in S], [0.05] * 5)
    poor = _fit(poor=True)
    for fit, law, why in ((poor, LawState.POOR, LawReason.CHI2),
                          (_fit(n_active=2, dof=0), LawState.UNDEFINED,
                           LawReason.TOO_FEW_ACTIVE)):
        v = judge(fit, (0.5, 1.5), (0.5, 1.3), (1.4, 1.6), MEASURED)
        assert (v.law, v.law_reason) == (law, why)
        assert (v.zero, v.zero_reason) == (ZeroState.NONE, ZeroReason.LAW_NOT_FITTED)
        assert (v.relation, v.relation_reason) == (Relation.NONE, RelationReason.LAW_NOT_FITTED)
        assert v.span == (0.95, 1.3)
    v = judge(ab, (-0.5, 1.5), (0.5, 1.3), (1.4, 1.6), MEASURED)
    assert (v.law_reason, v.relation_reason) == (LawReason.ALPHA_ZERO,
                                                 RelationReason.LAW_NOT_FITTED)
    # the loss not read: said before the law, whatever the law
    for fit in (ab, poor):
        v = judge(fit, (0.5, 1.5), (0.5, 1.3), (1.4, 1.6), loss.Loss())
        assert (v.relation, v.relation_reason) == (Relation.NONE, RelationReason.NOT_MEASURED)
        assert math.isnan(v.span[0]) and math.isnan(v.span[1])
    assert judge(ab, (0.5, 1.5), (0.5, 1.3), (1.05, 1.2), loss.Loss()).zero == \
        ZeroState.EXTRAPOLATED


def test_the_default_verdict_claims_nothing():
    v = Verdict()
    assert (v.law, v.law_reason) == (LawState.UNDEFINED, LawReason.NO_LINE)
    assert (v.zero, v.zero_reason) == (ZeroState.NONE, ZeroReason.LAW_NOT_FITTED)
    assert (v.relation, v.relation_reason) == (Relation.NONE, RelationReason.LAW_NOT_FITTED)
    assert all(math.isnan(x) for x in v.span + v.zero_ci) and len(v.span) == len(v.zero_ci) == 2
    # the words the CSV takes from the states
    assert [s.value for s in LawState] == ["fitted", "poor fit", "undefined"]
    assert [r.value for r in Relation] == ["within", "above", "below", ""]
    assert np.all([r.value == "" for r in (LawReason.NONE, ZeroReason.NONE,
                                          RelationReason.NONE)])

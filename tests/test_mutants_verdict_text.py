"""The page's words for the laws' states (analysis/verdict_text.py, zero_cell.py, loss_page.py),
pinned so that their one-line mutations fail (issue 34, item 6; benchmarks/mutation.py): every
sentence a state or a note turns into, with its numbers, word for word (the page says one thing
per state; a changed word or a dropped number is a different page). The studies are stand-ins
with the fields the words read (a :class:`..laws.study.KStudy`'s), so the words are tested for
each state whether or not a campaign reaches it."""

import math
from types import SimpleNamespace as NS

import pytest

from fibril_hpc.campaign.analysis import loss_page as lp
from fibril_hpc.campaign.analysis import verdict_text as vt
from fibril_hpc.campaign.analysis import zero_cell as zc
from fibril_hpc.campaign.laws import loss
from fibril_hpc.campaign.laws.alphabeta import ABFit, Note
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED
from fibril_hpc.campaign.laws.study import CIKind, OutReason
from fibril_hpc.campaign.laws.verdict import (
    LawReason,
    LawState,
    Relation,
    RelationReason,
    Verdict,
    ZeroReason,
    ZeroState,
)

INF, NAN = math.inf, math.nan


def _ab(**kw):
    f = dict(alpha=1.23456, beta=0.98765, sigma_c=1.25, alpha_se=0.01, beta_se=0.01,
             n_points=7, n_zero=2, sigmas=(), residuals=(), chi2_red=2.34567, poor=False,
             weighted=True, bracket=(0.8, 1.2), notes=[], n_active=4, dof=2, lost="out")
    f.update(kw)
    return ABFit(**f)


def _study(ab=None, verdict=None, measured=None, **kw):
    measured = measured or loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.8, INF),
                                     sigma=1.04321, ci=(0.95, 1.15), threshold=0.0248)
    verdict = verdict or Verdict(LawState.FITTED, LawReason.NONE, ZeroState.EXTRAPOLATED,
                                 ZeroReason.NONE, Relation.WITHIN, RelationReason.NONE,
                                 (0.8, 1.5), (1.1, 1.4))
    st = dict(ab=ab or _ab(), verdict=verdict, loss=measured, alpha_ci=(1.1, 1.35),
              beta_ci=(0.9, 1.05), sigma_c_ci=(1.1, 1.4), ci_kind=CIKind.SAME_SEEDS,
              n_labels=5, min_seeds=3, n_resamples=400, ab_from_cov=False, widened_poor=False,
              unbounded_share=0.0)
    st.update(kw)
    st = NS(**st)
    st.loss_kind, st.loss_bracket = st.loss.kind, st.loss.bracket
    st.sigma_loss, st.sigma_loss_ci = st.loss.sigma, st.loss.ci
    st.status = st.verdict.law
    return st


def test_fmt_ci():
    assert vt.fmt_ci(1.23456, (1.0, 1.5)) == "1.23 [1, 1.5]"
    assert vt.fmt_ci(1.23456, (0.987654, INF)) == "1.23 [0.988, ∞]"
    assert vt.fmt_ci(-1.0, (-INF, 2.0)) == "-1 [−∞, 2]"
    assert vt.fmt_ci(1.23456, (NAN, 2.0)) == "1.23"
    assert vt.fmt_ci(1.23456, (1.0, NAN)) == "1.23"
    for v in (NAN, INF, -INF):
        assert vt.fmt_ci(v, (1.0, 2.0)) == "—"


def test_the_fit_notes_in_words():
    ab = _ab(notes=list(Note), lost="floor", beta=-0.5, alpha=-0.25)
    assert vt.ab_notes(ab) == [
        "5 sigma~ with c > 0: alpha and beta need at least 2",
        "4 active points, 2 dof: a line through 2 points is no fit of the law (at least 3 "
        "points and 1 dof)",
        "poor fit: residuals exceed the seed scatter (chi^2/dof = 2.35 on 2 dof)",
        "unweighted (one seed: c has no scatter); covariance from the residuals",
        "beta = -0.5 <= 0: the line alpha/sigma~ - beta stays above 0 at every sigma~ and has "
        "no zero",
        "alpha = -0.25 <= 0: c does not fall as 1/sigma~",
        "2 sigma~ with adhesion lost (c = 0) left out of the fit: the line describes c where the "
        "brush adheres",
        "2 sigma~ with c = 0 in the fit (floor)",
    ]
    assert vt.ab_notes(_ab()) == []
    assert vt.ab_notes(_ab(notes=[Note.LOST_IN, Note.POOR])) == [
        "2 sigma~ with c = 0 in the fit (out)",
        "poor fit: residuals exceed the seed scatter (chi^2/dof = 2.35 on 2 dof)"]


def test_why_a_law_is_not_fitted():
    def why(reason, **kw):
        v = Verdict(LawState.UNDEFINED, reason)
        return vt.law_why(_study(verdict=v, **kw))

    assert why(LawReason.NO_LINE, ab=_ab(notes=[Note.TOO_FEW_RISING, Note.LOST_OUT],
                                         n_points=3)) == \
        "1 sigma~ with c > 0: alpha and beta need at least 2"
    assert why(LawReason.NO_LINE, ab=_ab(notes=[])) == "no fit"
    assert why(LawReason.TOO_FEW_ACTIVE) == ("4 active points and 2 dof: at least 3 and 1 make "
                                             "a fit of the law")
    assert why(LawReason.ALPHA_ZERO, alpha_ci=(-0.1, 2.5)) == (
        "alpha = 1.23 [-0.1, 2.5] is consistent with 0: c does not fall as 1/sigma~ within the "
        "seed scatter")
    assert why(LawReason.CHI2) == (
        "chi^2/dof = 2.35: c = alpha/sigma~ - beta does not describe c within the seed scatter; "
        "alpha and beta for orientation only")
    assert why(LawReason.NONE) == ""


def test_what_the_zero_is():
    st = _study()
    assert vt.zero_why(st) == ("alpha/beta = 1.25 [1.1, 1.4]: where the line extrapolates c to "
                               "0 (an extrapolation, not a measurement)")
    st = _study(verdict=Verdict(LawState.POOR, LawReason.CHI2, ZeroState.NONE,
                                ZeroReason.LAW_NOT_FITTED))
    assert vt.zero_why(st) == "the law is poor fit for this k~: its zero alpha/beta is not shown"
    st = _study(verdict=Verdict(LawState.FITTED, LawReason.NONE, ZeroState.NONE,
                                ZeroReason.BETA_ZERO), beta_ci=(-0.2, 2.0))
    assert vt.zero_why(st) == "beta = 0.988 [-0.2, 2] is consistent with 0: the line shows no zero"


def _rel(rel, why=RelationReason.NONE, span=(0.8, 1.5), zero_ci=(1.1, 1.4)):
    return _study(verdict=Verdict(LawState.FITTED, LawReason.NONE, ZeroState.EXTRAPOLATED,
                                  ZeroReason.NONE, rel, why, span, zero_ci))


def test_where_the_zero_lies_in_words():
    assert vt.relation_why(_rel(Relation.WITHIN)) == (
        "alpha/beta's zero 1.25 [1.1, 1.4] overlaps the measured loss, span (0.8, 1.5]")
    assert vt.relation_why(_rel(Relation.ABOVE, span=(0.8, 1.04))) == (
        "alpha/beta's zero 1.25 [1.1, 1.4] lies above the measured loss, span (0.8, 1.04]")
    assert vt.relation_why(_rel(Relation.BELOW, span=(1.5, INF))) == (
        "alpha/beta's zero 1.25 [1.1, 1.4] lies below the measured loss, span (1.5, ∞]")
    assert vt.relation_why(_rel(Relation.NONE, RelationReason.UNBOUNDED, (0.8, INF))) == (
        "alpha/beta's zero 1.25 [1.1, 1.4] and the measured loss, span (0.8, ∞]: an interval "
        "reaching ∞ cannot be told from the other")
    assert vt.relation_why(_rel(Relation.NONE, RelationReason.NO_ZERO)) == (
        "alpha/beta's zero 1.25 [1.1, 1.4]: beta is consistent with 0, so the line shows no "
        "zero to set beside it")
    assert vt.relation_why(_rel(Relation.NONE, RelationReason.NO_INTERVAL,
                                zero_ci=(NAN, NAN))) == (
        "alpha/beta's zero 1.25 has no seed interval: not set against the measured loss")
    for why in (RelationReason.NOT_MEASURED, RelationReason.LAW_NOT_FITTED):
        assert vt.relation_why(_rel(Relation.NONE, why)) == ""
    # the table cell's words, one per side
    assert vt.RELATION_WORDS[Relation.WITHIN] == "inside the measured span"
    assert vt.RELATION_WORDS[Relation.ABOVE].startswith("above the measured span (")
    assert vt.RELATION_WORDS[Relation.BELOW].startswith("below the measured span (")


def test_the_measured_loss_in_one_sentence():
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.8, INF), sigma=1.04321,
                  ci=(0.95, INF), threshold=0.0248, uncertain=(0.8, 1.5),
                  per_seed=((0, 0.97), (1, NAN), (2, 1.11), (3, INF)), again=(2.1, 3.0))
    assert vt.loss_note(_study(measured=m)) == (
        "adhesion lost at sigma~ = 1.04 [0.95, ∞] (the plateau crosses the loss threshold "
        "0.0248; bracket 0.9-1.2); each seed's own crossing: 2 inside (0.97-1.11), 1 above "
        "1.2 (3 seeds); "
        "adhesion is found again above it at sigma~ = 2.1, 3 (not monotone in sigma~); with "
        "their seeds the state of sigma~ = 0.8, 1.5 is not certain (plateau interval holds the "
        "threshold): the loss lies in (0.8, ∞]")
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.85, 1.3), sigma=1.04321,
                  ci=(0.95, 1.15), threshold=0.0248, per_seed=((0, 0.97), (2, 1.11111)))
    assert vt.loss_note(_study(measured=m)) == (
        "adhesion lost at sigma~ = 1.04 [0.95, 1.15] (the plateau crosses the loss threshold "
        "0.0248; bracket 0.9-1.2); each seed's own crossing: 2 inside (0.97-1.11) (2 seeds)")
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), sigma=1.0, threshold=0.0248,
                  per_seed=((0, 0.97),))
    assert vt.loss_note(_study(measured=m)) == (
        "adhesion lost at sigma~ = 1 (the plateau crosses the loss threshold 0.0248; bracket "
        "0.9-1.2)")
    m = loss.Loss(kind=loss.NO_LOSS, bracket=(2.1, INF), span=(1.5, INF), uncertain=(2.1,))
    assert vt.loss_note(_study(measured=m)) == (
        "no loss up to sigma~ = 2.1 (the largest run): sigma~_c > 2.1; with their seeds the "
        "state of sigma~ = 2.1 is not certain (plateau interval holds the threshold): the loss "
        "lies in (1.5, ∞]")
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.123456), span=(0.0, 0.5),
                  again=(0.7, 0.9), uncertain=(0.3,))
    assert vt.loss_note(_study(measured=m)) == (
        "lost at every sigma~ run (< 0.123456): adhesion is already lost at the smallest "
        "sigma~, sigma~_c < 0.123; adhesion is found again at sigma~ = 0.7, 0.9 (not monotone in "
        "sigma~); with their seeds the state of sigma~ = 0.3 is not certain (plateau interval "
        "holds the threshold): the loss lies in (0, 0.5]")
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.2))
    assert vt.loss_note(_study(measured=m)) == (
        "lost at every sigma~ run (< 0.2): adhesion is already lost at the smallest sigma~, "
        "sigma~_c < 0.2")
    assert vt.loss_note(_study(measured=loss.Loss())) == (
        "no sigma~ whose state could be read: the loss is not measured")
    # seeds: auto ran fewer seeds at one end: its certainty is that of the carried plateau,
    # which no table shows (the 18 x 18 page's sigma~ = 3.2 looked certain in the plateau table)
    m = loss.Loss(kind=loss.BRACKET, bracket=(2.93, 3.2), span=(2.69, 6.4), sigma=3.09,
                  threshold=0.0248, uncertain=(2.93, 3.2), matched=(10, 6))
    assert vt.loss_note(_study(measured=m)).endswith(
        "; with their seeds the state of sigma~ = 2.93, 3.2 is not certain (plateau interval "
        "holds the threshold, the smaller group's as carried to the same brushes): the loss "
        "lies in (2.69, 6.4]")


def _group(out, state=RESOLVED, in_fit=False, c_lower=0.0123456):
    return NS(reading=NS(state=state, c_lower=c_lower), out=out, in_fit=in_fit)


def test_why_a_group_is_out_of_the_fit():
    words = {
        OutReason.NONE: "",
        OutReason.SMOOTH_LIMIT: "sigma~ = 0 (the smooth limit) has no place in a law in 1/sigma~",
        OutReason.NO_DATA: "no finite points",
        OutReason.UNRESOLVED: "rise not resolved: c >= 0.0123 is a lower bound",
        OutReason.UNDETERMINED: "state undetermined (too few levels, or no pillar floor to tell "
                                "a loss)",
        OutReason.NOT_REACHED: "plateau not reached: c is provisional",
        OutReason.NO_C: "c could not be read (the rise never reaches half the plateau)",
    }
    for o, w in words.items():
        assert vt.why_out(_group(o)) == w, o
    assert vt.why_out(_group("something new")) == "something new"
    lost = _group(OutReason.NONE, state=LOST, in_fit=True)
    assert vt.line_out(lost, _ab(lost="out")) == ("adhesion lost (c = 0): left out of the "
                                                  "alpha/beta line")
    assert vt.line_out(lost, _ab(lost="floor")) == ""
    assert vt.line_out(_group(OutReason.NONE, in_fit=True), _ab()) == ""
    assert vt.line_out(_group(OutReason.NO_C, state=LOST), _ab()) == words[OutReason.NO_C]


def test_how_the_intervals_were_made():
    assert vt.ci_method(_study(ci_kind=CIKind.ONE_SEED)) == "one seed: no seed interval"
    assert vt.ci_method(_study(ci_kind=CIKind.OFF, ab_from_cov=True)) == (
        "bootstrap off: no seed interval; alpha, beta: the fit's covariance (Student t)")
    assert vt.ci_method(_study()) == "bootstrap over 5 seeds (400 resamples)"
    assert vt.ci_method(_study(ci_kind=CIKind.PAIRED_MIXED, n_labels=10)) == (
        "bootstrap over seed labels paired across sigma~, each (k~, sigma~) taking the drawn "
        "labels it holds (3 to 10 seeds; 400 resamples)")
    assert vt.study_notes(_study()) == []
    assert vt.study_notes(_study(widened_poor=True, unbounded_share=0.125)) == [
        "alpha, beta intervals widened to the fit's Student-t interval (poor fit)",
        "beta <= 0 in 12 % of the resamples: alpha/beta unbounded above"]
    assert vt.study_notes(_study(unbounded_share=0.004)) == [
        "beta <= 0 in 0 % of the resamples: alpha/beta unbounded above"]


def test_the_reason_words():
    assert vt.LAW_REASON_WORDS == {
        LawReason.NO_LINE: "fewer than 2 sigma~ with c > 0",
        LawReason.TOO_FEW_ACTIVE: "fewer than 3 active points",
        LawReason.ALPHA_ZERO: "alpha consistent with 0",
        LawReason.CHI2: "poor fit", LawReason.NONE: ""}
    assert vt.NO_ZERO_WORDS == {
        ZeroReason.LAW_NOT_FITTED: "law not fitted",
        ZeroReason.BETA_ZERO: "beta consistent with 0: the line may never reach 0, no zero shown",
        ZeroReason.NONE: "the line does not reach 0"}
    assert vt.RELATION_WORDS == {
        Relation.WITHIN: "inside the measured span",
        Relation.ABOVE: "above the measured span (the line still gives c > 0 where adhesion is "
                        "lost)",
        Relation.BELOW: "below the measured span (the line reaches 0 where the brush still "
                        "holds)"}


def test_the_zero_cell_and_law_zero():
    st = _study()
    assert zc.law_zero(st) == (1.25, (1.1, 1.4), Relation.WITHIN, ZeroReason.NONE)
    assert zc.zero_cell(st) == "1.25 [1.1, 1.4], inside the measured span"
    st = _rel(Relation.NONE, RelationReason.UNBOUNDED)
    assert zc.law_zero(st)[2] == Relation.NONE and zc.zero_cell(st) == "1.25 [1.1, 1.4]"
    st = _rel(Relation.ABOVE)
    assert zc.zero_cell(st) == ("1.25 [1.1, 1.4], above the measured span (the line still "
                                "gives c > 0 where adhesion is lost)")
    for zr, words in ((ZeroReason.LAW_NOT_FITTED, "— (law not fitted)"),
                      (ZeroReason.BETA_ZERO,
                       "— (beta consistent with 0: the line may never reach 0, no zero shown)")):
        st = _study(verdict=Verdict(LawState.FITTED, LawReason.NONE, ZeroState.NONE, zr,
                                    Relation.ABOVE))
        z, ci, rel, why = zc.law_zero(st)
        assert math.isnan(z) and all(math.isnan(v) for v in ci) and rel == "" and why == zr
        assert zc.zero_cell(st) == words
    # extrapolated but not finite (a study that says so by its numbers): no zero
    st = _study(ab=_ab(sigma_c=NAN))
    assert zc.law_zero(st)[3] == ZeroReason.NONE and math.isnan(zc.law_zero(st)[0])
    assert zc.zero_cell(st) == "— (the line does not reach 0)"


def test_the_measured_cell_and_span():
    st = _study()
    assert lp.measured_span(st) == (0.8, INF)
    assert lp.measured_cell(st) == "1.04 [0.95, 1.15] in (0.8, ∞]"
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(NAN, 1.3), sigma=1.04321)
    assert lp.measured_span(_study(measured=m)) == (0.9, 1.2)
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.85, NAN), sigma=1.04321)
    assert lp.measured_cell(_study(measured=m)) == "1.04 in (0.9, 1.2]"
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.812345, 1.312345), sigma=1.0)
    assert lp.measured_cell(_study(measured=m)) == "1 in (0.8123, 1.312]"
    assert lp.span_text((0.812345, INF)) == "(0.8123, ∞]"
    m = loss.Loss(kind=loss.NO_LOSS, bracket=(2.1, INF))
    assert lp.measured_cell(_study(measured=m)) == "> 2.1 (no loss up to the largest σ̃ run)"
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.15))
    assert lp.measured_cell(_study(measured=m)) == "< 0.15 (lost at every σ̃ run)"
    assert lp.measured_cell(_study(measured=loss.Loss())) == "—"
    # a corner grid (sigma~ 0.01 and 2.1) read '0.574 [0.57, 0.579]': over a bracket wider than
    # x 4 the seed interval is the line's scatter, not the loss's; left out, and said why
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.01, 2.1), span=(0.01, 2.1), sigma=0.5742,
                  ci=(0.57, 0.579))
    assert lp.measured_cell(_study(measured=m)) == (
        "0.5742 in (0.01, 2.1] (the bracket is × 210 wide: the value is the log–log line's "
        "between its ends and has no seed interval worth quoting; σ̃ inside it would measure "
        "the loss)")
    for hi, shown in ((0.04, True), (0.0401, False)):     # x 4 exactly still shows it
        m = loss.Loss(kind=loss.BRACKET, bracket=(0.01, hi), span=(0.01, hi), sigma=0.02,
                      ci=(0.015, 0.03))
        assert ("[0.015, 0.03]" in lp.measured_cell(_study(measured=m))) == shown
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.0, 0.5), span=(0.0, 0.5), sigma=0.2,
                  ci=(0.1, 0.3))
    assert lp.measured_cell(_study(measured=m)) == "0.2 [0.1, 0.3] in (0, 0.5]"


def test_a_bound_says_the_span_its_seeds_leave():
    """No bracket, but the seeds leave the end groups' state uncertain: the bound alone ('> 0.6')
    claims more than they show; the span is given beside it (and only then)."""
    m = loss.Loss(kind=loss.NO_LOSS, bracket=(0.6, INF), span=(0.5, INF), uncertain=(0.6,))
    assert lp.measured_cell(_study(measured=m)) == (
        "> 0.6 (no loss up to the largest σ̃ run; with its seeds σ̃ = 0.6 is not certain: lost "
        "in (0.5, ∞])")
    m = loss.Loss(kind=loss.NO_LOSS, bracket=(0.6, INF), span=(0.0, INF),
                  uncertain=(0.3, 0.5, 0.6))
    assert lp.open_note(_study(measured=m)) == (
        "; with its seeds σ̃ = 0.3, 0.5, 0.6 are not certain: lost in (0, ∞]")
    m = loss.Loss(kind=loss.NO_LOSS, bracket=(0.6, INF), span=(0.6, INF), uncertain=(0.3,))
    assert lp.open_note(_study(measured=m)) == ""          # the top group is certain
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.15), span=(0.0, 0.3), uncertain=(0.15, 0.3))
    assert lp.measured_cell(_study(measured=m)) == (
        "< 0.15 (lost at every σ̃ run; with its seeds σ̃ = 0.15 is not certain: lost in (0, 0.3])")
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.15), span=(0.0, 0.15), uncertain=(0.3,))
    assert lp.open_note(_study(measured=m)) == ""
    m = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.15), span=(0.0, 0.3))
    assert lp.open_note(_study(measured=m)) == (
        "; with its seeds the end groups are not certain: lost in (0, 0.3]")
    m = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.5, 2.0), sigma=1.0,
                  uncertain=(0.9, 1.2))
    assert lp.open_note(_study(measured=m)) == ""          # a bracket gives its span itself


@pytest.mark.parametrize("text, want", [
    ("sigma_tilde: {auto: {start: [0.1, 0.3], max: 2.5}}\n", 2.5),
    ("sigma_tilde: [0.1, 0.3]\n", NAN),
    ("sigma_tilde: {auto: {max: -1}}\n", NAN),        # not valid: the planner refuses it
    ("sigma_tilde: [0.1\n", NAN),                      # not YAML
    ("- 1\n- 2\n", NAN),                               # not a mapping
    ("", NAN),
])
def test_the_search_limit_is_read_by_the_planner(text, want):
    got = lp.search_max({"campaign_yaml": text})
    assert got == want or (math.isnan(want) and math.isnan(got))


def test_the_search_limit_without_a_grid_text():
    for meta in (None, {}, {"campaign_yaml": None}):
        assert math.isnan(lp.search_max(meta))

"""The page's first lines and notes (analysis/headline.py), pinned so that their one-line
mutations fail (issue 34, item 6; benchmarks/mutation.py): what the measured sigma~_c is of,
one value per k~ for each kind of loss, the law's line with where its zero lies, the cautions,
the four-line limit, and each note, word for word, from stand-ins with the fields the page reads
(a ReportData's and a KStudy's), so that every state is said whether or not a campaign reaches
it."""

import math
from dataclasses import replace
from types import SimpleNamespace as NS

from fibril_hpc.campaign.analysis import headline as hl
from fibril_hpc.campaign.laws import loss
from fibril_hpc.campaign.laws.alphabeta import ABFit
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNRESOLVED
from fibril_hpc.campaign.laws.size import DIFFERS, UNKNOWN, WITHIN
from fibril_hpc.campaign.laws.study import OutReason
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


def _group(sigma, state=RESOLVED, n_seeds=3, out=OutReason.NONE, plateau=1.0, p_ci=(0.9, 1.1),
           c=2.0, c_ci=(1.9, 2.1)):
    return NS(sigma_tilde=sigma, n_seeds=n_seeds, out=out, plateau_ci=p_ci, c_ci=c_ci,
              reading=NS(state=state, plateau=plateau, c=c, c_lower=0.5))


def _study(law=LawState.FITTED, rel=Relation.WITHIN, measured=None, groups=None, ok=True,
           chi2=1.23456, reason=LawReason.NONE):
    measured = measured or loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.8, 1.3),
                                     sigma=1.04321, ci=(0.95, 1.15))
    zero = ZeroState.EXTRAPOLATED if law == LawState.FITTED else ZeroState.NONE
    zr = ZeroReason.NONE if law == LawState.FITTED else ZeroReason.LAW_NOT_FITTED
    v = Verdict(law, reason, zero, zr, rel, RelationReason.NONE, measured.span, (1.1, 1.4))
    ab = ABFit(1.0 if ok else NAN, 0.8, 1.25, 0.1, 0.1, 5, 1, (), (), chi2, False, True,
               (0.9, 1.2), [], 4, 2)
    st = NS(ab=ab, verdict=v, loss=measured, sigma_c_ci=(1.1, 1.4), alpha_ci=(0.8, 1.2),
            beta_ci=(0.6, 1.0), groups=groups if groups is not None else [_group(0.5)],
            status=str(law))
    st.loss_kind, st.loss_bracket, st.sigma_loss = measured.kind, measured.bracket, measured.sigma
    st.sigma_loss_ci = measured.ci
    return st


def _data(studies, **kw):
    d = dict(studies=studies, n_jobs=40, n_failed=0, n_nonfinite=0, meta={},
             brush=(18, 0.16, ""), preset="fast", seeds_auto=None, n_sides=[], n_side=None,
             variant=None, seed_limits=[], size_loss={}, floor_note="", bias=NAN,
             bias_note="not measured", size=[], coarse=[], elsewhere={}, floor=0.01)
    d.update(kw)
    return NS(**d)


def test_what_the_measured_sigma_c_is_of():
    d = _data({1.0: _study(groups=[_group(0.5, n_seeds=3), _group(0.7, n_seeds=10)]),
               0.1: _study(groups=[_group(0.5, n_seeds=5), _group(0.7, n_seeds=3)])})
    assert hl.of_what(d) == "324 pillars (18 × 18), φ = 0.16, preset fast, 3–10 seeds per (k̃, σ̃)"
    d = _data({1.0: _study(groups=[_group(0.5, n_seeds=1)])}, brush=(None, NAN, ""), preset="",
              seeds_auto={"start": 3}, n_sides=[8, 12], n_side=12,
              variant=NS(label="E = 2"))
    assert hl.of_what(d) == ("preset unknown, 1 seed per (k̃, σ̃) (seeds: auto), n_side = 12 of "
                             "8, 12, E = 2")
    d = _data({1.0: _study(groups=[_group(0.5, n_seeds=2), _group(0.6, n_seeds=2)])})
    assert hl.of_what(d).endswith(", 2 seeds per (k̃, σ̃)")
    assert hl.of_what(_data({1.0: _study(groups=[])})).endswith(", no seeds")


def test_the_headline_of_a_search():
    no_loss = loss.Loss(kind=loss.NO_LOSS, bracket=(2.5, INF), span=(2.5, INF))
    all_lost = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.05), span=(0.0, 0.05))
    studies = {1.0: _study(rel=Relation.ABOVE), 0.1: _study(LawState.POOR, Relation.NONE,
                                                             no_loss),
               0.01: _study(LawState.UNDEFINED, Relation.NONE, all_lost),
               0.001: _study(LawState.FITTED, Relation.BELOW, loss.Loss())}
    meta = {"campaign_yaml": "sigma_tilde: {auto: {start: [0.1, 0.3], max: 2.5}}\n"}
    lines = hl.headline(_data(studies, meta=meta))
    assert lines == [
        "Where this brush loses adhesion, σ̃_c per k̃ (model-free: the σ̃ where the seed-mean "
        "plateau falls to 3 pillars' pull-off; lost in: the σ̃ run around it, widened to any σ̃ "
        "beside it whose state its seeds leave uncertain, and where none is certain to where "
        "another seed set as large would measure it), of 324 pillars (18 × 18), φ = 0.16, "
        "preset fast, 3 seeds per (k̃, σ̃):",
        "k̃ = 1: 1.04, lost in (0.8, 1.3]; k̃ = 0.1: > 2.5 (no loss up to the largest σ̃ run, the "
        "search's limit); k̃ = 0.01: < 0.05 (lost at every σ̃ run); k̃ = 0.001: not measured.",
        "c = α/σ̃ − β (4 k̃): fitted within the seed scatter for k̃ = 1, 0.001; a **poor fit** "
        "(for orientation only) for k̃ = 0.1 (χ²/dof 1.23); undefined for k̃ = 0.01. Its zero "
        "α/β is an extrapolation of that line, given beside the measurement in the α/β table "
        "(above the measured span for k̃ = 1; below the measured span for k̃ = 0.001)."]
    # below the search's limit, or a fixed grid: the limit is not claimed
    short = loss.Loss(kind=loss.NO_LOSS, bracket=(2.0, INF), span=(2.0, INF))
    line = hl.headline(_data({0.1: _study(measured=short)}, meta=meta))[1]
    assert line == "k̃ = 0.1: > 2 (no loss up to the largest σ̃ run)."
    line = hl.headline(_data({0.1: _study(measured=no_loss)}))[1]
    assert line == "k̃ = 0.1: > 2.5 (no loss up to the largest σ̃ run)."
    # seeds that leave the top group's state uncertain: the headline gives the span they leave
    loose = loss.Loss(kind=loss.NO_LOSS, bracket=(2.5, INF), span=(2.0, INF), uncertain=(2.5,))
    line = hl.headline(_data({0.1: _study(measured=loose)}, meta=meta))[1]
    assert line == ("k̃ = 0.1: > 2.5 (no loss up to the largest σ̃ run, the search's limit; with "
                    "its seeds σ̃ = 2.5 is not certain: lost in (2, ∞]).")
    loose = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.05), span=(0.0, 0.1), uncertain=(0.05,))
    line = hl.headline(_data({0.1: _study(measured=loose)}))[1]
    assert line == ("k̃ = 0.1: < 0.05 (lost at every σ̃ run; with its seeds σ̃ = 0.05 is not "
                    "certain: lost in (0, 0.1]).")


def test_the_law_line_of_one_state():
    d = _data({1.0: _study(), 0.5: _study()})
    assert hl.headline(d)[2] == (
        "c = α/σ̃ − β (2 k̃): fitted within the seed scatter for k̃ = 1, 0.5. Its zero α/β is an "
        "extrapolation of that line, given beside the measurement in the α/β table.")
    d = _data({1.0: _study(LawState.POOR, Relation.NONE, chi2=3.0),
               0.5: _study(LawState.POOR, Relation.NONE, chi2=4.5)})
    # a poor fit shows no zero (the α/β table gives it only for a fitted law): none promised
    assert hl.headline(d)[2] == (
        "c = α/σ̃ − β (2 k̃): a **poor fit** (for orientation only) for k̃ = 1 (χ²/dof 3), 0.5 "
        "(χ²/dof 4.5). No line shows a zero (the α/β table says why).")
    d = _data({1.0: _study(LawState.UNDEFINED, Relation.ABOVE)})
    # no line fitted: no zero is spoken of (the α/β table gives none)
    assert hl.headline(d)[2] == "c = α/σ̃ − β (1 k̃): undefined for k̃ = 1."
    d = _data({1.0: _study(LawState.UNDEFINED, Relation.ABOVE),
               0.5: _study(LawState.POOR, Relation.NONE, chi2=3.0)})
    assert hl.headline(d)[2].endswith(". No line shows a zero (the α/β table says why).")
    # fitted, but beta consistent with 0 (the r18 and 8-20 pages): the page gives no zero
    flat = _study()
    flat.verdict = replace(flat.verdict, zero=ZeroState.NONE, zero_reason=ZeroReason.BETA_ZERO)
    d = _data({1.0: flat, 0.5: _study(LawState.UNDEFINED, Relation.NONE)})
    assert hl.headline(d)[2] == ("c = α/σ̃ − β (2 k̃): fitted within the seed scatter for k̃ = 1; "
                                 "undefined for k̃ = 0.5. No line shows a zero (the α/β table "
                                 "says why).")
    # one k~ shows a zero: the sentence stands
    d = _data({1.0: flat, 0.5: _study()})
    assert hl.headline(d)[2].endswith("Its zero α/β is an extrapolation of that line, given "
                                      "beside the measurement in the α/β table.")


def test_the_cautions_and_the_four_line_limit(monkeypatch):
    unsure = loss.Loss(kind=loss.BRACKET, bracket=(0.9, 1.2), span=(0.8, INF), sigma=1.0,
                       uncertain=(1.2,))
    un_all = loss.Loss(kind=loss.ALL_LOST, bracket=(0.0, 0.2), span=(0.0, 0.5), uncertain=(0.2,))
    studies = {1.0: _study(measured=unsure), 0.5: _study(measured=un_all),
               0.1: _study(LawState.UNDEFINED, Relation.NONE, ok=False),
               0.01: _study(LawState.UNDEFINED, Relation.NONE, ok=False)}
    d = _data(studies, n_failed=2, n_nonfinite=1, seed_limits=[1, 2])
    lines = hl.headline(d)
    assert len(lines) == 4
    assert lines[3] == (
        "Before quoting: 3 of 40 jobs failed or gave non-finite forces (left out); for k̃ = 1 a "
        "group beside the loss is not certainly lost or holding with its seeds (its interval is "
        "widened to hold it); 2 (k̃, σ̃) stopped at the maximum of seeds: auto short of its "
        "precision target (plateau table); α and β need a wider grid (notes).")
    # one undefined k~ that has a line: no call for a wider grid
    studies[0.01] = _study(LawState.UNDEFINED, Relation.NONE, ok=True)
    assert "wider grid" not in hl.headline(_data(studies))[3]
    assert hl.headline(_data(studies, n_nonfinite=1))[3] == (
        "Before quoting: 1 of 40 jobs failed or gave non-finite forces (left out); for k̃ = 1 a "
        "group beside the loss is not certainly lost or holding with its seeds (its interval is "
        "widened to hold it).")
    # a fifth line (the loss across sizes) joins the last two into the fourth
    monkeypatch.setattr(hl, "size_loss_line", lambda s: f"SIZES {sorted(s)}.")
    lines = hl.headline(_data(studies, n_failed=1, size_loss={1.0: "x"}))
    plain = hl.headline(_data(studies, n_failed=1))
    assert len(lines) == 4 and lines[:2] == plain[:2] and lines[2] == "SIZES [1.0]."
    # a data object without the field: no line
    bare = _data(studies, n_failed=1)
    del bare.size_loss
    assert hl.headline(bare) == plain
    assert lines[3] == plain[2] + " " + plain[3]
    assert hl.MAX_LINES == 4


def test_a_campaign_without_results():
    d = _data({}, n_jobs=12, n_failed=5)
    assert hl.headline(d) == [
        "No done job with finite forces (12 job records, 5 failed): nothing to read. "
        + hl.GRID_ADVICE + "."]
    assert hl.notes(d) == []
    assert hl.GRID_ADVICE.startswith("α and β need, per k̃, at least two σ̃ > 0 whose F̃_A rises")
    assert hl.GRID_ADVICE.endswith("(campaigns/demo.yaml is such a grid)")


def test_the_notes():
    groups = [_group(0.3, UNRESOLVED, out=OutReason.UNRESOLVED, plateau=2.0, p_ci=(1.0, 3.0)),
              _group(0.5, plateau=1.0, p_ci=(0.999, 1.001), c=2.0, c_ci=(1.0, 3.0)),
              _group(0.9, LOST, out=OutReason.NONE), _group(1.2, LOST, p_ci=(NAN, NAN))]
    und = [_group(0.4, out=OutReason.NOT_REACHED), _group(0.6, out=OutReason.NOT_REACHED),
           _group(0.8, UNRESOLVED, out=OutReason.UNRESOLVED)]
    studies = {1.0: _study(groups=groups),
               0.1: _study(LawState.UNDEFINED, Relation.NONE, groups=und, ok=False,
                           reason=LawReason.TOO_FEW_ACTIVE)}
    d = _data(studies, floor_note="one pillar, 0.00828", bias=0.0312,
              bias_note="measured on 18 x 18", seeds_auto={"start": 3, "max": 10, "width": 0.2},
              seed_limits=[NS(k_tilde=1.0, sigma_tilde=0.9)])
    out = hl.notes(d)
    assert out[0] == ("States of the 7 (k̃, σ̃): 2 adhesion lost, 2 rise not resolved, 3 rise "
                      "resolved (pillar floor: one pillar, 0.00828).")
    assert out[1] == ("2 (k̃, σ̃) have a rise not resolved: F̃_A is already near the plateau at "
                      "the smallest preload reached, c is only a lower bound and stays out of "
                      "the fit (the coefficients table says which preload would resolve it).")
    assert out[2] == ("2 (k̃, σ̃) have lost adhesion (a plateau within 3 pillars' pull-off): c = "
                      "0 by that threshold, left out of the α/β line, whose zero is set beside "
                      "the measured loss.")
    assert out[3] == (
        "α and β undefined: k̃ = 0.1: 4 active points and 2 dof: at least 3 and 1 make a fit of "
        "the law. Left out of the fit: plateau not reached: (0.1, 0.4), (0.1, 0.6); rise not "
        "resolved: (0.1, 0.8). " + hl.GRID_ADVICE + ".")
    # which error is larger, per (k~, sigma~): one plateau interval narrower than the 3.12 %
    # bias, one without an interval
    assert out[4] == ("Larger error: plateau: the seeds in 5, the discretisation in 1 of 7 "
                      "(k̃, σ̃); c: the seeds in 7, the discretisation in 0 of 7 (k̃, σ̃).")
    assert out[5] == hl.seeds_line(d.seeds_auto, d.seed_limits)
    assert out[6] == ("Discretisation bias: measured on 18 x 18 (+3.1 % on every force-like "
                      "number; measured on one scene, carried over as an assumption).")
    assert len(out) == 7
    # no bias: said so, no error comparison; nothing undefined, nothing lost
    d = _data({1.0: _study(groups=[_group(0.5)])})
    assert hl.notes(d) == ["States of the 1 (k̃, σ̃): 1 rise resolved.",
                           "Discretisation bias: not measured."]
    # undefined with a line: no grid advice, no "left out" without groups out
    d = _data({0.1: _study(LawState.UNDEFINED, Relation.NONE, groups=[_group(0.5)],
                           reason=LawReason.CHI2)})
    assert hl.notes(d)[1] == (
        "α and β undefined: k̃ = 0.1: chi^2/dof = 1.23: c = alpha/sigma~ - beta does not "
        "describe c within the seed scatter; alpha and beta for orientation only.")


def test_the_seeds_line():
    auto = {"start": 3, "max": 10, "width": 0.2}
    assert hl.seeds_line(None, []) == "" and hl.seeds_line({}, [1]) == ""
    assert "target: intervals 60 % wide" in hl.seeds_line({"start": 3, "max": 10, "width": 0.6},
                                                          [])
    assert hl.seeds_line(auto, []) == (
        "seeds: auto (from 3, at most 10 per (k̃, σ̃), target: intervals 20 % wide): no (k̃, σ̃) "
        "stopped at the maximum short of the target.")
    lim = [NS(k_tilde=1.0, sigma_tilde=0.9), NS(k_tilde=0.01, sigma_tilde=1.25)]
    assert hl.seeds_line(auto, lim) == (
        "seeds: auto (from 3, at most 10 per (k̃, σ̃), target: intervals 20 % wide): 2 (k̃, σ̃) "
        "stopped at the maximum short of the target, their intervals as narrow as the campaign "
        "could make them, not as asked (k̃ = 1, σ̃ = 0.9; k̃ = 0.01, σ̃ = 1.25; the plateau "
        "table says what is short).")


def _row(n, rel, verdict):
    return NS(n_side=n, rel=rel, verdict=verdict)


def test_the_size_line_and_its_note():
    rows = [_row(8, 0.1234, WITHIN), _row(8, -0.05, DIFFERS), _row(8, 0.02, UNKNOWN),
            _row(12, NAN, UNKNOWN), _row(16, 0.0, WITHIN), _row(18, 0.0, WITHIN)]
    d = _data({}, n_sides=[8, 10, 12, 16, 18], n_side=16, size=rows)     # no row at 10
    assert hl.size_line(d) == (
        "Finite size: n_side = 8, 10, 12, 16, 18; the other tables and figures read n_side = 16 (the "
        "largest with done jobs). Plateau against n_side = 18: n_side = 8: -5.00 … +12.3 % "
        "(within the seed scatter in 1 of 2 (k̃, σ̃)); n_side = 12: no relative change (no "
        "plateau at 18); n_side = 16: +0.00 … +0.00 % (within the seed scatter in 1 of 1 (k̃, "
        "σ̃)).")
    d = _data({}, n_sides=[8, 18], n_side=18, size=[_row(8, 0.02, UNKNOWN)])
    assert hl.size_line(d) == (
        "Finite size: n_side = 8, 18; the other tables and figures read n_side = 18. Plateau "
        "against n_side = 18: n_side = 8: +2.00 … +2.00 %.")
    d = _data({}, n_sides=[8, 18], n_side=None, size=[])
    assert hl.size_line(d) == (
        "Finite size: n_side = 8, 18; the other tables and figures read n_side = —. Plateau "
        "against n_side = 18: no smaller n_side with a plateau yet.")
    d = _data({1.0: _study()}, n_sides=[8, 18], n_side=18, size=[_row(8, 0.02, UNKNOWN)])
    assert hl.notes(d)[-2] == hl.size_line(d)


def test_the_notes_of_two_undefined_laws():
    st = {k: _study(LawState.UNDEFINED, Relation.NONE, groups=[_group(0.5)],
                    reason=LawReason.CHI2, chi2=c) for k, c in ((0.1, 2.0), (0.01, 3.0))}
    assert hl.notes(_data(st))[1] == (
        "α and β undefined: k̃ = 0.1: chi^2/dof = 2: c = alpha/sigma~ - beta does not describe c "
        "within the seed scatter; alpha and beta for orientation only; k̃ = 0.01: chi^2/dof = 3: "
        "c = alpha/sigma~ - beta does not describe c within the seed scatter; alpha and beta for "
        "orientation only.")


def test_a_k_that_did_not_run_the_size_read_is_named_with_its_own_largest():
    """A merged file (k~ = 1 and 0.001 at 8-16, k~ = 0.01 also at 20) read every per-(k~,
    sigma~) table at n_side = 20 and showed k~ = 0.01 alone, without a word of the other two."""
    d = _data({0.01: _study()}, n_sides=[8, 12, 16, 20], n_side=20,
              elsewhere={0.001: 16, 1.0: 12})
    lines = hl.headline(d)
    assert lines[-1] == (
        "Before quoting: k̃ = 1, 0.001 ran no job at n_side = 20 (largest: 12, 16): the σ̃_c "
        "line, the per-(k̃, σ̃) tables and the figures leave them out; the across-sizes tables "
        "read them at their sizes.")
    assert not any("ran no job" in line for line in hl.headline(_data({0.01: _study()})))


def test_a_size_sweep_without_a_pillar_floor_says_why_no_loss_across_sizes_is_read():
    rows = [_row(12, 0.1, WITHIN), _row(18, 0.0, WITHIN)]
    say = "Where adhesion is lost across sizes is not read (no pillar floor: the tips"
    d = _data({}, n_sides=[12, 18], n_side=18, size=rows, floor=NAN,
              floor_note="no pillar floor: the tips are not flat punches")
    assert say in hl.size_line(d)
    for kw in ({"floor": 0.01}, {"size_loss": {1.0: object()}}, {"n_sides": [18]}):
        assert say not in hl.size_line(_data({}, **{**dict(
            n_sides=[12, 18], n_side=18, size=rows, floor=NAN,
            floor_note="no pillar floor: the tips are not flat punches"), **kw}))

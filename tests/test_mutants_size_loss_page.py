"""The page's tables and line for the loss across brush sizes (analysis/size_loss_page.py),
pinned so that their one-line mutations fail (issue 34, item 6; benchmarks/mutation.py): every
CSV column of both tables (docs/report.md defines them) and every page cell, for each kind of
crossing, from a :class:`..laws.size_loss.SizeLoss` of chosen numbers."""

import math
from types import SimpleNamespace as NS

from fibril_hpc.campaign.analysis import size_loss_page as slp
from fibril_hpc.campaign.laws import size_loss as sl

INF, NAN = math.inf, math.nan
PHI = 0.16


def _loss(k=1.0, thr=0.1):
    s = sl.SizeLoss(k, PHI, (8, 12), (0.2, 0.4), {}, {}, {}, {8: 4, 12: 3}, area_threshold=thr)
    s.few = [sl.Crossing(8, 0.0521, sl.BRACKET, 0.61234, (0.55, 0.7), (0.5, 0.7), 4),
             sl.Crossing(12, 0.0284, sl.NO_LOSS, NAN, (NAN, NAN), (0.9, INF), 3)]
    s.area = [sl.Crossing(8, thr, sl.ALL_LOST, NAN, (NAN, NAN), (0.0, 0.2), 4, True),
              sl.Crossing(12, thr, sl.BRACKET, 0.45678, (0.4, 0.5), (0.4, 0.5), 3)]
    s.area_trend = sl.STEADY
    s.extrapolations = [
        sl.Extrapolation(0.2, (8, 12, 16), 0.45612, (0.41, 0.5), 2.5, 0.123, 1, sl.HOLDS),
        sl.Extrapolation(0.4, (8, 12, 16), -0.0123, (-0.05, 0.02), 3.1, NAN, 1, sl.GONE)]
    s.p, s.p_ci, s.p_state = 0.8123, (0.6, 1.1), sl.CONSISTENT
    s.sigma_inf_kind, s.sigma_inf, s.sigma_inf_ci = sl.BRACKET, 0.4567, (0.44, 0.47)
    s.sigma_inf_bracket = (0.4, 0.5)
    s.sigma_zero_kind, s.sigma_zero, s.sigma_zero_ci = sl.NO_LOSS, NAN, (NAN, NAN)
    s.sigma_zero_bracket = (1.0, INF)
    return s


HEAD = ["k_tilde", "n_side", "n_pillars", "n_seeds", "k_pillar", "few_threshold", "sigma_few",
        "sigma_few_lo", "sigma_few_hi", "few_kind", "pillar_sigma_few", "area_threshold",
        "sigma_area", "sigma_area_lo", "sigma_area_hi", "area_kind", "area_below_floor",
        "pillar_sigma_area", "area_trend", "sigma_zero", "sigma_zero_lo", "sigma_zero_hi",
        "zero_kind", "p", "p_lo", "p_hi", "p_state", "few_drift", "few_drift_lo",
        "few_drift_hi", "few_drift_state", "area_drift", "area_drift_lo", "area_drift_hi",
        "area_drift_state", "spring_few", "spring_area", "reach_few", "reach_area"]


def test_the_size_loss_table():
    s = _loss()
    t = slp.table(NS(size_loss={1.0: s}))
    assert t.name == "size_loss"
    assert t.title == ("Where adhesion is lost, per brush size and for a large brush (per-area "
                       "threshold F̃_A = 0.1)")
    assert t.csv_rows[0] == HEAD and len(t.csv_rows) == 4
    r8, r12, rinf = (dict(zip(HEAD, r)) for r in t.csv_rows[1:])
    assert all(len(r) == len(HEAD) for r in t.csv_rows)
    assert r8 == {
        "k_tilde": "1.0", "n_side": "8", "n_pillars": "64", "n_seeds": "4",
        "k_pillar": repr(sl.pillar_k(1.0, 8, PHI)), "few_threshold": "0.0521",
        "sigma_few": "0.61234", "sigma_few_lo": "0.55", "sigma_few_hi": "0.7",
        "few_kind": sl.BRACKET, "pillar_sigma_few": repr(sl.pillar_sigma(0.61234, 8, PHI)),
        "area_threshold": "0.1", "sigma_area": "", "sigma_area_lo": "", "sigma_area_hi": "",
        "area_kind": sl.ALL_LOST, "area_below_floor": "true", "pillar_sigma_area": "",
        "area_trend": "", "sigma_zero": "", "sigma_zero_lo": "", "sigma_zero_hi": "",
        "zero_kind": "", "p": "", "p_lo": "", "p_hi": "", "p_state": "", "few_drift": "",
        "few_drift_lo": "", "few_drift_hi": "", "few_drift_state": "", "area_drift": "",
        "area_drift_lo": "", "area_drift_hi": "", "area_drift_state": "",
        "spring_few": repr(sl.pillar_spring(0.61234, 1.0, 8, PHI)), "spring_area": "",
        "reach_few": repr(sl.pillar_reach(0.61234, 1.0, 8, PHI)), "reach_area": ""}
    assert r12["n_pillars"] == "144" and r12["n_seeds"] == "3" and r12["few_kind"] == sl.NO_LOSS
    assert r12["area_below_floor"] == "false" and r12["sigma_area"] == "0.45678"
    assert r12["pillar_sigma_area"] == repr(sl.pillar_sigma(0.45678, 12, PHI))
    assert r12["k_pillar"] == repr(sl.pillar_k(1.0, 12, PHI))
    assert rinf == {
        "k_tilde": "1.0", "n_side": "inf", "n_pillars": "inf", "n_seeds": "3", "k_pillar": "inf",
        "few_threshold": "", "sigma_few": "", "sigma_few_lo": "", "sigma_few_hi": "",
        "few_kind": "", "pillar_sigma_few": "", "area_threshold": "0.1", "sigma_area": "0.4567",
        "sigma_area_lo": "0.44", "sigma_area_hi": "0.47", "area_kind": sl.BRACKET,
        "area_below_floor": "", "pillar_sigma_area": "inf", "area_trend": sl.STEADY,
        "sigma_zero": "", "sigma_zero_lo": "", "sigma_zero_hi": "", "zero_kind": sl.NO_LOSS,
        "p": "0.8123", "p_lo": "0.6", "p_hi": "1.1", "p_state": sl.CONSISTENT,
        "few_drift": "", "few_drift_lo": "", "few_drift_hi": "", "few_drift_state": sl.NOT_MEASURED,
        "area_drift": "", "area_drift_lo": "", "area_drift_hi": "", "area_drift_state": sl.NOT_MEASURED,
        "spring_few": "inf", "spring_area": "inf", "reach_few": "", "reach_area": ""}
    assert t.page_rows[0] == ["k̃", "n_side", "k/(E* D)", "σ̃ at 3 pillars [CI]", "σ/d_c1 there",
                              "σ̃ at F̃_A = 0.1 [CI]", "σ/d_c1 there", "k σ/F_c1 there",
                              "σ/(d_c1 + F_c1/k) there", "note"]
    assert t.page_rows[1] == [
        "1", "8", format(sl.pillar_k(1.0, 8, PHI), ".3g"), "0.612 [0.55, 0.7]",
        format(sl.pillar_sigma(0.61234, 8, PHI), ".3g"), "< 0.2 (below every σ̃ run)", "—",
        "—", "—", "the per-area threshold is within 3 pillars' pull-off here"]
    assert t.page_rows[2] == [
        "1", "12", format(sl.pillar_k(1.0, 12, PHI), ".3g"), "> 0.9 (not reached)", "—",
        "0.457 [0.4, 0.5]", format(sl.pillar_sigma(0.45678, 12, PHI), ".3g"),
        format(sl.pillar_spring(0.45678, 1.0, 12, PHI), ".3g"),
        format(sl.pillar_reach(0.45678, 1.0, 12, PHI), ".3g"), ""]
    assert t.page_rows[3] == [
        "1", "∞ (P∞)", "∞", "—", "∞", "0.457 [0.44, 0.47]", "∞", "∞", "—",
        "σ̃ where P∞ = 0: > 1 (not reached); per-area crossing over the two largest sizes: "
        "steady; p = 0.812 [0.6, 1.1] (consistent with 3/4); d ln σ̃ / d ln N at 3 pillars —, "
        "at F̃_A = 0.1 —"]
    # a crossing not read is a dash; no size: the default threshold in the title
    s.few[0].kind = sl.NOT_READ
    assert slp.table(NS(size_loss={1.0: s})).page_rows[1][3] == "—"
    empty = slp.table(NS(size_loss={}))
    assert empty.title.endswith(f"(per-area threshold F̃_A = {sl.AREA_THRESHOLD:g})")
    assert empty.csv_rows == [HEAD] and len(empty.page_rows) == 1
    # the threshold of the study, not the default; the n_seeds of a k~ without sizes
    t = slp.table(NS(size_loss={0.01: _loss(0.01, thr=0.25)}))
    assert "F̃_A = 0.25)" in t.title and t.csv_rows[1][0] == "0.01"
    bare = _loss()
    bare.n_seeds = {}
    assert slp.table(NS(size_loss={1.0: bare})).csv_rows[1][3] == "0"
    assert slp.table(NS(size_loss={1.0: bare})).csv_rows[-1][3] == "0"


def test_the_extrapolation_table():
    t = slp.extrapolation_table(NS(size_loss={1.0: _loss()}))
    assert t.name == "size_extrapolation"
    assert t.title == ("The plateau extrapolated in the number of pillars N: P(N) = P∞ + A "
                       "N^(−3/4)")
    assert t.csv_rows == [
        ["k_tilde", "sigma_tilde", "n_sides", "P_inf", "P_inf_lo", "P_inf_hi", "A", "chi2", "dof",
         "state"],
        ["1.0", "0.2", "8 12 16", "0.45612", "0.41", "0.5", "2.5", "0.123", "1", sl.HOLDS],
        ["1.0", "0.4", "8 12 16", "-0.0123", "-0.05", "0.02", "3.1", "", "1", sl.GONE]]
    assert t.page_rows == [
        ["k̃", "σ̃", "sizes", "P∞ [CI]", "A", "χ² (dof)", "P∞"],
        ["1", "0.2", "8, 12, 16", "0.456 [0.41, 0.5]", "2.5", "0.12 (1)", "holds"],
        ["1", "0.4", "8, 12, 16", "-0.0123 [-0.05, 0.02]", "3.1", "— (1)", "**gone**"]]


def test_the_headline_line():
    a, b = _loss(), _loss(0.01, thr=0.1)
    b.sigma_inf_kind, b.sigma_inf_bracket = sl.ALL_LOST, (0.0, 0.2)
    assert slp.headline_line({1.0: a, 0.01: b}) == (
        "Loss across sizes (sizes 8, 12): k̃ = 1: per area (F̃_A = 0.1 in the N → ∞ "
        "extrapolation) σ̃ = 0.457 [0.44, 0.47]; at 3 pillars, by n_side, 8: 0.612 [0.55, "
        "0.7], 12: > 0.9 (not reached); k̃ = 0.01: per area (F̃_A = 0.1 in the N → ∞ "
        "extrapolation) σ̃ = < 0.2 (below every σ̃ run); at 3 pillars, by n_side, 8: 0.612 "
        "[0.55, 0.7], 12: > 0.9 (not reached).")


def test_small_numbers_and_the_other_kinds_of_the_large_brush_row():
    """Three significant digits in lower-case exponent notation where numbers are small, and
    the large-brush row's sigma~_0 (a bracket) and sigma~_inf (not reached)."""
    s = _loss(k=1e-6)
    s.few[0].sigma, s.few[0].ci = 2.3456e-6, (1.1e-6, 3.3e-6)
    s.few[1].bracket = (0.91234, INF)
    s.area[0].bracket = (0.0, 1.23456e-5)
    s.area[1].sigma, s.area[1].ci = 5.4321e-6, (4e-6, 6e-6)
    s.extrapolations[0] = sl.Extrapolation(0.2, (8, 12, 16), 4.5678e-6, (1e-6, 8e-6), 2.5678e-5,
                                           1.2345e-7, 1, sl.HOLDS)
    s.p, s.p_ci = 1.2345e-5, (1e-5, 2e-5)
    s.sigma_inf_kind, s.sigma_inf, s.sigma_inf_ci = sl.NO_LOSS, NAN, (NAN, NAN)
    s.sigma_inf_bracket = (1.23456e-5, INF)
    s.sigma_zero_kind, s.sigma_zero, s.sigma_zero_ci = sl.BRACKET, 0.61234, (0.55, 0.7)
    t = slp.table(NS(size_loss={1e-6: s}))
    kp8 = sl.pillar_k(1e-6, 8, PHI)
    assert t.page_rows[1][:5] == ["1e-06", "8", format(kp8, ".3g"), "2.35e-06 [1.1e-06, 3.3e-06]",
                                  format(sl.pillar_sigma(2.3456e-6, 8, PHI), ".3g")]
    assert "e-05" in t.page_rows[1][2] and "e-06" in t.page_rows[1][4]
    assert t.page_rows[1][5] == "< 1.23e-05 (below every σ̃ run)"
    assert t.page_rows[2][3] == "> 0.912 (not reached)"
    assert t.page_rows[2][6] == format(sl.pillar_sigma(5.4321e-6, 12, PHI), ".3g")
    assert "e-05" in t.page_rows[2][6]
    assert t.page_rows[3][5] == "> 1.23e-05 (not reached)"
    assert t.page_rows[3][-1] == (
        "σ̃ where P∞ = 0: 0.612 [0.55, 0.7]; per-area crossing over the two largest sizes: "
        "steady; p = 1.23e-05 [1e-05, 2e-05] (consistent with 3/4); d ln σ̃ / d ln N at 3 "
        "pillars —, at F̃_A = 0.1 —")
    rinf = dict(zip(HEAD, t.csv_rows[-1]))
    assert (rinf["sigma_zero"], rinf["sigma_zero_lo"], rinf["sigma_zero_hi"]) == ("0.61234",
                                                                                  "0.55", "0.7")
    assert rinf["zero_kind"] == sl.BRACKET and rinf["sigma_area"] == ""
    assert rinf["area_kind"] == sl.NO_LOSS
    e = slp.extrapolation_table(NS(size_loss={1e-6: s})).page_rows[1]
    assert e == ["1e-06", "0.2", "8, 12, 16", "4.57e-06 [1e-06, 8e-06]", "2.57e-05",
                 "1.2e-07 (1)", "holds"]

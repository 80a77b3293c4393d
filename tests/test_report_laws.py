"""The report's science on known inputs: the plateau read where F~_A stops rising, c and c0 by
their definitions, alpha/beta with c = 0 groups, seed intervals and the preset's bias, the law
fits through scipy, and F_P: auto's plateau rounds."""

import math

import numpy as np
import pytest

from fibril_hpc.campaign.analysis.verdict_text import ci_method, why_out
from fibril_hpc.campaign.laws import alphabeta, fit, intervals, reading
from fibril_hpc.campaign.laws.study import study_k
from fibril_hpc.campaign.plan import auto

PRE = [0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0]


def _group(fa_of, pre=PRE, seeds=3, noise=0.01, rng_seed=0):
    """(seed, preload, F_P, F_A) arrays: F~_A = fa_of(F~_P) x (1 + seed effect)."""
    rng = np.random.default_rng(rng_seed)
    eff = {s: rng.normal(0, noise) for s in range(seeds)}
    rows = [(s, p, p, float(fa_of(p)) * (1 + eff[s])) for s in range(seeds) for p in pre]
    return tuple(np.array(c) for c in zip(*rows))


def test_the_plateau_is_where_F_A_stops_rising():
    r = reading.read_group(*_group(lambda p: 1.2 * math.tanh(p / 0.05)))
    assert r.plateau_state == "reached" and r.plateau == pytest.approx(1.2, rel=0.02)
    # read from the preloads above the rise only, and inside the top preload's seed range
    assert r.plateau_from >= 0.25 and r.top_lo - 1e-12 <= r.plateau <= r.top_hi + 1e-12
    still = reading.read_group(*_group(lambda p: 1.2 * math.tanh(p / 2.0)))
    assert still.plateau_state == "not reached" and "not reached" in still.notes[0]
    assert still.top_lo <= still.plateau <= still.top_hi        # a lower bound: F~_A at the top


FLOOR = reading.pillar_floor(18, 0.16)


def test_a_flat_group_at_the_pillar_floor_is_adhesion_lost_and_a_flat_plateau_is_unresolved():
    # every seed the same F~_A (the last pillar's pull-off) at every preload: adhesion lost
    seed, pre, x, y = _group(lambda p: 0.0075, noise=0.0)
    r = reading.read_group(seed, pre, x, y, floor=FLOOR)
    assert r.state == reading.LOST and r.c == 0.0 and r.c0 == 0.0
    assert r.plateau == pytest.approx(0.0075) and not r.rises
    st = study_k(1.0, {2.1: (seed, pre, x, y)}, n_boot=50, floor=FLOOR)
    assert st.groups[0].c_ci == (0.0, 0.0) and st.groups[0].in_fit
    # the same flat curve far above the floor: the rise lies below the smallest preload
    flat = reading.read_group(seed, pre, x, 1.96 + 0 * y, floor=FLOOR)
    assert flat.state == reading.UNRESOLVED and math.isnan(flat.c)
    assert flat.c_lower == pytest.approx(1.96 / 0.001) and flat.resolve_below == pytest.approx(1e-4)
    assert "rise not resolved" in flat.c_notes[-1] and "0.0001" in flat.c_notes[-1]
    st = study_k(1.0, {0.01: (seed, pre, x, 1.96 + 0 * y)}, n_boot=50, floor=FLOOR)
    assert not st.groups[0].in_fit and "lower bound" in why_out(st.groups[0])
    # without a floor the two cannot be told apart: undetermined, never a zero
    none = reading.read_group(seed, pre, x, y)
    assert none.state == reading.UNDETERMINED and math.isnan(none.c)


def test_a_first_contact_that_overshoots_says_no_smaller_preload_is_reachable():
    seed = np.repeat([0, 1], 4)
    pre = np.tile([0.001, 0.004, 0.25, 1.0], 2)
    x = np.tile([0.03, 0.03, 0.25, 1.0], 2)            # 0.001 and 0.004 reached at 0.03
    y = np.tile([1.04, 1.04, 1.045, 1.045], 2) * np.repeat([1.0, 1.001], 4)
    r = reading.read_group(seed, pre, x, y, floor=FLOOR)
    assert r.state == reading.UNRESOLVED and r.c_lower == pytest.approx(1.04 * 1.0005 / 0.03,
                                                                        rel=1e-3)
    assert "overshot" in r.c_notes[-1] and math.isnan(r.resolve_below)


def test_c_is_the_secant_to_half_the_plateau_c_stage_the_linear_stage_c0_the_first_contacts():
    c_true, P = 8.0, 1.0
    pre = [0.002, 0.01, 0.03, 0.5, 1.0, 4.0]
    r = reading.read_group(*_group(lambda p: min(c_true * p, P), pre=pre, noise=0.0),
                           floor=FLOOR)
    assert r.state == reading.RESOLVED and r.plateau_state == "reached"
    assert r.plateau == pytest.approx(P)
    # the half point, interpolated in log F~_P between the levels 0.03 (0.24) and 0.5 (1.0)
    t = (0.5 - 0.24) / (1.0 - 0.24)
    assert r.F_P_half == pytest.approx(0.03 * (0.5 / 0.03) ** t)
    assert r.c == pytest.approx(0.5 / r.F_P_half)
    assert any("x 17 apart" in n for n in r.c_notes)       # levels around it too far apart
    assert r.c_stage == pytest.approx(c_true, rel=1e-9) and r.n_stage == 2   # 0.002: < 3 pillars
    assert r.c0 == pytest.approx(c_true, rel=1e-9)       # F~_A/F~_P on the linear stage
    # a preload at the half point itself: c is exact
    exact = reading.read_group(*_group(lambda p: min(c_true * p, P), pre=pre + [P / 2 / c_true],
                                       noise=0.0), floor=FLOOR)
    assert exact.c == pytest.approx(c_true)


def test_levels_merge_a_first_contact_that_overshot_two_preloads():
    seed = np.array([0, 0, 0, 1, 1, 1])
    pre = np.array([0.001, 0.004, 1.0] * 2)
    x = np.array([0.0078, 0.0078, 1.0, 0.0079, 0.0079, 1.0])
    y = np.array([0.1, 0.1, 1.0, 0.11, 0.11, 1.1])
    lv = reading.levels(seed, pre, x, y)
    assert len(lv) == 2 and list(lv.preload) == [0.004, 1.0] and list(lv.n) == [2, 2]


def test_one_seed_and_one_preload_are_read_with_reasons():
    r = reading.read_group(*_group(lambda p: math.tanh(p / 0.05), seeds=1), floor=FLOOR)
    assert r.plateau_state == "reached" and math.isfinite(r.c) and r.state == reading.RESOLVED
    one = reading.read_group(np.array([0]), np.array([1.0]), np.array([1.0]), np.array([0.5]))
    assert one.plateau_state == "not reached" and math.isnan(one.c) and one.notes
    st = study_k(1.0, {0.3: _group(lambda p: math.tanh(p / 0.05), seeds=1)}, n_boot=50)
    assert ci_method(st).startswith("one seed") and not st.ab.ok and st.ab.notes


def test_alpha_beta_with_zero_groups_recovers_the_line_and_brackets_sigma_c():
    a, b = 0.5, 0.25                                      # sigma~_c = 2
    s = np.array([0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4])
    c = alphabeta.model(s, a, b)
    assert c[-2:].tolist() == [0.0, 0.0]
    f = alphabeta.fit_alpha_beta(s, c, np.full(s.size, 0.01))
    assert f.alpha == pytest.approx(a, rel=1e-6) and f.beta == pytest.approx(b, rel=1e-6)
    assert f.sigma_c == pytest.approx(2.0, rel=1e-6) and f.bracket == (1.6, 3.2)
    assert f.n_zero == 2 and not f.poor


def test_beta_below_zero_says_why_and_a_poor_fit_is_flagged():
    s = np.array([0.1, 0.5, 1.0])
    f = alphabeta.fit_alpha_beta(s, [1.0, 1.5, 2.0], [0.1, 0.1, 0.1])
    assert f.beta < 0 and math.isnan(f.sigma_c)
    assert alphabeta.Note.BETA_NONPOS in f.notes
    s = np.array([0.1, 0.2, 0.4, 0.8])
    bad = alphabeta.fit_alpha_beta(s, [5.0, 1.0, 3.0, 0.2], [0.05] * 4)
    assert bad.poor and alphabeta.Note.POOR in bad.notes
    assert alphabeta.fit_alpha_beta([0.1], [1.0]).ok is False


def test_study_intervals_hold_the_truth_of_a_noisy_campaign():
    a, b, P = 0.5, 0.25, 1.0
    half = 0.5 / math.atanh(0.5)        # a tanh rise's secant to half over its initial slope
    pts = {}
    for i, s in enumerate((0.1, 0.2, 0.4, 0.8)):
        slope = (a / s - b) / half
        pre = sorted(set(np.geomspace(1e-3, 4, 30).round(7)))
        pts[s] = _group(lambda p, k=slope: P * math.tanh(k * p / P), pre=pre, seeds=6,
                        noise=0.02, rng_seed=i)
    st = study_k(1.0, pts, n_boot=100, floor=FLOOR)
    assert st.ab.ok and st.alpha_ci[0] < a < st.alpha_ci[1] and st.beta_ci[0] < b < st.beta_ci[1]
    assert st.sigma_c_ci[0] < a / b < st.sigma_c_ci[1]
    assert st.status == "fitted" and st.verdict.zero == "extrapolated"
    for g in st.groups:
        assert g.plateau_ci[0] <= g.reading.plateau <= g.plateau_ci[1]
        assert g.reading.c == pytest.approx(a / g.sigma_tilde - b, rel=0.1)


def test_seed_intervals_and_the_preset_bias():
    assert intervals.seed_replicates([0], lambda s: [1.0], 50) is None
    reps = intervals.seed_replicates([0, 1, 2], lambda s: [float(np.mean(s))], 200)
    lo, hi = intervals.percentile_interval(reps[0])
    assert 0 <= lo < 1 < hi <= 2
    assert intervals.percentile_interval([1.0, 2.0, math.inf, math.inf])[1] == math.inf
    # an end that the percentile interpolates towards an unbounded replicate is unbounded, never
    # a huge number on the page (found on a pillar-brush search: 6.4e299)
    r = list(np.linspace(1.0, 2.0, 39)) + [math.inf]
    assert intervals.percentile_interval(r)[1] == math.inf
    assert intervals.percentile_interval([-math.inf] + r[:-1])[0] == -math.inf
    assert intervals.percentile_interval(r[:-1] + [3.0]) == pytest.approx(
        tuple(np.percentile(r[:-1] + [3.0], [2.5, 97.5])))
    assert intervals.preset_bias("fast", 6)[0] == -0.036
    assert math.isnan(intervals.preset_bias("fast", 8)[0])
    assert intervals.dominant(1.0, (0.9, 1.1), -0.036) == "seeds"
    assert intervals.dominant(1.0, (0.99, 1.01), -0.036) == "discretisation"


@pytest.mark.parametrize("law", fit.LAWS)
def test_fit_law_finds_the_least_squares_kink(law):
    pre = np.array(PRE * 2)
    y = fit.model(law, pre, 20.0, 1.0) * (1 + 0.03 * np.repeat([1.0, -1.0], len(PRE)))
    f = fit.fit_law(pre, y, law)
    v = np.log(y)
    for tk in math.log(f.kink) + np.linspace(-0.05, 0.05, 101):
        g = np.log(fit.model(law, pre, math.exp(-tk), 1.0))      # plateau 1, kink e^tk
        r = v - np.mean(v - g) - g
        assert math.sqrt(np.mean(r * r)) >= f.rms_log - 1e-9
    assert f.plateau == pytest.approx(1.0, rel=0.05)


def test_auto_adds_plateau_rounds_until_F_A_stops_rising():
    a = auto.AutoPreloads(start=(0.01, 0.1, 1.0, 4.0), below=1, above=1, bracket=100.0)
    rising = {p: (p, math.tanh(p / 10.0)) for p in a.start}      # still rising at 4
    assert auto.path_todo(a, rising)[0] == [16.0]
    rising[16.0] = (16.0, math.tanh(16.0 / 10.0))
    assert auto.path_todo(a, rising)[0] == [20.0]                # capped at max
    rising[20.0] = (20.0, math.tanh(2.0))
    assert auto.path_todo(a, rising)[0] == []                    # max reached
    flat = {p: (p, math.tanh(p / 0.01)) for p in a.start}
    assert auto.path_todo(a, flat)[0] == []
    assert auto.path_todo(a, {p: (p, math.nan) for p in a.start})[0] == []


def test_the_pillar_floor_comes_from_the_campaigns_scene():
    from fibril_hpc.campaign.analysis.report_data import campaign_floor

    job = {"status": "done", "scene_yaml": "n_side: 6\nphi: 0.16\n"}
    # no grid text in the file: the first done job's stored scene tells (not the defaults)
    f, note = campaign_floor({"campaign_yaml": ""}, [job])
    assert f == pytest.approx(reading.pillar_floor(6, 0.16)) and "N = 36" in note
    f, _ = campaign_floor({"campaign_yaml": "scene: {n_side: 18}\n"}, [job])
    assert f == pytest.approx(FLOOR)
    assert math.isnan(campaign_floor({"campaign_yaml": "scene: {tip: sphere}\n"}, [job])[0])
    assert math.isnan(campaign_floor({}, [])[0])

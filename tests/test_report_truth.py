"""The report against known truth: synthetic groups and campaigns (tests/synthetic_campaigns.py)
whose state, plateau, c and sigma~_c are set, covering smooth and sharp rises, saturation at
first contact, the one-pillar floor, lost adhesion, 1-10 seeds, mixed seed sets per level and
preloads added below the rise. Property tests draw the truths with hypothesis."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from fibril_hpc.campaign.analysis.verdict_text import why_out
from fibril_hpc.campaign.laws import reading
from fibril_hpc.campaign.laws.intervals import small_sample_factor
from fibril_hpc.campaign.laws.study import study_k

from synthetic_campaigns import FLOOR, START, Truth, group, law_campaign

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

truths = st.builds(
    lambda shape, logc, P, fc: Truth(shape, 0.0 if shape == "lost" else math.exp(logc),
                                     FLOOR if shape == "lost" else P,
                                     first_contact=fc if shape in ("instant", "lost") else 0.0),
    st.sampled_from(["sharp", "smooth", "instant", "lost"]),
    st.floats(math.log(0.5), math.log(3000)), st.floats(0.1, 2.5), st.floats(0.002, 0.05))


@SETTINGS
@given(t=truths, seeds=st.integers(1, 10), extra=st.integers(0, 3), rounds=st.integers(0, 2),
       rng=st.integers(0, 2**31))
def test_every_state_is_recovered_and_c_where_the_rise_is_resolved(t, seeds, extra, rounds, rng):
    x0 = max(min(START), t.first_contact)
    if t.shape in ("sharp", "smooth"):
        # clear of the borderline where the seed scatter decides the state
        assume(not 0.3 * t.plateau <= t.c * x0 <= 0.7 * t.plateau)
        # the plateau reached by the fixed preloads (F~_A flat over the two largest)
        assume(t.c * 1.0 >= 3 * t.plateau)
    r = reading.read_group(*group(t, seeds, START, extra, rounds, rng), floor=FLOOR)
    want = t.state(min(START))
    assert r.state == want, (r.state, r.c_notes, r.notes)
    if want == reading.LOST:
        assert r.c == 0.0 and r.c0 == 0.0
    elif want == reading.UNRESOLVED:
        assert math.isnan(r.c) and r.c_lower > 0
        if t.shape != "instant":        # a lower bound of the truth (a concave rise)
            assert r.c_lower <= t.c * (1 + 5 * t.c_sd)
        else:
            assert r.c_lower == pytest.approx(t.plateau / x0, rel=5 * t.P_sd)
            assert ("overshot" in r.c_notes[-1]) == (x0 > 1.5 * min(START))
    else:
        seed_tol = 5 * t.c_sd / math.sqrt(seeds)
        if t.shape == "smooth":         # log interpolation of a tanh across x 4
            assert abs(r.c / t.c_read() - 1) <= seed_tol + 0.15, (r.c, t.c_read())
        else:                           # a sharp bend between two levels x 4 apart
            assert t.c_read() / 4.5 <= r.c <= 4.5 * t.c_read() * (1 + seed_tol)
            assert any("apart" in n for n in r.c_notes) or \
                abs(r.c / t.c_read() - 1) <= seed_tol + 0.15


@SETTINGS
@given(logc=st.floats(math.log(3), math.log(300)), P=st.floats(0.3, 2.0),
       shape=st.sampled_from(["sharp", "smooth"]), seeds=st.integers(1, 5),
       below=st.lists(st.floats(1e-6, 1.0), min_size=1, max_size=4), rng=st.integers(0, 2**31))
def test_preloads_added_below_the_rise_leave_c_unchanged(logc, P, shape, seeds, below, rng):
    c = math.exp(logc)
    t = Truth(shape, c, P)
    pre = tuple(float(v) for v in np.geomspace(P / c / 30, 8 * P / c, 9))
    # preloads on the first-contact floor (c F~_P below one pillar's pull-off)
    low = tuple(sorted({float(np.round(FLOOR / c * f, 12)) for f in below}))
    a = reading.read_group(*group(t, seeds, pre, rng=rng), floor=FLOOR)
    b = reading.read_group(*group(t, seeds, low + pre, rng=rng), floor=FLOOR)
    assert a.state == b.state == reading.RESOLVED
    assert b.c == pytest.approx(a.c, rel=1e-9) and b.c_stage == pytest.approx(a.c_stage, rel=1e-9)


def test_a_mixed_seed_set_at_the_top_is_flagged_and_never_sets_the_plateau():
    t = Truth("sharp", 20.0, 1.0, P_sd=0.0, c_sd=0.0)
    seed, pre, x, y = group(t, 3, START, rng=0)
    # one seed has a plateau round at F~_P = 16 where its F~_A is 40 % lower (a bad level)
    seed, pre, x, y = (np.append(seed, 0), np.append(pre, 16.0), np.append(x, 16.0),
                       np.append(y, 0.6))
    r = reading.read_group(seed, pre, x, y, floor=FLOOR)
    assert r.seeds[-1] == 1 and r.seeds[0] == 3
    assert r.plateau == pytest.approx(1.0) and r.top_lo == r.top_hi == pytest.approx(1.0)
    assert any("fewer seeds" in n for n in r.notes)


def _coverage(n_seeds, draws, rng):
    hit = 0
    for d in range(draws):
        c = float(np.exp(rng.uniform(np.log(3), np.log(300))))
        P = float(rng.uniform(0.3, 2.0))
        t = Truth("smooth", c, P, c_sd=0.1, P_sd=0.03)
        pre = tuple(float(v) for v in np.geomspace(P / c / 200, 8 * P / c, 16))
        g = study_k(1.0, {0.5: group(t, n_seeds, pre, rng=rng)}, n_boot=100,
                    rng_seed=d).groups[0]
        hit += g.c_ci[0] <= t.c_read() <= g.c_ci[1]
    return hit / draws


@pytest.mark.slow
@pytest.mark.parametrize("n_seeds", [3, 10])
def test_the_seed_interval_of_c_holds_the_truth_at_the_rate_it_claims(n_seeds):
    # the widened interval held the truth in 90-97 % of 120-150 draws (benchmarks/NOTES.md);
    # >= 51 of 60 here (a true 90 % gives that with probability 0.87, a true 95 % 0.99; the
    # draws are fixed, so the test is deterministic); the plain percentile interval held it in
    # 67-81 % (3 seeds)
    assert small_sample_factor(n_seeds) > 1
    assert _coverage(n_seeds, 60, np.random.default_rng(n_seeds)) >= 51 / 60


@pytest.mark.slow
def test_alpha_beta_and_sigma_c_of_a_law_campaign_with_lost_groups():
    alpha, beta = 2.0, 1.0                                 # sigma~_c = 2
    sigmas = (0.07, 0.164, 0.384, 0.898, 2.1, 4.9)
    held = 0
    for draw in range(4):       # a 95 % interval may miss once; the rest hold on every draw
        pts, _ = law_campaign(alpha, beta, sigmas, seeds=5, rng=draw, c_sd=0.05)
        st_ = study_k(1.0, pts, n_boot=100, floor=FLOOR)
        states = [g.reading.state for g in st_.groups]
        assert states == [reading.RESOLVED] * 4 + [reading.LOST] * 2
        assert st_.ab.bracket == (0.898, 2.1)              # the model-free bracket holds 2
        assert st_.status == "fitted"
        held += (st_.alpha_ci[0] <= alpha <= st_.alpha_ci[1]
                 and st_.beta_ci[0] <= beta <= st_.beta_ci[1])
        # the lost groups are out of the fit: the line's zero is an extrapolation of the rising
        # c, and it lies within the measured loss (the law is true here)
        assert st_.verdict.zero == "extrapolated" and st_.loss_vs_law == "within"
    assert held >= 3


def test_a_zero_beyond_the_grid_is_an_extrapolation_and_its_interval_holds_it():
    alpha, beta = 2.0, 0.5                                 # sigma~_c = 4, beyond the grid
    pts, _ = law_campaign(alpha, beta, (0.07, 0.164, 0.384, 0.898, 2.1), seeds=6, rng=5,
                          c_sd=0.05)
    st_ = study_k(1.0, pts, n_boot=100, floor=FLOOR)
    assert st_.status == "fitted" and st_.verdict.zero == "extrapolated"
    assert st_.sigma_c_ci[0] <= 4.0 <= st_.sigma_c_ci[1]


def test_a_law_the_data_do_not_follow_is_never_called_fitted():
    # c falling as 1/sigma~^2 with little scatter: the line leaves residuals beyond it
    sig = (0.07, 0.164, 0.384, 0.898, 2.1)
    pts = {}
    for i, s in enumerate(sig):
        c = 0.5 / s**2
        t = Truth("sharp", c, 1.5, c_sd=0.02)
        pts[s] = group(t, 5, tuple(np.geomspace(1.5 / c / 300, 12 / c, 12)), rng=i)
    st_ = study_k(1.0, pts, n_boot=60, floor=FLOOR)
    assert st_.status in ("poor fit", "undefined") and st_.verdict.zero == "none"
    # c that does not depend on sigma~: alpha consistent with 0, the law undefined
    flat = {s: group(Truth("sharp", 30.0, 1.5, c_sd=0.1), 5,
                     tuple(np.geomspace(1.5 / 30 / 300, 12 / 30, 12)), rng=10 + i)
            for i, s in enumerate(sig)}
    st2 = study_k(1.0, flat, n_boot=60, floor=FLOOR)
    assert st2.status in ("undefined", "poor fit")
    assert st2.verdict.zero == "none" and st2.loss_vs_law == ""


def test_unresolved_groups_stay_out_of_the_fit_and_lost_ones_enter_as_zero():
    pts, _ = law_campaign(2.0, 1.0, (0.164, 0.384, 0.898, 2.1), seeds=3, rng=1)
    # the smooth limit saturating at first contact: rise not resolved, a lower bound
    pts[0.01] = group(Truth("instant", math.nan, 1.9, first_contact=0.03), 3, START, rng=2)
    st_ = study_k(1.0, pts, n_boot=60, floor=FLOOR)
    g = {g.sigma_tilde: g for g in st_.groups}
    assert g[0.01].reading.state == reading.UNRESOLVED and not g[0.01].in_fit
    assert "lower bound" in why_out(g[0.01])
    assert g[2.1].reading.state == reading.LOST and g[2.1].in_fit and g[2.1].reading.c == 0
    assert 0.01 not in st_.ab.sigmas and 2.1 in st_.ab.sigmas

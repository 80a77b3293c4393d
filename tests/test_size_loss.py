"""Where adhesion is lost across brush sizes (:mod:`fibril_hpc.campaign.laws.size_loss`),
against synthetic brushes of known truth (tests/size_truth.py): a plateau that fades with
sigma~ to a known P_inf(sigma~) plus a finite-size term of a few pillars, A N^(-3/4), with the
seed scatter of real 8-16 brushes (6 % on P_inf, 20 % on the few pillars) and four seeds, each
seed one height pattern at every sigma~ of its size."""

from __future__ import annotations

import math
import os
import sys
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))
import size_truth as st  # noqa: E402

from fibril_hpc.campaign.laws import size_loss as sl  # noqa: E402
from fibril_hpc.geometry.scaling import Scaling  # noqa: E402

SIZES = (8, 12, 16)
THR = sl.AREA_THRESHOLD
TRUE_INF = st.sigma_at(THR)          # 0.461: where P_inf falls to the per-area threshold


@pytest.fixture(scope="module")
def draws():
    return [sl.size_loss(1.0, st.brushes(SIZES, pillars=2.5, rng=r), st.PHI, n_boot=80,
                         rng_seed=r) for r in range(4)]


def test_the_intensive_loss_is_recovered_with_its_interval(draws):
    cover = 0
    for s in draws:
        assert s.sigma_inf_kind == sl.BRACKET
        assert abs(s.sigma_inf - TRUE_INF) < 0.03, s.sigma_inf
        lo, hi = s.sigma_inf_ci
        assert lo < s.sigma_inf < hi and hi - lo < 0.1
        cover += lo <= TRUE_INF <= hi
    assert cover >= 3


def test_p_inf_is_recovered_at_every_sigma(draws):
    hits = total = 0
    for s in draws:
        for e in s.extrapolations:
            truth = st.p_inf(e.sigma_tilde)
            assert abs(e.p_inf - truth) < 0.06, (e.sigma_tilde, e.p_inf, truth)
            total += 1
            hits += e.p_inf_ci[0] <= truth <= e.p_inf_ci[1]
            # held where the truth is clearly above 0, gone where it is 0
            if truth > 0.05:
                assert e.state == sl.HOLDS
            if truth == 0.0:
                assert e.state == sl.GONE
    assert hits >= 0.8 * total


def test_the_few_pillar_crossing_is_not_the_intensive_loss(draws):
    """Beyond sigma_inf every size still holds its few tallest pillars (2.5 pillars' pull-off,
    under the 3-pillar threshold only there): the 3-pillar crossing of every size lies above
    the per-area loss, while the per-area crossing approaches it as N grows."""
    for s in draws:
        few = {c.n_side: c for c in s.few}
        area = {c.n_side: c for c in s.area}
        for n in SIZES:
            assert few[n].kind == sl.BRACKET and few[n].sigma > TRUE_INF + 0.05
            assert not area[n].below_floor
        assert abs(area[16].sigma - TRUE_INF) < abs(area[8].sigma - TRUE_INF)
        assert area[16].sigma > s.sigma_inf          # a finite brush holds longer
        lo, hi = area[16].ci
        assert lo < area[16].sigma < hi


def test_no_loss_in_the_range_run_is_said_so():
    s = sl.size_loss(1.0, st.brushes(SIZES, sigmas=(0.1, 0.2, 0.3), rng=1), st.PHI, n_boot=20)
    assert s.sigma_inf_kind == sl.NO_LOSS and math.isnan(s.sigma_inf)
    assert s.sigma_inf_bracket == (0.3, math.inf)
    assert all(c.kind == sl.NO_LOSS for c in s.few)


@pytest.mark.parametrize("exponent, state", [(0.75, sl.CONSISTENT), (0.35, sl.DIFFERS)])
def test_the_exponent_is_measured_over_sizes_far_apart(exponent, state):
    """Four sizes a factor 8 apart and little scatter: p is measured, 3/4 found or refused."""
    s = sl.size_loss(1.0, st.brushes((8, 16, 32, 64), sigmas=(0.1, 0.2, 0.3, 0.4), sd_inf=0.01,
                                     sd_a=0.02, exponent=exponent, pillars=6.0, rng=2),
                     st.PHI, n_boot=40)
    assert s.p_state == state, (s.p, s.p_ci)
    assert abs(s.p - exponent) < 0.15
    assert s.p_sigmas == (0.1, 0.2, 0.3, 0.4)


@pytest.mark.parametrize("p, ci, state", [
    (0.8, (0.6, 1.0), sl.CONSISTENT), (0.75, (0.75, 0.9), sl.CONSISTENT),
    (0.4, (0.3, 0.5), sl.DIFFERS), (1.2, (0.9, 1.5), sl.DIFFERS),
    (0.9, (0.3, 1.5), sl.NOT_DETERMINED), (1.0, (-0.2, 1.4), sl.NOT_DETERMINED),
    (3.0, (1.2, 3.0), sl.NOT_DETERMINED), (0.9, (0.05, 1.0), sl.NOT_DETERMINED),
    (math.nan, (0.5, 1.0), sl.NOT_FITTED), (0.8, (0.6, math.inf), sl.NOT_FITTED)])
def test_the_exponent_state(p, ci, state):
    assert sl.exponent_state(p, ci) == state


def test_p_is_measured_on_the_groups_that_hold_adhesion_only(draws):
    """Lost groups (a few pillars: N^(-3/4) by construction) stay out of the exponent."""
    for s in draws:
        assert s.p_sigmas == (0.2, 0.3, 0.4, 0.5)


def test_the_seeds_of_one_size_are_resampled_alike_at_every_sigma(draws):
    """Beyond sigma_inf the synthetic groups of one size are the same points at every sigma~:
    paired replicates give them the same P_inf in every replicate, so the same interval."""
    for s in draws:
        ci = {e.sigma_tilde: e.p_inf_ci for e in s.extrapolations}
        assert ci[0.6] == ci[0.8] == ci[1.0]


def test_two_seeds_widen_the_interval_for_the_small_sample():
    """Two seeds per size: a bootstrap of two seeds has three distinct resamples and a
    percentile interval far too narrow; widened by t_1 (x 9.2) it holds the truth."""
    for r in range(3):
        s = sl.size_loss(1.0, st.brushes(SIZES, pillars=2.5, seeds=2, rng=10 + r), st.PHI,
                         n_boot=60, rng_seed=r)
        lo, hi = s.sigma_inf_ci
        assert lo <= TRUE_INF <= hi and hi - lo > 0.015, s.sigma_inf_ci


def test_three_close_sizes_do_not_determine_the_exponent(draws):
    assert all(s.p_state in (sl.NOT_DETERMINED, sl.CONSISTENT) for s in draws)
    assert sum(s.p_state == sl.NOT_DETERMINED for s in draws) >= 2


def test_two_sizes_give_crossings_but_no_extrapolation():
    s = sl.size_loss(1.0, {n: g for n, g in st.brushes((8, 16), rng=3).items()}, st.PHI,
                     n_boot=20)
    assert len(s.few) == 2 and not s.extrapolations
    assert s.sigma_inf_kind == sl.NOT_READ and s.p_state == sl.NOT_FITTED
    # two crossed sizes are enough for a drift (no degree of freedom, but a slope)
    assert s.area_drift.n_sides == (8, 16) and s.area_drift.state != sl.NOT_MEASURED
    q = math.log(s.area[1].sigma / s.area[0].sigma) / math.log(4.0)
    assert s.area_drift.q == pytest.approx(q)


def test_a_size_whose_few_pillar_threshold_reaches_the_area_one_is_left_out_of_its_drift():
    """At 4 x 4 three pillars' pull-off (0.24) is above F~_A = 0.1: its per-area crossing is a
    pillar count, so the per-area drift reads 8 and 16 only; the 3-pillar drift reads all."""
    s = sl.size_loss(1.0, st.brushes((4, 8, 16), pillars=0.5, rng=4), st.PHI, n_boot=20)
    assert s.area[0].below_floor and not s.area[1].below_floor
    assert s.area_drift.n_sides == (8, 16)
    assert s.few_drift.n_sides == tuple(c.n_side for c in s.few if c.kind == sl.BRACKET)


FAR = (8, 16, 32, 64)
FAR_SIGMAS = (0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0)


@pytest.mark.parametrize("pillar_ref, q_true, state, sigmas", [
    (None, 0.0, sl.FIXED_SIGMA, FAR_SIGMAS), (16, sl.Q_PILLAR, sl.FIXED_PILLAR, FAR_SIGMAS),
    (16, sl.Q_SPRING, sl.FIXED_SPRING, tuple(np.geomspace(0.03, 2.5, 24).round(4)))])
def test_the_drift_tells_the_three_limits_apart(pillar_ref, q_true, state, sigmas):
    """Sizes a factor 64 apart and a small finite-size term (0.2 pillars): a loss per area at
    a fixed sigma~ has a per-area crossing that stays put (q = 0); one at a fixed sigma / d_c1
    moves as N^(-1/4), one at a fixed k sigma / F_c1 as N^(-3/4)."""
    for r in range(2):
        s = sl.size_loss(1.0, st.brushes(FAR, sigmas=sigmas, pillars=0.2, pillar_ref=pillar_ref,
                                         loss_drift=q_true, rng=r), st.PHI, n_boot=40,
                         rng_seed=r)
        d = s.area_drift
        assert d.n_sides == FAR and d.state == state, (d.q, d.q_ci)
        assert abs(d.q - q_true) < 0.02 and d.q_ci[0] < d.q < d.q_ci[1]


def _true_drift(threshold_of_n, sizes=SIZES, pillars=2.5):
    """The least-squares d ln sigma~ / d ln N of the synthetic truth's crossings."""
    x = np.log([n * n for n in sizes])
    y = [math.log(st.sigma_at(threshold_of_n(n) - st.amplitude(pillars) * (n * n) ** -0.75))
         for n in sizes]
    return float(np.polyfit(x, y, 1)[0])


def test_the_crossings_drift_as_the_truth_does_over_8_to_16(draws):
    """Loss per area at a fixed sigma~ plus 2.5 pillars' finite-size term: the per-area
    crossing falls towards sigma~_inf (q < 0), the 3-pillar one rises towards sigma~_0
    (q > 0); the measured q's intervals hold the truth's."""
    from fibril_hpc.campaign.laws.reading import FEW_PILLARS, pillar_floor

    q_area = _true_drift(lambda n: THR)
    q_few = _true_drift(lambda n: FEW_PILLARS * pillar_floor(n, st.PHI))
    assert q_area < -0.05 and q_few > 0.01
    cover_area = cover_few = 0
    for s in draws:
        assert s.area_drift.q < 0 < s.few_drift.q
        cover_area += s.area_drift.q_ci[0] <= q_area <= s.area_drift.q_ci[1]
        cover_few += s.few_drift.q_ci[0] <= q_few <= s.few_drift.q_ci[1]
    assert cover_area >= 3 and cover_few >= 3


def _crossing(n, sigma, reps):
    return sl.Crossing(n, 0.1, sl.BRACKET, sigma, (0.0, 1.0), (0.0, 1.0), 4,
                       replicates=tuple(reps))


def test_a_replicate_that_does_not_cross_leaves_the_drift_unbounded_on_its_side():
    """A replicate without a crossing at the largest size (inf) is a drift of +inf; at the
    smallest size (inf there) one of -inf; the value itself is the bracketed crossings'."""
    rng = np.random.default_rng(0)
    base = {8: 0.6, 12: 0.55, 16: 0.5}

    def reps(n, inf_share):
        r = base[n] * np.exp(0.03 * rng.standard_normal(200))
        r[: int(inf_share * 200)] = math.inf
        return r

    up = sl.crossing_drift([_crossing(n, base[n], reps(n, 0.2 if n == 16 else 0))
                            for n in SIZES])
    down = sl.crossing_drift([_crossing(n, base[n], reps(n, 0.2 if n == 8 else 0))
                              for n in SIZES])
    q = float(np.polyfit(np.log([64, 144, 256]), np.log([0.6, 0.55, 0.5]), 1)[0])
    assert up.q == pytest.approx(q) and down.q == pytest.approx(q)
    assert up.q_ci[1] == math.inf and math.isfinite(up.q_ci[0])
    assert down.q_ci[0] == -math.inf and math.isfinite(down.q_ci[1])
    # one bracketed size, or none replicated: no drift measured
    one = sl.crossing_drift([_crossing(8, 0.6, reps(8, 0)),
                             sl.Crossing(16, 0.1, sl.NO_LOSS, math.nan)])
    assert one.state == sl.NOT_MEASURED and math.isnan(one.q)
    bare = sl.crossing_drift([sl.Crossing(n, 0.1, sl.BRACKET, base[n]) for n in SIZES])
    assert bare.q == pytest.approx(q) and bare.state == sl.NOT_MEASURED


@pytest.mark.parametrize("q, ci, state", [
    (-0.02, (-0.1, 0.05), sl.FIXED_SIGMA), (-0.25, (-0.3, -0.2), sl.FIXED_PILLAR),
    (-0.8, (-0.9, -0.7), sl.FIXED_SPRING), (-0.5, (-0.76, -0.4), sl.FIXED_SPRING),
    (-0.1, (-0.3, 0.1), "fixed sigma~ or fixed sigma/d_c1"),
    (-0.1, (-0.2, -0.05), sl.NEITHER), (-0.5, (-0.7, -0.3), sl.NEITHER),
    (0.3, (0.2, 0.4), sl.NEITHER), (-1.2, (-2.0, -0.8), sl.NEITHER),
    (-0.5, (-math.inf, -0.1), "fixed sigma/d_c1 or fixed k sigma/F_c1"),
    (0.0, (-0.1, math.inf), sl.FIXED_SIGMA), (-0.25, (-0.25, 0.0),
                                              "fixed sigma~ or fixed sigma/d_c1"),
    (-0.3, (-1.0, 0.2), "fixed sigma~ or fixed sigma/d_c1 or fixed k sigma/F_c1"),
    (math.nan, (-0.1, 0.1), sl.NOT_MEASURED), (0.0, (math.nan, math.nan), sl.NOT_MEASURED)])
def test_the_drift_state(q, ci, state):
    assert sl.drift_state(q, ci) == state


def test_curve_crossing_is_exact_on_a_power_law_and_bounded():
    sig = [0.2, 0.4, 0.8]
    p = [0.5 * (x / 0.2) ** -2 for x in sig]           # 0.5, 0.125, 0.03125
    s, br = sl.first_fall(sig, p, 0.05)
    assert br == (0.4, 0.8) and s == pytest.approx(0.2 * (0.5 / 0.05) ** 0.5)
    assert sl.first_fall(sig, p, 0.01, clip=False)[0] == math.inf
    assert sl.first_fall(sig, p, 0.9, clip=False)[0] == 0.0
    assert math.isnan(sl.first_fall(sig, p, 0.01)[0])
    s, br = sl.level_crossing([0.1, 0.2, 0.3], [0.4, 0.1, -0.2], 0.0)
    assert br == (0.2, 0.3) and s == pytest.approx(0.2 + 0.1 / 3)


def test_pillar_variables_follow_from_the_scaling():
    """sigma / d_c1 and k / (E* D) from :class:`Scaling` of the brush and of one pillar (its own
    compact punch, phi = 1, area phi L^2 / N)."""
    phi, n, dgamma = 0.16, 12, 0.7
    brush = Scaling(phi, dgamma)
    one = Scaling(1.0, dgamma, area=phi / n ** 2)
    sigma_t, k_t = 0.4, 0.01
    assert sl.pillar_sigma(sigma_t, n, phi) == pytest.approx(sigma_t * brush.d_c / one.d_c)
    D = 2.0 * math.sqrt(phi / n ** 2 / math.pi)
    assert sl.pillar_k(k_t, n, phi) == pytest.approx(brush.k(k_t) / D)
    # the spring force at the roughness over one pillar's own Kendall pull-off
    assert sl.pillar_spring(sigma_t, k_t, n, phi) == pytest.approx(
        brush.k(k_t) * sigma_t * brush.d_c / one.F_c)
    # the roughness over the pillar's reach: its own d_c1 plus its spring's stretch at F_c1
    assert sl.pillar_reach(sigma_t, k_t, n, phi) == pytest.approx(
        sigma_t * brush.d_c / (one.d_c + one.F_c / brush.k(k_t)))


def test_the_headline_names_each_k_sizes_when_they_differ(draws):
    """Merged files may sweep other sizes per k~ (20 x 20 added to one k~ only): each k~'s part
    of the headline names its own sizes; with one set of sizes the line names it once."""
    from fibril_hpc.campaign.analysis import size_loss_page

    wide = sl.size_loss(0.01, st.brushes((8, 12, 16, 20), pillars=2.5, rng=7), st.PHI,
                        n_boot=20)
    line = size_loss_page.headline_line({1.0: draws[0], 0.01: wide})
    assert "k̃ = 1 (sizes 8, 12, 16):" in line and "k̃ = 0.01 (sizes 8, 12, 16, 20):" in line
    one = size_loss_page.headline_line({1.0: draws[0], 0.5: draws[1]})
    assert one.startswith("Loss across sizes (sizes 8, 12, 16): k̃ = 1: ")


def test_the_page_says_what_the_numbers_say(draws, tmp_path):
    from fibril_hpc.campaign.analysis import figures_size_loss, size_loss_page

    d = SimpleNamespace(size_loss={1.0: draws[0]})
    t = size_loss_page.table(d)
    head = t.csv_rows[0]
    assert len(t.csv_rows) == 1 + len(SIZES) + 1 and all(len(r) == len(head) for r in t.csv_rows)
    inf_row = dict(zip(head, t.csv_rows[-1]))
    assert inf_row["n_side"] == "inf" and float(inf_row["sigma_area"]) == draws[0].sigma_inf
    for name in ("few_drift", "area_drift"):
        dr = getattr(draws[0], name)
        assert float(inf_row[name]) == dr.q and inf_row[name + "_state"] == dr.state
        assert (float(inf_row[name + "_lo"]), float(inf_row[name + "_hi"])) == dr.q_ci
    assert f"{draws[0].area_drift.q:.2g}" in t.page_rows[-1][-1]
    row16 = dict(zip(head, t.csv_rows[3]))
    assert float(row16["pillar_sigma_few"]) == pytest.approx(
        draws[0].few[2].sigma * (st.PHI * 256) ** 0.25)
    assert float(row16["spring_area"]) == pytest.approx(
        sl.pillar_k(1.0, 16, st.PHI) * float(row16["pillar_sigma_area"]))
    assert all(len(r) == len(t.page_rows[0]) for r in t.page_rows)
    assert float(row16["reach_area"]) == pytest.approx(
        float(row16["pillar_sigma_area"]) / (1 + 1 / sl.pillar_k(1.0, 16, st.PHI)))
    e = size_loss_page.extrapolation_table(d)
    assert len(e.csv_rows) == 1 + len(draws[0].extrapolations)
    line = size_loss_page.headline_line(d.size_loss)
    assert f"{draws[0].sigma_inf:.3g}" in line and "8, 12, 16" in line
    png = figures_size_loss.loss_across_sizes(d, str(tmp_path))
    assert os.path.getsize(png) > 10_000
    assert np.isfinite(draws[0].plateau[8]).all()


LOSS_SIGMAS = (0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0)


@pytest.mark.parametrize("r", range(3))
def test_a_loss_at_a_fixed_pillar_roughness_has_no_size_free_sigma(r, tmp_path):
    """Sizes 16-64 whose loss sits at one sigma / d_c1 (its crossings fall as N^(-1/4) without
    end): the line P_inf + A N^(-3/4) does not fit near the crossing, and no sigma~_inf is given
    (the old reading gave 0.21 [0.21, 0.22], a precise number of a limit that does not exist);
    the page says so and gives the drift instead."""
    from fibril_hpc.campaign.analysis import figures_size_loss, size_loss_page

    s = sl.size_loss(1.0, st.brushes((16, 32, 64), sigmas=LOSS_SIGMAS, pillars=2.5,
                                     pillar_ref=16, rng=r), st.PHI, n_boot=40, rng_seed=r)
    assert s.sigma_inf_kind == sl.NOT_SIZE_FREE and math.isnan(s.sigma_inf)
    assert all(math.isnan(v) for v in s.sigma_inf_ci)
    assert {e.sigma_tilde for e in s.extrapolations if e.state == sl.REJECTED} >= {0.2, 0.3}
    assert s.area_drift.state == sl.FIXED_PILLAR or s.area_drift.q < -0.2
    line = size_loss_page.headline_line({1.0: s})
    assert "no N → ∞ σ̃ read (P∞ + A N^(−3/4) does not fit" in line
    assert "N → ∞ extrapolation" not in line
    assert f"{s.area_drift.q:.2g}" in line and "0.2 (χ²/dof" in line
    d = SimpleNamespace(size_loss={1.0: s})
    t = size_loss_page.table(d)
    inf_row = dict(zip(t.csv_rows[0], t.csv_rows[-1]))
    assert inf_row["sigma_area"] == "" and inf_row["area_kind"] == sl.NOT_SIZE_FREE
    assert "not read (no N → ∞ limit from these sizes)" in t.page_rows[-1]
    e = size_loss_page.extrapolation_table(d)
    assert "**model rejected**" in [row[-1] for row in e.page_rows]
    assert os.path.getsize(figures_size_loss.loss_across_sizes(d, str(tmp_path))) > 10_000


@pytest.mark.parametrize("sizes", [(8, 12, 16), (16, 32, 64)])
def test_a_loss_at_a_fixed_sigma_keeps_its_size_free_sigma(sizes):
    """The same four-seed scatter with the loss at a fixed sigma~: the line fits at every
    sigma~ (no rejection) and sigma~_inf is the truth's, over close and far sizes."""
    from fibril_hpc.campaign.analysis import size_loss_page

    moving = 0
    for r in range(4):
        s = sl.size_loss(1.0, st.brushes(sizes, sigmas=LOSS_SIGMAS, pillars=2.5, rng=r),
                         st.PHI, n_boot=40, rng_seed=r)
        assert not [e for e in s.extrapolations if e.state == sl.REJECTED], r
        assert s.sigma_inf_kind == sl.BRACKET and abs(s.sigma_inf - TRUE_INF) < 0.03
        # the headline gives the number, and says when the sizes' crossings still move
        line = size_loss_page.headline_line({1.0: s})
        assert f"σ̃ = {s.sigma_inf:.3g}" in line
        assert ("still move" in line) == (sl.FIXED_SIGMA not in s.area_drift.state), line
        moving += "still move" in line
    assert moving       # the finite-size term moves them a little, and the intervals see it


@pytest.mark.parametrize("lo, chi2, dof, state", [
    (0.1, 29.9, 1, sl.HOLDS), (0.1, 30.1, 1, sl.REJECTED), (-0.1, 30.1, 1, sl.REJECTED),
    (-0.1, 59.0, 2, sl.GONE), (0.0, 1.0, 1, sl.GONE), (0.1, 61.0, 2, sl.REJECTED),
    (math.nan, 1.0, 1, sl.UNKNOWN), (math.nan, 31.0, 1, sl.REJECTED), (0.1, 1e9, 0, sl.HOLDS)])
def test_the_extrapolation_state(lo, chi2, dof, state):
    assert sl.extrapolation_state(lo, chi2, dof) == state
    assert sl.extrapolation_state(lo, chi2, dof, 0.05) == state


@pytest.mark.parametrize("hi, chi2, state", [
    (-1e-9, 1.0, sl.BELOW), (0.0, 1.0, sl.GONE), (-0.05, 30.1, sl.REJECTED),
    (math.nan, 1.0, sl.GONE)])
def test_an_interval_wholly_below_0_is_no_plateau(hi, chi2, state):
    """The k~ = 0.01 page read P∞ = -0.0796 [-0.0988, -0.0526] at sigma~ = 0.7 as **gone**: a
    line that overshoots 0 says the plateau falls faster than N^(-3/4), not that it is 0."""
    assert sl.extrapolation_state(-0.1, chi2, 1, hi) == state
    assert (sl.BELOW in sl.NO_LIMIT) and (sl.GONE not in sl.NO_LIMIT)


@pytest.mark.parametrize("rejected, kind", [
    ((), sl.BRACKET), ((0.3,), sl.NOT_SIZE_FREE), ((0.4,), sl.NOT_SIZE_FREE),
    ((0.6,), sl.BRACKET), ((0.2,), sl.NOT_SIZE_FREE), ((0.2, 0.6), sl.NOT_SIZE_FREE)])
def test_sigma_inf_rests_on_the_extrapolations_up_to_its_bracket(rejected, kind):
    """sigma~_inf is the first crossing of the threshold, read between the two sigma~ whose
    P_inf bracket it (0.3, 0.4 here): a rejected line at or below the bracket's top leaves it
    without a number; one above it does not."""
    sigmas, p_inf = (0.2, 0.3, 0.4, 0.6), (0.4, 0.2, 0.05, 0.0)
    s = sl.SizeLoss(1.0, st.PHI, (16, 32, 64), sigmas, {}, {}, {}, {})
    s.extrapolations = [sl.Extrapolation(v, (16, 32, 64), p, state=sl.REJECTED if v in rejected
                                         else sl.HOLDS) for v, p in zip(sigmas, p_inf)]
    sl._loss_at(s, "sigma_inf", THR, sigmas, p_inf, [], 4)
    assert s.sigma_inf_kind == kind and s.sigma_inf_bracket == (0.3, 0.4)
    assert math.isfinite(s.sigma_inf) == (kind == sl.BRACKET)


@pytest.mark.parametrize("state, falls", [
    (sl.FIXED_PILLAR, True), (sl.FIXED_SPRING, True),
    (f"{sl.FIXED_PILLAR} or {sl.FIXED_SPRING}", True), (sl.FIXED_SIGMA, False),
    (f"{sl.FIXED_SIGMA} or {sl.FIXED_PILLAR}", False), (sl.NEITHER, False),
    (sl.NOT_MEASURED, False)])
def test_a_drift_that_names_only_falling_limits_reads_no_sigma_inf(state, falls):
    """Crossings drifting as a fixed sigma / d_c1 (or k sigma / F_c1) would, and not as a fixed
    sigma~, leave no sigma~_inf to read, even where every line fits (close sizes cannot reject
    it); a drift that a fixed sigma~ allows, or that names no limit, keeps the number."""
    from fibril_hpc.campaign.analysis import size_loss_page

    assert sl.keeps_falling(state) == falls
    sigmas, p_inf = (0.2, 0.3, 0.4, 0.6), (0.4, 0.2, 0.05, 0.0)
    s = sl.SizeLoss(1.0, st.PHI, (16, 32, 64), sigmas, {}, {}, {}, {})
    s.area_drift = sl.Drift((32, 64), -0.25, (-0.33, -0.12), state)
    s.extrapolations = [sl.Extrapolation(v, (16, 32, 64), p, state=sl.HOLDS)
                        for v, p in zip(sigmas, p_inf)]
    sl._loss_at(s, "sigma_inf", THR, sigmas, p_inf, [], 4)
    assert (s.sigma_inf_kind == sl.NOT_SIZE_FREE) == falls
    line = size_loss_page.headline_line({1.0: s})
    assert ("crossings drift as a limit that keeps falling" in line) == falls


def test_p_s_interval_stays_in_the_fit_s_range_and_the_page_says_where_it_ends():
    """The widened interval of p stops at the fit's bounds (a p below 0.05 is never fitted): an
    end there is written '≤ 0.05' / '≥ 3', not a number the fit cannot give (-0.0144 was)."""
    from fibril_hpc.campaign.analysis import size_loss_page

    s = sl.size_loss(1.0, st.brushes((8, 12, 16), sigmas=(0.1, 0.2, 0.3), sd_inf=0.1,
                                     sd_a=0.3, rng=5), st.PHI, n_boot=40)
    lo, hi = s.p_ci
    assert sl.P_BOUNDS[0] <= lo <= s.p <= hi <= sl.P_BOUNDS[1], (s.p, s.p_ci)
    assert s.p_state == sl.NOT_DETERMINED
    assert lo == sl.P_BOUNDS[0] or hi == sl.P_BOUNDS[1]
    text = size_loss_page._p_text
    assert text(0.124, (0.05, 0.547)) == "= 0.124 [≤ 0.05, 0.547]"
    assert text(0.124, (0.05, 3.0)) == "= 0.124 [≤ 0.05, ≥ 3]"
    assert text(0.124, (0.0499, 2.99)) == "= 0.124 [0.0499, 2.99]"     # not at a bound: as is
    assert text(0.75, (0.6, 0.9)) == "= 0.75 [0.6, 0.9]"
    assert text(0.75, (math.nan, math.nan)) == "= 0.75"
    assert text(math.nan, (0.6, 0.9)) == "= —"
    # p itself at a bound is no estimate
    assert text(0.05, (0.05, 0.576)) == "at the fit's bound 0.05 [≤ 0.05, 0.576]"
    assert text(3.0, (0.9, 3.0)) == "at the fit's bound 3 [0.9, ≥ 3]"


def test_a_limit_read_with_an_exponent_the_sizes_do_not_back_says_so(draws):
    """σ~_inf rests on P∞ + A N^(−3/4): where the sizes do not determine p, or measure another,
    the headline says the exponent was assumed; where they agree with 3/4 it says nothing."""
    from dataclasses import replace

    from fibril_hpc.campaign.analysis import size_loss_page

    s = draws[0]
    assert s.sigma_inf_kind == sl.BRACKET
    line = size_loss_page.headline_line
    said = "(N^(−3/4) assumed: these sizes do not determine the exponent)"
    for state in (sl.NOT_DETERMINED, sl.NOT_FITTED):
        assert said in line({1.0: replace(s, p_state=state)})
    assert "assumed" not in line({1.0: replace(s, p_state=sl.CONSISTENT)})
    other = replace(s, p_state=sl.DIFFERS, p=0.3, p_ci=(0.2, 0.45))
    assert "(N^(−3/4) assumed: these sizes measure p = 0.3 [0.2, 0.45])" in line({1.0: other})
    none = replace(s, p_state=sl.NOT_DETERMINED, sigma_inf_kind=sl.NO_LOSS)
    assert "assumed" not in line({1.0: none})          # no limit read: nothing to qualify


@pytest.mark.parametrize("below, blocked", [((), False), ((0.6,), False), ((0.4,), True),
                                            ((0.3, 0.6), True)])
def test_a_line_below_0_blocks_only_at_or_below_the_bracket_and_is_named_only_then(below,
                                                                                  blocked):
    """The 8-20 k~ = 0.01 page named P∞ below 0 at sigma~ = 2-4, above the bracket, as why no
    sigma~_inf was read, while the drift was the reason: the page names what blocks it."""
    from fibril_hpc.campaign.analysis import size_loss_page

    sigmas, p_inf = (0.2, 0.3, 0.4, 0.6), (0.4, 0.2, 0.05, -0.1)
    s = sl.SizeLoss(1.0, st.PHI, (16, 32, 64), sigmas, {}, {}, {}, {})
    s.area_drift = sl.Drift((32, 64), -0.25, (-0.33, -0.12), sl.FIXED_PILLAR)
    s.extrapolations = [sl.Extrapolation(v, (16, 32, 64), p, state=sl.BELOW if v in below
                                         else sl.HOLDS) for v, p in zip(sigmas, p_inf)]
    sl._loss_at(s, "sigma_inf", THR, sigmas, p_inf, [], 4)
    assert s.sigma_inf_kind == sl.NOT_SIZE_FREE       # the drift alone keeps falling
    line = size_loss_page.headline_line({1.0: s})
    assert "keeps falling" in line
    assert ("lies below 0 at" in line) == blocked, line
    if blocked:
        assert "lies below 0 at σ̃ = " + ", ".join(f"{v:g}" for v in below if v <= 0.4) in line
    # without the drift, a line below 0 up to the bracket's top alone blocks the reading
    s.area_drift = sl.Drift((32, 64), 0.0, (-0.1, 0.1), sl.FIXED_SIGMA)
    sl._loss_at(s, "sigma_inf", THR, sigmas, p_inf, [], 4)
    assert (s.sigma_inf_kind == sl.NOT_SIZE_FREE) == blocked


def test_a_lost_group_below_the_first_held_one_does_not_end_the_reading():
    """A plateau at or below the threshold before any sigma~ holds (a lost group below the first
    held one) is not the loss: the crossing is the first fall after a held sigma~, as the
    report's bracket (it read 0 before); from sigma~ = 0 the crossing is linear in sigma~."""
    s, br = sl.first_fall([0.5, 1.0, 2.0], [0.5, 4.0, 0.25], 1.0)
    assert br == (1.0, 2.0) and s == pytest.approx(math.sqrt(2.0))
    assert sl.first_fall([0.5, 1.0, 2.0], [0.5, 4.0, 2.0], 1.0, clip=False) == (0.0, (0.0, 0.5))
    s, br = sl.first_fall([0.0, 1.0], [2.0, 0.5], 1.0)
    assert br == (0.0, 1.0) and 0.0 < s < 1.0


def test_the_read_size_gives_the_measured_sigma_c_and_no_other_size():
    from fibril_hpc.campaign.laws.loss import BRACKET, NO_LOSS, Loss

    s = sl.size_loss(1.0, st.brushes((8, 16), seeds=3, rng=5), st.PHI, n_boot=30)
    few = {c.n_side: c for c in s.few}
    thr = few[16].threshold
    own8 = (few[8].sigma, few[8].ci)
    m = Loss(kind=BRACKET, bracket=(0.5, 0.6), sigma=0.55, ci=(0.41, 0.83), threshold=thr)
    sl.adopt_measured(s, 16, m)
    assert (few[16].kind, few[16].sigma, few[16].ci, few[16].bracket) == (
        sl.BRACKET, 0.55, (0.41, 0.83), (0.5, 0.6))
    assert (few[8].sigma, few[8].ci) == own8
    # another threshold (another brush's floor) or no bracket: the size keeps its own reading
    for other in (Loss(kind=BRACKET, sigma=0.7, ci=(0.6, 0.9), threshold=thr * 1.01),
                  Loss(kind=NO_LOSS, threshold=thr)):
        sl.adopt_measured(s, 8, other)
        assert (few[8].sigma, few[8].ci) == own8


def test_the_figure_tells_a_line_below_0_from_a_rejected_one(monkeypatch):
    """loss_across_sizes.png drew P∞ below 0 (sigma~ 0.7 and 1 of the k~ = 0.01 16-64 file) as
    red crosses labelled "P∞ rejected (χ²/dof > 30)"."""
    from fibril_hpc.campaign.analysis import figures_size_loss as fsl

    s = sl.size_loss(1.0, st.brushes((8, 12, 16), rng=2), st.PHI, n_boot=20)
    states = [sl.REJECTED, sl.BELOW, sl.BELOW, sl.HOLDS]
    for e, state in zip(s.extrapolations, states + [sl.HOLDS] * 9):
        e.state = state
    figs = []
    monkeypatch.setattr(fsl, "save", lambda fig, out, name: figs.append(fig) or name)
    fsl.loss_across_sizes(SimpleNamespace(size_loss={1.0: s}), "unused")
    labels = dict(zip(*reversed(figs[0].axes[0].get_legend_handles_labels())))
    rej = labels[f"P∞ rejected (χ²/dof > {sl.POOR_CHI2:g})"]
    below = labels["P∞ below 0: the line overshoots"]
    x = [e.sigma_tilde for e in s.extrapolations]
    assert list(rej.get_xdata()) == [x[0]] and list(below.get_xdata()) == x[1:3]

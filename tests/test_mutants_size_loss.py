"""laws.size_loss, pinned so that its one-line mutations fail (issue 34, item 6;
benchmarks/mutation.py). Small synthetic brushes of known truth (tests/size_truth.py, each
seed one height pattern at every sigma~ of its size) and few resamples, so that it runs in
seconds: the pillar variables, both crossings at their edges, the weighted line and the shared
exponent against exact data, the weights' floor, the paired resampling of a size (against a
reconstruction from the module text: one draw of the size's seed labels per replicate, read at
every sigma~), sizes drawn independently, the trend of the per-area crossing, the
extrapolation in N with its states, the exponent's states at their edges, and the grouping by
k~."""

from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))
import size_truth as st  # noqa: E402

from fibril_hpc.campaign.laws import size_loss as sl  # noqa: E402
from fibril_hpc.campaign.laws.intervals import expanded, percentile_interval  # noqa: E402
from fibril_hpc.campaign.laws.reading import (  # noqa: E402
    FEW_PILLARS,
    LOST,
    RESOLVED,
    pillar_floor,
    read_group,
)

SIZES = (8, 12, 16)
SIG = (0.2, 0.4, 0.5, 0.7)
NB = 12


def _brushes(**kw):
    kw = {"sizes": SIZES, "sigmas": SIG, "seeds": 3, "pillars": 2.5, "rng": 5, **kw}
    return st.brushes(**kw)


def _reps(group_by_sigma, sigmas, floor, n_boot, seed):
    """Replicate plateaus of one size as the module text defines them: per replicate one draw
    of the size's seed labels (with replacement), every sigma~ read on the labels drawn that it
    holds, each drawn label a seed of its own."""
    rng = np.random.default_rng(seed)
    labels = sorted({int(v) for g in group_by_sigma.values() for v in g[0]})
    out = np.full((n_boot, len(sigmas)), np.nan)
    for b in range(n_boot):
        pick = [labels[i] for i in rng.integers(0, len(labels), len(labels))]
        for i, s in enumerate(sigmas):
            if s not in group_by_sigma:
                continue
            seed_, pre, x, y = group_by_sigma[s]
            sel, lab = [], []
            for j, p in enumerate(pick):
                rows = np.flatnonzero(seed_ == p)
                sel += rows.tolist()
                lab += [100 + j] * rows.size
            if sel:
                out[b, i] = read_group(np.array(lab), pre[sel], x[sel], y[sel],
                                       floor=floor).plateau
    return out


@pytest.fixture
def case():
    # not module-scoped: mutmut runs, for a mutant, the tests it saw reach the function, and a
    # shared fixture is reached by the first test that builds it only
    by_n = _brushes()
    s = sl.size_loss(1.0, by_n, st.PHI, n_boot=NB, rng_seed=3)
    reps = {n: _reps(by_n[n], SIG, pillar_floor(n, st.PHI), NB, 3 + 7919 * n) for n in SIZES}
    return by_n, s, reps


def test_pillar_variables():
    assert sl.pillar_sigma(0.4, 12, 0.16) == pytest.approx(0.4 * (0.16 * 144) ** 0.25, rel=1e-14)
    assert sl.pillar_sigma(1, 3, 1) == pytest.approx(3 ** 0.5, rel=1e-14)
    assert sl.pillar_k(0.01, 12, 0.16) == pytest.approx(0.01 * math.sqrt(math.pi * 144 / 0.64),
                                                        rel=1e-14)
    assert sl.pillar_k(1, 2, 1) == pytest.approx(math.sqrt(math.pi), rel=1e-14)


def test_curve_crossing_at_its_edges():
    sig = [0.2, 0.4, 0.8, 1.6]
    p = [1.0, 0.25, 0.0625, 0.015625]                  # P = 0.04 sigma~^-2
    s, br = sl.first_fall(sig, p, 0.1)
    assert br == (0.4, 0.8) and s == pytest.approx(math.sqrt(0.4), rel=1e-12)
    assert isinstance(s, float) and all(isinstance(v, float) for v in br)
    # a level exactly at the threshold has fallen to it
    assert sl.first_fall(sig, p, 0.25) == (pytest.approx(0.4, rel=1e-12), (0.2, 0.4))
    first = sl.first_fall(sig, p, 1.0)
    assert math.isnan(first[0]) and first[1] == (0.0, 0.2)
    assert sl.first_fall(sig, p, 1.0, clip=False) == (0.0, (0.0, 0.2))
    assert sl.first_fall(sig, p, 2.0, clip=False) == (0.0, (0.0, 0.2))
    never = sl.first_fall(sig, p, 0.01)
    assert math.isnan(never[0]) and never[1] == (1.6, math.inf)
    assert sl.first_fall(sig, p, 0.01, clip=False) == (math.inf, (1.6, math.inf))
    # points that are not a positive plateau are skipped, not crossed
    s, br = sl.first_fall([0.1] + sig + [3.0], [math.nan] + [1.0, 0.0, 0.0625, 0.015625]
                              + [-1.0], 0.1)
    assert br == (0.2, 0.8) and s == pytest.approx(math.sqrt(0.4), rel=1e-12)
    for thr in (0.0, -1.0, math.nan):
        s, br = sl.first_fall(sig, p, thr)
        assert math.isnan(s) and all(math.isnan(v) for v in br)
    s, br = sl.first_fall([0.2, 0.4], [math.nan, -1.0], 0.1)
    assert math.isnan(s) and all(math.isnan(v) for v in br)


def test_level_crossing_at_its_edges():
    sig = [0.1, 0.2, 0.3, 0.5]
    p = [0.5, 0.3, 0.1, -0.1]
    s, br = sl.level_crossing(sig, p, 0.2)
    assert br == (0.2, 0.3) and s == pytest.approx(0.25, rel=1e-12)
    assert sl.level_crossing(sig, p) == (pytest.approx(0.4, rel=1e-12), (0.3, 0.5))
    assert sl.level_crossing(sig, p, 0.3) == (pytest.approx(0.2, rel=1e-12), (0.1, 0.2))
    first = sl.level_crossing(sig, p, 0.5)
    assert math.isnan(first[0]) and first[1] == (0.0, 0.1)
    assert sl.level_crossing(sig, p, 0.5, clip=False) == (0.0, (0.0, 0.1))
    never = sl.level_crossing(sig, p, -0.2)
    assert math.isnan(never[0]) and never[1] == (0.5, math.inf)
    assert sl.level_crossing(sig, p, -0.2, clip=False) == (math.inf, (0.5, math.inf))
    # NaN P_inf skipped (a sigma~ not run at every size)
    s, br = sl.level_crossing([0.1, 0.2, 0.3], [0.4, math.nan, -0.2])
    assert br == (0.1, 0.3) and s == pytest.approx(0.1 + 0.2 * 0.4 / 0.6, rel=1e-12)
    s, br = sl.level_crossing([0.1], [math.nan])
    assert math.isnan(s) and all(math.isnan(v) for v in br)


def test_the_weighted_line_and_its_chi2():
    x = np.array([0.0, 1.0, 2.0, 4.0])
    y = np.array([1.0, 2.9, 5.2, 8.8])
    w = np.array([1.0, 4.0, 0.5, 2.0])
    a, b, chi2 = sl.fit_line(x, y, w)
    B, A = np.polyfit(x, y, 1, w=np.sqrt(w))
    assert (a, b) == pytest.approx((A, B), rel=1e-10)
    assert chi2 == pytest.approx(float(np.sum(w * (y - A - B * x) ** 2)), rel=1e-10)
    # points without a finite value or a positive weight are left out
    a2, b2, c2 = sl.fit_line(np.append(x, [5.0, 6.0, math.nan, 7.0]),
                             np.append(y, [0.0, math.nan, 1.0, 3.0]),
                             np.append(w, [0.0, 1.0, 1.0, math.inf]))
    assert (a2, b2, c2) == pytest.approx((a, b, chi2), rel=1e-12)
    for w in ([1.0, -1.0], [1.0, 0.0]):
        assert sl.fit_line([1.0, 2.0], [1.0, 3.0], w) == pytest.approx(
            (math.nan, math.nan, math.nan), nan_ok=True)
    assert sl.fit_line([1.0, 2.0], [1.0, 3.0], [1.0, 1.0]) == pytest.approx((-1.0, 2.0, 0.0),
                                                                             abs=1e-12)


def test_the_shared_exponent_is_recovered_from_exact_data():
    N = np.array([64.0, 144.0, 256.0, 1024.0])
    for p in (0.4, 0.75, 1.5):
        Y = np.array([0.5 + 2.0 * N ** -p, 0.1 + 4.0 * N ** -p, 0.0 + 1.0 * N ** -p])
        W = np.array([[1.0, 2.0, 1.0, 3.0]] * 3)
        assert sl.fit_shared_p(N, Y, W) == pytest.approx(p, rel=1e-5)
        assert sl.fit_shared_p(N, Y, W, p0=2.0) == pytest.approx(p, rel=1e-3)
    # weights matter: one point off the law, weighted down, hardly moves p
    Y = np.array([0.5 + 2.0 * N ** -0.75, 0.1 + 4.0 * N ** -0.75])
    Y[0, 0] *= 1.3
    light = sl.fit_shared_p(N, Y, np.array([[1e-6, 1, 1, 1], [1, 1, 1, 1.0]]))
    heavy = sl.fit_shared_p(N, Y, np.ones((2, 4)))
    assert abs(light - 0.75) < 1e-3 < abs(heavy - 0.75)
    n4 = np.array([2.0, 3.0, 4.0, 6.0])                 # p beyond the range: at its bound
    Y = np.array([0.5 + 2.0 * n4 ** -4.0, 0.1 + 4.0 * n4 ** -4.0])
    assert sl.fit_shared_p(n4, Y, np.ones((2, 4))) == pytest.approx(sl.P_BOUNDS[1], rel=1e-4)
    Y = np.array([0.5 + 2.0 * N ** -0.01, 0.1 + 4.0 * N ** -0.01])
    assert sl.fit_shared_p(N, Y, np.ones((2, 4))) == pytest.approx(sl.P_BOUNDS[0], rel=1e-3)
    for bad in (math.nan, math.inf):
        Y2 = np.array([0.5 + 2.0 * N ** -0.75] * 2)
        Y2[1, 2] = bad
        assert math.isnan(sl.fit_shared_p(N, Y2, np.ones((2, 4))))
        assert math.isnan(sl.fit_shared_p(N, Y2[:1] * 1.0, np.full((1, 4), bad)))


def test_the_exponent_state_at_its_edges():
    lo_b, hi_b = sl.P_BOUNDS
    assert sl.exponent_state(0.75, (0.5, 1.0)) == sl.CONSISTENT
    assert sl.exponent_state(0.75, (0.75, 1.0)) == sl.CONSISTENT
    assert sl.exponent_state(0.75, (0.5, 0.75)) == sl.CONSISTENT
    assert sl.exponent_state(0.8, (0.76, 1.0)) == sl.DIFFERS
    assert sl.exponent_state(0.7, (0.5, 0.74)) == sl.DIFFERS
    # the span: hi / lo up to P_SPAN determines p
    assert sl.exponent_state(0.8, (0.5, 0.5 * sl.P_SPAN)) == sl.CONSISTENT
    assert sl.exponent_state(0.8, (0.5, 0.5 * sl.P_SPAN * 1.001)) == sl.NOT_DETERMINED
    assert sl.exponent_state(1.0, (0.0, 1.2)) == sl.NOT_DETERMINED
    # within 1 % of a bound: not determined; just inside: judged
    assert sl.exponent_state(0.9, (lo_b * 1.01, 1.0)) == sl.NOT_DETERMINED
    assert sl.exponent_state(0.9, (lo_b * 1.011, 0.2)) == sl.DIFFERS
    assert sl.exponent_state(2.5, (2.0, hi_b * 0.99)) == sl.NOT_DETERMINED
    assert sl.exponent_state(2.5, (2.0, hi_b * 0.989)) == sl.DIFFERS
    assert sl.exponent_state(hi_b * 0.99, (2.0, 2.5)) == sl.NOT_DETERMINED
    assert sl.exponent_state(lo_b * 1.01, (0.06, 0.2)) == sl.NOT_DETERMINED
    for p, ci in ((math.nan, (0.5, 1.0)), (0.8, (math.nan, 1.0)), (0.8, (0.5, math.nan)),
                  (0.8, (0.5, math.inf)), (math.inf, (0.5, 1.0)), (0.8, (-math.inf, 1.0))):
        assert sl.exponent_state(p, ci) == sl.NOT_FITTED, (p, ci)


def test_every_size_is_read_with_its_own_floor_and_paired_seeds(case):
    by_n, s, reps = case
    assert s.n_sides == SIZES and s.sigmas == SIG and s.k_tilde == 1.0 and s.phi == st.PHI
    for n in SIZES:
        floor = pillar_floor(n, st.PHI)
        rd = [read_group(*by_n[n][x], floor=floor) for x in SIG]
        np.testing.assert_array_equal(s.plateau[n], [r.plateau for r in rd])
        assert s.states[n] == [r.state for r in rd]
        assert s.n_seeds[n] == 3
        want = [expanded(v, percentile_interval(reps[n][:, i]), 3)
                for i, v in enumerate(s.plateau[n])]
        np.testing.assert_allclose(s.plateau_ci[n], want, rtol=1e-12)
        few, area = s.few[SIZES.index(n)], s.area[SIZES.index(n)]
        assert few.n_side == n and few.threshold == FEW_PILLARS * floor and few.n_seeds == 3
        assert area.threshold == sl.AREA_THRESHOLD and area.n_seeds == 3
        assert area.below_floor is (FEW_PILLARS * floor >= sl.AREA_THRESHOLD)
        for c in (few, area):
            x, br = sl.first_fall(SIG, s.plateau[n], c.threshold)
            assert c.kind == sl.BRACKET and c.sigma == x and c.bracket == br
            r = [sl.first_fall(SIG, row, c.threshold, clip=False)[0] for row in reps[n]]
            lo, hi = expanded(x, percentile_interval(r), 3)
            assert c.ci == pytest.approx((max(lo, 0.0), max(hi, 0.0)), rel=1e-12)


def test_the_extrapolation_in_n_and_the_large_brush_loss(case):
    by_n, s, reps = case
    N = np.array([n * n for n in SIZES], float)
    x = N ** -0.75
    rep_pinf = []
    assert [e.sigma_tilde for e in s.extrapolations] == list(SIG)
    for i, e in enumerate(s.extrapolations):
        y = np.array([s.plateau[n][i] for n in SIZES])
        sd = np.array([np.std(reps[n][:, i], ddof=1) for n in SIZES])
        w = 1 / np.maximum(sd, 0.01 * np.abs(y)) ** 2
        a, b, chi2 = sl.fit_line(x, y, w)
        assert e.n_sides == SIZES and e.dof == 1
        assert (e.p_inf, e.amplitude, e.chi2) == pytest.approx((a, b, chi2), rel=1e-9)
        r = [sl.fit_line(x, [reps[n][j, i] for n in SIZES], w)[0] for j in range(NB)]
        rep_pinf.append(r)
        assert e.p_inf_ci == pytest.approx(expanded(a, percentile_interval(r), 3), rel=1e-9)
        assert e.state == (sl.HOLDS if e.p_inf_ci[0] > 0 else sl.GONE)
        # against the truth: P_inf of the synthetic brush
        assert abs(e.p_inf - st.p_inf(SIG[i])) < 0.08
    assert [e.state for e in s.extrapolations] == [sl.HOLDS, sl.HOLDS, sl.HOLDS, sl.GONE]
    rep_pinf = np.array(rep_pinf).T
    for name, level in (("sigma_inf", sl.AREA_THRESHOLD), ("sigma_zero", 0.0)):
        s0, br = sl.level_crossing(SIG, [e.p_inf for e in s.extrapolations], level)
        assert getattr(s, name) == s0 and getattr(s, name + "_bracket") == br
        assert getattr(s, name + "_kind") == sl.BRACKET
        r = [sl.level_crossing(SIG, row, level, clip=False)[0] for row in rep_pinf]
        lo, hi = expanded(s0, percentile_interval(r), 3)
        assert getattr(s, name + "_ci") == pytest.approx((max(lo, 0.0), max(hi, 0.0)), rel=1e-9)
    assert abs(s.sigma_inf - st.sigma_at(sl.AREA_THRESHOLD)) < 0.05
    # the exponent from the sigma~ that hold adhesion at every size only
    held = tuple(x for i, x in enumerate(SIG)
                 if all(s.states[n][i] == RESOLVED for n in SIZES))
    assert s.p_sigmas == held and len(held) >= 2 and 0.7 not in held
    keep = [SIG.index(v) for v in held]
    W = []
    for i in keep:
        y = np.array([s.plateau[n][i] for n in SIZES])
        sd = np.array([np.std(reps[n][:, i], ddof=1) for n in SIZES])
        W.append(1 / np.maximum(sd, 0.01 * np.abs(y)) ** 2)
    Y = np.array([[s.plateau[n][i] for n in SIZES] for i in keep])
    assert s.p == sl.fit_shared_p(N, Y, np.array(W))
    r = [sl.fit_shared_p(N, np.array([[reps[n][j, i] for n in SIZES] for i in keep]),
                         np.array(W)) for j in range(NB)]
    # the widened interval, clipped to the fit's range (an end beyond it is not a fitted p)
    want = np.clip(expanded(s.p, percentile_interval(r), 3), *sl.P_BOUNDS)
    assert s.p_ci == pytest.approx(tuple(want), rel=1e-9)
    assert s.p_state == sl.exponent_state(s.p, s.p_ci)


def test_sizes_are_drawn_independently_and_seeds_alike_within_one():
    """The same points given as two sizes: their replicates must not be the same draws. And a
    size's sigma~ with the same points are resampled alike (paired)."""
    g = _brushes(sizes=(8,))[8]
    same = {8: g, 9: g}
    s = sl.size_loss(1.0, same, st.PHI, n_boot=NB, rng_seed=0)
    assert s.plateau_ci[8] != s.plateau_ci[9]
    twin = {8: {0.2: g[0.2], 0.3: g[0.2]}}
    t = sl.size_loss(1.0, twin, st.PHI, n_boot=NB, rng_seed=0)
    assert t.plateau_ci[8][0] == t.plateau_ci[8][1]


def test_a_group_short_of_a_seed_takes_the_drawn_seeds_it_holds():
    by_n = _brushes(sizes=(8,))
    g = dict(by_n[8])
    seed, pre, x, y = g[0.4]
    keep = seed != 2
    g[0.4] = (seed[keep], pre[keep], x[keep], y[keep])
    s = sl.size_loss(1.0, {8: g}, st.PHI, n_boot=NB, rng_seed=4)
    reps = _reps(g, SIG, pillar_floor(8, st.PHI), NB, 4 + 7919 * 8)
    assert s.n_seeds[8] == 3
    want = [expanded(v, percentile_interval(reps[:, i]), 3) for i, v in enumerate(s.plateau[8])]
    np.testing.assert_allclose(s.plateau_ci[8], want, rtol=1e-12)


def test_one_seed_or_no_resamples_give_numbers_without_intervals():
    for by_n, nb in ((_brushes(seeds=1), NB), (_brushes(), 0)):
        s = sl.size_loss(1.0, by_n, st.PHI, n_boot=nb)
        assert all(math.isnan(v) for n in SIZES for ci in s.plateau_ci[n] for v in ci)
        assert all(math.isnan(v) for c in s.few + s.area for v in c.ci)
        assert all(c.kind == sl.BRACKET and math.isfinite(c.sigma) for c in s.few)
        assert len(s.extrapolations) == len(SIG)
        for e in s.extrapolations:
            assert e.state == sl.UNKNOWN and all(math.isnan(v) for v in e.p_inf_ci)
            assert math.isfinite(e.p_inf)
        assert s.sigma_inf_kind == sl.BRACKET and math.isfinite(s.sigma_inf)
        assert all(math.isnan(v) for v in s.sigma_inf_ci)
        assert s.p_state == sl.NOT_FITTED and all(math.isnan(v) for v in s.p_ci)
        assert math.isfinite(s.p) and s.area_trend == sl.UNKNOWN
    # without resamples the weights are the floor's: 1 / (1 % of the plateau)^2
    s = sl.size_loss(1.0, _brushes(), st.PHI, n_boot=0)
    x = np.array([n * n for n in SIZES], float) ** -0.75
    for i, e in enumerate(s.extrapolations):
        y = np.array([s.plateau[n][i] for n in SIZES])
        assert e.chi2 == pytest.approx(sl.fit_line(x, y, 1 / (0.01 * y) ** 2)[2], rel=1e-9)


def test_the_per_area_trend_of_the_two_largest_sizes():
    def _with(cis, below=(False, False, False), kinds=(sl.BRACKET,) * 3):
        s = sl.SizeLoss(1.0, st.PHI, SIZES, SIG, {}, {}, {}, {})
        s.area = [sl.Crossing(n, 0.1, kind=k, sigma=0.5, ci=ci, below_floor=b)
                  for n, ci, b, k in zip(SIZES, cis, below, kinds)]
        sl._trend(s)
        return s.area_trend

    assert _with([(0.1, 0.2), (0.4, 0.5), (0.5, 0.6)]) == sl.STEADY        # touching
    assert _with([(0.1, 0.2), (0.5, 0.6), (0.4, 0.5)]) == sl.STEADY
    assert _with([(0.4, 0.5), (0.4, 0.5), (0.51, 0.6)]) == sl.DRIFTS
    assert _with([(0.4, 0.5), (0.61, 0.7), (0.5, 0.6)]) == sl.DRIFTS
    # the two largest usable ones: below the floor, not a bracket or no finite interval skip
    assert _with([(0.4, 0.5), (0.1, 0.2), (0.45, 0.6)], below=(False, True, False)) == sl.STEADY
    assert _with([(0.4, 0.5), (0.1, 0.2), (0.45, 0.6)],
                 kinds=(sl.BRACKET, sl.NO_LOSS, sl.BRACKET)) == sl.STEADY
    assert _with([(0.4, 0.5), (0.1, math.inf), (0.45, 0.6)]) == sl.STEADY
    assert _with([(0.4, 0.5), (math.nan, 0.2), (0.45, 0.6)]) == sl.STEADY
    assert _with([(0.4, 0.5), (0.1, 0.2), (0.45, 0.6)],
                 below=(True, True, False)) == sl.UNKNOWN


def test_an_extrapolation_needs_three_sizes_and_the_exponent_two_held_sigmas():
    two = sl.size_loss(1.0, _brushes(sizes=(8, 12)), st.PHI, n_boot=0)
    assert two.extrapolations == [] and two.sigma_inf_kind == sl.NOT_READ
    assert math.isnan(two.p) and two.p_sigmas == ()
    one_held = sl.size_loss(1.0, _brushes(sigmas=(0.2, 0.6, 0.8)), st.PHI, n_boot=0)
    assert one_held.p_sigmas == (0.2,) and math.isnan(one_held.p)
    assert one_held.p_state == sl.NOT_FITTED
    assert all(one_held.states[n][1:] == [LOST, LOST] for n in SIZES)
    # a sigma~ not run at one size is not extrapolated
    by_n = _brushes()
    del by_n[12][0.4]
    s = sl.size_loss(1.0, by_n, st.PHI, n_boot=0)
    assert [e.sigma_tilde for e in s.extrapolations] == [0.2, 0.5, 0.7]
    assert math.isnan(s.plateau[12][1]) and s.states[12][1] == ""
    assert s.p_sigmas == (0.2, 0.5) and math.isfinite(s.p)        # two sigma~: one dof


def test_no_loss_and_lost_everywhere():
    hold = sl.size_loss(1.0, _brushes(sigmas=(0.1, 0.2)), st.PHI, n_boot=0)
    assert hold.sigma_inf_kind == sl.NO_LOSS and math.isnan(hold.sigma_inf)
    assert hold.sigma_inf_bracket == (0.2, math.inf)
    assert all(c.kind == sl.NO_LOSS and c.bracket == (0.2, math.inf) for c in hold.few)
    gone = sl.size_loss(1.0, _brushes(sigmas=(0.7, 0.9), pillars=1.0), st.PHI, n_boot=0)
    assert gone.sigma_inf_kind == sl.ALL_LOST and gone.sigma_inf_bracket == (0.0, 0.7)
    assert all(c.kind == sl.ALL_LOST and c.bracket == (0.0, 0.7) for c in gone.few)
    empty = sl.size_loss(1.0, {8: {}}, st.PHI)
    assert empty.n_sides == () and empty.sigmas == () and empty.few == []


def test_size_losses_groups_by_k_descending():
    b1 = _brushes(sizes=(8, 12), sigmas=(0.2, 0.5))
    b2 = _brushes(sizes=(8, 12), sigmas=(0.2, 0.5), rng=9)
    by = {n: {**{(1.0, s): p for s, p in b1[n].items()},
              **{(0.01, s): p for s, p in b2[n].items()}} for n in (8, 12)}
    out = sl.size_losses(by, st.PHI, n_boot=0, area_threshold=0.2)
    assert list(out) == [1.0, 0.01]
    for k, b in ((1.0, b1), (0.01, b2)):
        alone = sl.size_loss(k, b, st.PHI, n_boot=0, area_threshold=0.2)
        assert out[k].k_tilde == k and out[k].area_threshold == 0.2
        for n in (8, 12):
            np.testing.assert_array_equal(out[k].plateau[n], alone.plateau[n])
        assert [c.sigma for c in out[k].area] == [c.sigma for c in alone.area]
        assert all(c.threshold == 0.2 for c in out[k].area)
    seeded = sl.size_losses(by, st.PHI, n_boot=NB, rng_seed=6)
    ref = sl.size_loss(1.0, b1, st.PHI, n_boot=NB, rng_seed=6)
    assert seeded[1.0].plateau_ci == ref.plateau_ci
    assert seeded[1.0].area_threshold == sl.AREA_THRESHOLD


def test_replicate_crossings_are_not_clipped():
    """A replicate that never falls to the threshold crosses at inf, one already below it at the
    first sigma~ at 0: the interval is then unbounded, or reaches 0, not the clipped bracket."""
    sig = (0.2, 0.4, 0.8)
    plat = np.array([1.0, 0.2, 0.05])
    reps = np.array([[1.0, 0.2, 0.05]] * 8 + [[1.0, 0.5, 0.3]] * 2)
    c = sl._crossing(8, sig, plat, reps, 0.1, 10)
    assert c.kind == sl.BRACKET and c.ci[1] == math.inf and c.ci[0] <= c.sigma
    reps = np.array([[1.0, 0.2, 0.05]] * 8 + [[0.05, 0.02, 0.01]] * 2)
    c = sl._crossing(8, sig, plat, reps, 0.1, 10)
    assert c.ci[0] == 0.0 and c.ci[1] >= c.sigma


def test_two_seeds_give_intervals_and_one_resample_none():
    s = sl.size_loss(1.0, _brushes(seeds=2), st.PHI, n_boot=NB)
    assert all(math.isfinite(v) for n in SIZES for ci in s.plateau_ci[n] for v in ci)
    assert all(e.state in (sl.HOLDS, sl.GONE) for e in s.extrapolations)
    one = sl.size_loss(1.0, _brushes(), st.PHI, n_boot=1)
    assert all(e.state == sl.UNKNOWN for e in one.extrapolations)
    assert all(math.isnan(v) for e in one.extrapolations for v in e.p_inf_ci)
    assert all(math.isnan(v) for v in one.sigma_inf_ci) and one.p_state == sl.NOT_FITTED


def test_a_sigma_missing_at_one_size_is_no_replicate_there():
    by_n = _brushes()
    del by_n[12][0.4]
    s = sl.size_loss(1.0, by_n, st.PHI, n_boot=NB, rng_seed=2)
    assert all(math.isnan(v) for v in s.plateau_ci[12][1])
    reps = _reps(by_n[12], SIG, pillar_floor(12, st.PHI), NB, 2 + 7919 * 12)
    want = [expanded(v, percentile_interval(reps[:, i]), 3) if math.isfinite(v) else (math.nan,
                                                                                       math.nan)
            for i, v in enumerate(s.plateau[12])]
    np.testing.assert_allclose(s.plateau_ci[12], want, rtol=1e-12)
    assert [e.sigma_tilde for e in s.extrapolations] == [0.2, 0.5, 0.7]


def test_no_loss_has_no_interval_even_with_resamples():
    hold = sl.size_loss(1.0, _brushes(sigmas=(0.1, 0.2)), st.PHI, n_boot=NB)
    assert hold.sigma_inf_kind == sl.NO_LOSS
    assert all(math.isnan(v) for v in hold.sigma_inf_ci + hold.sigma_zero_ci)

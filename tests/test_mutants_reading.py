"""laws.reading, pinned so that its one-line mutations fail (issue 34; benchmarks/mutation.py):
the levels (merging, thin levels, seed statistics), the plateau set's tolerance, the crossing's
interpolation, and every number of a reading checked against the module text's definitions on
groups whose seed means are known exactly, at the edges of each state."""

import math

import numpy as np
import pytest

from fibril_hpc.campaign.laws import reading as rd
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNDETERMINED, UNRESOLVED

PRE = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0]
DEV = (-0.02, 0.0, 0.02)                  # per-seed relative deviation: seed means are exact


def _group(curve, pre=PRE, dev=DEV, fp=None):
    """(seed, preload, F_P, F_A) with F_A = curve(F_P) (1 + dev[seed]); F_P = preload unless
    ``fp`` maps a preload to the reached F~_P."""
    rows = [(s, p, (fp or (lambda q: q))(p), curve((fp or (lambda q: q))(p)) * (1 + d))
            for s, d in enumerate(dev) for p in pre]
    return tuple(np.array(c) for c in zip(*rows))


def _log_cross(x0, y0, x1, y1, target):
    t = (target - y0) / (y1 - y0)
    return math.exp(math.log(x0) + t * math.log(x1 / x0))


def test_pillar_floor():
    assert rd.pillar_floor(18, 0.16) == pytest.approx(0.16 ** 0.25 / 18 ** 1.5, rel=1e-15)
    assert rd.pillar_floor(4, 1.0) == 0.125 and isinstance(rd.pillar_floor(4, 1), float)


# ------------------------------------------------------------------------------ levels
def test_levels_are_seed_statistics_per_requested_preload_sorted_by_force():
    seed = [0, 1, 0, 1, 2, 0]
    pre = [1.0, 1.0, 0.5, 0.5, 0.5, 2.0]
    fp = [1.1, 1.3, 0.6, 0.4, 0.5, 2.0]
    fa = [0.2, 0.4, 0.1, 0.3, 0.2, 0.9]
    lv = rd.levels(seed, pre, fp, fa)
    assert len(lv) == 3
    assert lv.preload.tolist() == [0.5, 1.0, 2.0]
    np.testing.assert_allclose(lv.F_P, [0.5, 1.2, 2.0], rtol=1e-12)
    np.testing.assert_allclose(lv.F_A, [0.2, 0.3, 0.9], rtol=1e-12)
    np.testing.assert_allclose(lv.sd[:2], [0.1, np.std([0.2, 0.4], ddof=1)], rtol=1e-12)
    assert math.isnan(lv.sd[2])                              # one seed: no sd
    assert lv.n.tolist() == [3, 2, 1] and lv.n.dtype.kind == "i"
    assert lv.lo.tolist() == [0.1, 0.2, 0.9] and lv.hi.tolist() == [0.3, 0.4, 0.9]
    assert lv.thin.tolist() == [False, True, True]
    sub = lv.subset([True, False, True])
    assert sub.preload.tolist() == [0.5, 2.0] and sub.n.tolist() == [3, 1] and len(sub) == 2
    assert lv.subset([1, 0, 1]).preload.tolist() == [0.5, 2.0]          # a mask, not indices


def test_levels_sort_by_reached_force_then_preload_and_drop_non_finite():
    lv = rd.levels([0, 0, 0, 0, 0], [1.0, 2.0, 3.0, np.nan, 4.0], [0.5, 0.5, 0.2, 1.0, np.inf],
                   [0.1, 0.2, 0.3, 0.4, 0.5])
    assert lv.preload.tolist() == [3.0, 1.0, 2.0] and lv.F_A.tolist() == [0.3, 0.1, 0.2]
    assert len(rd.levels([0], [1.0], [1.0], [np.nan])) == 0
    empty = rd.levels([], [], [], [])
    assert len(empty) == 0 and empty.n.dtype.kind == "i" and empty.thin.size == 0


def test_an_overshot_level_is_merged_into_the_next_only_when_every_seed_is_the_same():
    # preload 0.1 overshot to the 0.5 event in both seeds: the same point, merged
    seed, pre = [0, 1, 0, 1], [0.1, 0.1, 0.5, 0.5]
    lv = rd.levels(seed, pre, [0.5, 0.6, 0.5, 0.6], [0.2, 0.3, 0.2, 0.3])
    assert lv.preload.tolist() == [0.5] and lv.n.tolist() == [2]
    # one seed differs: two levels
    lv = rd.levels(seed, pre, [0.5, 0.6, 0.5, 0.6], [0.2, 0.3, 0.2, 0.31])
    assert lv.preload.tolist() == [0.1, 0.5]
    lv = rd.levels(seed, pre, [0.5, 0.55, 0.5, 0.6], [0.2, 0.3, 0.2, 0.3])
    assert lv.preload.tolist() == [0.1, 0.5]
    # other seeds at the next level: not the same point
    lv = rd.levels([0, 0, 1], [0.1, 0.5, 0.5], [0.5, 0.5, 0.6], [0.2, 0.2, 0.3])
    assert lv.preload.tolist() == [0.1, 0.5]
    # three levels, the first two the same as the third: both merged
    lv = rd.levels([0, 0, 0], [0.1, 0.2, 0.5], [0.5, 0.5, 0.5], [0.2, 0.2, 0.2])
    assert lv.preload.tolist() == [0.5]


def test_a_repeated_point_counts_once_and_a_conflicting_one_is_named():
    lv = rd.levels([0, 0, 1], [1.0, 1.0, 1.0], [1.0, 1.0, 2.0], [0.5, 0.5, 0.7])
    assert lv.n.tolist() == [2] and lv.F_A.tolist() == [0.6]
    with pytest.raises(ValueError) as e:
        rd.levels([0, 0], [1.0, 1.0], [1.0, 1.0], [0.5, 0.6])
    assert str(e.value) == ("two points at preload 1, seed 0 with different (F~_P, F~_A): (1, 0.5) "
                            "and (1, 0.6): points of different scenes in one group")


# ------------------------------------------------------------------------------ plateau set
def test_tolerances_pool_the_relative_sd_for_one_seed_levels():
    lv = rd.levels([0, 1, 0, 1, 0], [1, 1, 2, 2, 3], [1, 1, 2, 2, 3], [1.0, 3.0, 2.0, 2.0, 4.0])
    assert rd._tolerances(lv, 1) is None
    se = rd._tolerances(lv, 2)
    rel = [math.sqrt(2) / 2, 0.0]                    # sd/mean of the two-seed levels
    pooled = math.sqrt(np.mean(np.square(rel)))
    np.testing.assert_allclose(se, [math.sqrt(2) / math.sqrt(2), 0.0, pooled * 4.0], rtol=1e-12)
    # a level of mean 0 is left out of the pool; no two-seed level: pool 0
    lv = rd.levels([0, 1, 0, 1, 0], [1, 1, 2, 2, 3], [1, 1, 2, 2, 3], [-1.0, 1.0, 2.0, 4.0, 4.0])
    rel = [math.sqrt(2) / 3]
    np.testing.assert_allclose(rd._tolerances(lv, 2)[2], math.sqrt(np.mean(np.square(rel))) * 4,
                               rtol=1e-12)
    lv = rd.levels([0, 0], [1, 2], [1, 2], [1.0, 2.0])
    assert rd._tolerances(lv, 2).tolist() == [0.0, 0.0]


def test_plateau_set_with_one_seed_uses_the_path_tolerance():
    # one seed: 3 % of the set's mean
    fa = [0.1, 0.5, 0.97, 0.99, 1.0]
    lv = rd.levels([0] * 5, range(5), range(1, 6), fa)
    assert rd.plateau_set(lv, 1) == 2                         # 0.97 within 3 % of 0.995
    fa = [0.1, 0.5, 0.96, 0.99, 1.0]
    lv = rd.levels([0] * 5, range(5), range(1, 6), fa)
    assert rd.plateau_set(lv, 1) == 3
    # negative forces: the tolerance is of |P|
    lv = rd.levels([0] * 3, range(3), range(1, 4), [-2.0, -1.0, -1.01])
    assert rd.plateau_set(lv, 1) == 1


def test_plateau_set_with_seeds_uses_two_standard_errors_and_one_percent_at_least():
    # two seeds, sd 0.1 at every level: se 0.1/sqrt(2); a level 0.2 below the set is within
    # 2 hypot(se, se_set) = 2 * 0.0707 * sqrt(1 + 1/n_set)... but not 0.3 below
    def lv_of(means, sd=0.1):
        seed, pre, x, y = [], [], [], []
        for i, m in enumerate(means):
            for s, d in ((0, -sd / math.sqrt(2)), (1, sd / math.sqrt(2))):
                seed.append(s)
                pre.append(float(i + 1))
                x.append(float(i + 1))
                y.append(m + d)
        return rd.levels(seed, pre, x, y)

    se = 0.1 / math.sqrt(2)
    tol1 = 2 * math.hypot(se, se)                             # a set of one level: 0.2
    assert rd.plateau_set(lv_of([0.0, 1.0 - 0.99 * tol1, 1.0]), 2) == 1
    assert rd.plateau_set(lv_of([0.0, 1.0 - 1.01 * tol1, 1.0]), 2) == 2
    tol2 = 2 * math.hypot(se, math.sqrt(2 * se ** 2) / 2)      # a set of two levels
    assert rd.plateau_set(lv_of([0.0, 1.0 - 0.99 * tol2, 1.0, 1.0]), 2) == 1
    assert rd.plateau_set(lv_of([0.0, 1.0 - 1.01 * tol2, 1.0, 1.0]), 2) == 2
    # no scatter: 1 % of the plateau
    assert rd.plateau_set(lv_of([0.0, 0.991, 1.0], sd=0.0), 2) == 1
    assert rd.plateau_set(lv_of([0.0, 0.989, 1.0], sd=0.0), 2) == 2
    # a level above the set (not below) always joins
    assert rd.plateau_set(lv_of([0.0, 5.0, 1.0], sd=0.0), 2) == 1


def test_plateau_set_starts_at_the_largest_full_level():
    # seeds 0, 1 at every level; seed 1 alone at a last, larger one (thin)
    seed = [0, 1, 0, 1, 0, 1, 1]
    pre = [1, 1, 2, 2, 3, 3, 4]
    fa = [0.1, 0.1, 0.5, 0.5, 1.0, 1.0, 0.3]
    lv = rd.levels(seed, pre, pre, fa)
    assert lv.thin.tolist() == [False, False, False, True]
    assert rd.plateau_set(lv, 2) == 2                         # from level 2, not from the thin 3


# ------------------------------------------------------------------------------ crossing etc.
def test_crossing_interpolates_in_log_or_linear_force():
    lv = rd.levels([0] * 4, [1, 2, 3, 4], [0.1, 1.0, 10.0, 100.0], [0.1, 0.2, 0.6, 1.0])
    x, i = rd._crossing(lv, 0.4)
    assert i == 2 and x == pytest.approx(math.sqrt(10.0), rel=1e-12)       # halfway in log
    x, i = rd._crossing(lv, 0.4, log=False)
    assert i == 2 and x == pytest.approx(5.5, rel=1e-12)
    x, i = rd._crossing(lv, 0.6)
    assert i == 2 and x == pytest.approx(10.0, rel=1e-12)                  # reached exactly
    x, i = rd._crossing(lv, 0.15)
    assert i == 1 and x == pytest.approx(math.sqrt(0.1), rel=1e-12)
    x, i = rd._crossing(lv, 0.05)            # the smallest level is above: from level 1 on
    assert i == 1 and x == pytest.approx(0.1 * 10 ** -0.5, rel=1e-12)
    x, i = rd._crossing(lv, 2.0)
    assert math.isnan(x) and i == 4
    flat = rd.levels([0] * 3, [1, 2, 3], [1.0, 2.0, 4.0], [0.5, 0.5, 0.5])
    x, i = rd._crossing(flat, 0.5)
    assert (x, i) == (1.0, 1)                                # equal ends: the lower one
    zero = rd.levels([0] * 2, [1, 2], [0.0, 2.0], [0.0, 1.0])
    x, i = rd._crossing(zero, 0.5)
    assert (x, i) == (1.0, 1)                                # F~_P = 0: linear


def test_floor_levels_and_c0():
    lv = rd.levels([0] * 6, range(6), [1, 2, 4, 8, 16, 32], [0.96, 0.98, 1.0, 2.0, 4.0, 4.0])
    assert rd._floor_levels(lv, 4) == 2
    assert rd._floor_levels(lv, 2) == 1                       # stops below the plateau set
    assert rd._floor_levels(lv, 0) == 0
    lv2 = rd.levels([0] * 3, range(3), [1, 2, 4], [0.95, 1.0, 2.0])
    assert rd._floor_levels(lv2, 2) == 1                      # exactly 95 %
    # c0: geometric mean of F~_A/F~_P over the first quarter of the rise
    lv = rd.levels([0] * 5, range(5), [1, 2, 4, 8, 16], [0.1, 0.15, 0.325, 0.5, 1.0])
    # quarter = 0.1 + 0.25 * 0.9 = 0.325: levels 0, 1, 2
    want = math.exp(np.mean(np.log([0.1 / 1, 0.15 / 2, 0.325 / 4])))
    assert rd._c0(lv, 1.0) == pytest.approx(want, rel=1e-12)
    assert rd._c0(lv, 0.1) == pytest.approx(0.1, rel=1e-12)   # only the smallest
    neg = rd.levels([0] * 3, range(3), [1, 2, 4], [0.0, 0.1, 1.0])
    assert rd._c0(neg, 1.0) == pytest.approx(0.05, rel=1e-12)   # F~_A = 0 left out
    assert math.isnan(rd._c0(rd.levels([0] * 2, range(2), [0, 2], [0.0, 1.0]), 1.0))


def test_path_plateau_reached():
    assert rd.path_plateau_reached([1, 2, 4], [0.5, 1.0, 1.03 / 1.0])
    assert rd.path_plateau_reached([1, 2], [1.0, 1.0309])                # 3 % of the last
    assert not rd.path_plateau_reached([1, 2], [1.0, 1.031])
    assert rd.path_plateau_reached([2, 1], [1.0, 1.01])          # sorted by F~_P
    assert rd.path_plateau_reached([1, 2], [1.0, 1.1], rtol=0.1)
    assert rd.path_plateau_reached([1, 2, np.nan], [1.0, 1.0, 5.0])
    assert not rd.path_plateau_reached([1], [1.0]) and not rd.path_plateau_reached([], [])
    assert not rd.path_plateau_reached([1, 2], [1.0, np.inf])
    assert rd.path_plateau_reached([1, 2], [-1.0, -1.02])        # of |F~_A|
    assert not rd.path_plateau_reached([1, 2, 4], [1.0, 1.0, 2.0])   # the last two points
    assert rd.path_plateau_reached([1, 2], [1.0, 2.0], rtol=0.5)     # 2 <= 1 + 0.5 x 2


# ------------------------------------------------------------------------------ read_group
def test_a_resolved_rise_every_number_by_its_definition():
    r = rd.read_group(*_group(lambda x: min(x, 1.0)), floor=0.001)
    assert r.state == RESOLVED and r.rises and r.plateau_state == "reached"
    assert r.plateau == 1.0 and r.plateau_from == 1.0 and r.n_plateau == 3 and r.n_rise == 4
    assert r.n_levels == 7 and r.n_seeds == 3 and r.seeds == (3,) * 7 and r.floor == 0.001
    assert (r.F_P0, r.F_A0) == (0.01, 0.01)
    xh = _log_cross(0.3, 0.3, 1.0, 1.0, 0.5)
    assert r.F_P_half == pytest.approx(xh, rel=1e-12) and r.c == pytest.approx(0.5 / xh, rel=1e-12)
    assert r.c_res == pytest.approx(abs(0.5 / xh - 0.5 / 0.5), rel=1e-12)
    assert r.c_stage == pytest.approx(1.0, rel=1e-12) and r.n_stage == 4
    yc = 0.01 + 0.5 * (1.0 - 0.01)
    assert r.c_chord == pytest.approx((yc - 0.01) / (_log_cross(0.3, 0.3, 1.0, 1.0, yc) - 0.01),
                                      rel=1e-12)
    # c0: the levels up to a quarter of the rise (0.01 + 0.2475): 0.01, 0.03, 0.1
    assert r.c0 == pytest.approx(1.0, rel=1e-12)
    assert r.c_detect == pytest.approx(0.04 / (10 - 0.01), rel=1e-12)        # the seed spread
    assert (r.top_lo, r.top_hi) == (0.98, 1.02)
    assert math.isnan(r.c_lower) and math.isnan(r.resolve_below) and r.notes == []
    assert r.c_notes == ["the half point lies between preloads 0.3 and 1 (x 3.3 apart): c is "
                         "resolved to that factor at worst; preloads between them would refine it"]
    # the half fraction of the chord is a parameter
    r3 = rd.read_group(*_group(lambda x: min(x, 1.0)), floor=0.001, half=0.25)
    yc = 0.01 + 0.25 * 0.99
    assert r3.c_chord == pytest.approx((yc - 0.01) / (_log_cross(0.1, 0.1, 0.3, 0.3, yc) - 0.01),
                                       rel=1e-12)
    assert r3.c == r.c


def test_the_stage_leaves_out_the_first_contact_floor_and_the_few_pillars():
    # F~_A sits at 0.05 for the two smallest preloads (first-contact floor), then rises as 2 x
    curve = lambda x: min(max(0.05, 2 * x), 1.0)   # noqa: E731
    pre = [0.001, 0.01, 0.05, 0.1, 0.2, 0.4, 1.0, 3.0]
    r = rd.read_group(*_group(curve, pre), floor=0.001)
    assert r.state == RESOLVED
    # stage: levels from the floor's last (the first is left out) to below the half point,
    # with 3 floors < F~_A <= P/2
    lv_x = np.array([0.01, 0.05, 0.1, 0.2])
    lv_y = np.array([0.05, 0.1, 0.2, 0.4])
    assert r.n_stage == 4 and r.c_stage == pytest.approx(np.sum(lv_x * lv_y) / np.sum(lv_x ** 2))
    assert "c0 read on the first-contact floor" in " ".join(r.c_notes)
    # a floor of 3 pillars above the first contact's F~_A leaves it out of the stage
    r = rd.read_group(*_group(curve, pre), floor=0.02)
    assert r.n_stage == 3 and r.c_stage == pytest.approx(2.0)
    # no floor: as with a small one
    r = rd.read_group(*_group(curve, pre))
    assert r.n_stage == 4 and r.state == RESOLVED


def test_a_half_point_at_an_exact_level_and_fine_spacing_has_no_coarse_note():
    pre = [0.1, 0.2, 0.4, 0.5, 0.8, 1.6, 3.2]
    r = rd.read_group(*_group(lambda x: min(x, 1.0), pre), floor=0.001)
    assert r.F_P_half == pytest.approx(0.5) and r.c == pytest.approx(1.0) and r.c_res == 0
    assert r.c_notes == []
    pre = [0.1, 0.2, 0.4, 0.99, 1.6, 3.2]                    # 0.4 .. 0.99: x 2.475, fine
    r = rd.read_group(*_group(lambda x: min(x, 1.0), pre), floor=0.001)
    assert not any("half point lies" in n for n in r.c_notes)
    pre = [0.1, 0.2, 0.4, 1.01, 1.6, 3.2]                    # x 2.525: coarse
    r = rd.read_group(*_group(lambda x: min(x, 1.0), pre), floor=0.001)
    assert any("half point lies between preloads 0.4 and 1.01" in n for n in r.c_notes)


def test_a_plateau_not_reached_is_a_lower_bound():
    r = rd.read_group(*_group(lambda x: min(x, 100.0)), floor=0.001)
    assert r.plateau_state == "not reached" and r.n_plateau == 1 and r.plateau == 10.0
    assert r.plateau_from == 10.0 and r.n_rise == 6 and r.state == RESOLVED
    assert r.notes == [("plateau not reached: F~_A still rises from 3 at F~_P = 3 to 10 at 10; "
                        "the plateau is a lower bound and c is provisional")]
    assert r.c_notes[0] == r.notes[0]


def test_an_unresolved_rise_and_which_preloads_would_resolve_it():
    curve = lambda x: min(0.6 + 0.1 * x, 1.0)   # noqa: E731   # 60 % of the plateau at once
    r = rd.read_group(*_group(curve), floor=0.001)
    assert r.state == UNRESOLVED and not r.rises
    assert math.isnan(r.c) and math.isnan(r.F_P_half) and r.c_lower == pytest.approx(0.601 / 0.01)
    assert r.resolve_below == pytest.approx(0.001) and r.plateau == 1.0
    assert r.plateau_from == 10.0 and r.n_rise == 6 and r.plateau_state == "not reached"
    assert r.c0 == pytest.approx(rd._c0(rd.levels(*_group(curve)), 1.0), rel=1e-12)
    assert any(n.startswith("rise not resolved: F~_A = 0.601 at the smallest preload F~_P = 0.01 "
                            "is already 60% of the plateau 1; c >= 60.1 (a lower bound, out of "
                            "the fit); preloads at or below 0.001") for n in r.c_notes)
    # exactly half the plateau at the smallest level: not resolved
    r = rd.read_group(*_group(lambda x: min(0.5 + x, 1.0), pre=[0.001, 0.1, 0.3, 0.5, 1, 2]),
                      floor=0.001)
    assert r.F_A0 == pytest.approx(0.501)
    r = rd.read_group(*_group(lambda x: 0.5 if x < 0.05 else 1.0, pre=[0.01, 0.1, 1.0, 2.0]),
                      floor=0.001)
    assert r.state == UNRESOLVED


def test_an_overshot_first_contact_says_no_smaller_preload_is_reachable():
    # every preload below 0.2 reached 0.2 at first contact (different F~_A per preload: kept)
    pre = [0.01, 0.02, 0.1, 0.3, 1.0, 3.0]
    fp = lambda p: max(p, 0.2)   # noqa: E731
    seed, p, x, y = _group(lambda v: min(0.7 + v, 1.0), pre, fp=fp)
    y = y * (1 + 1e-3 * np.arange(y.size) % 3)                 # not the same event's numbers
    r = rd.read_group(seed, p, x, y, floor=0.001)
    assert r.state == UNRESOLVED and math.isnan(r.resolve_below)
    assert any("the first contact overshot the smallest preload asked for (0.01) to F~_P = 0.2"
               in n for n in r.c_notes)
    # reached within 1.5 x of the asked preload: not an overshoot
    seed, p, x, y = _group(lambda v: min(0.7 + v, 1.0), pre, fp=lambda q: q * 1.5)
    r = rd.read_group(seed, p, x, y, floor=0.001)
    assert r.resolve_below == pytest.approx(0.0015)


def test_a_lost_group_is_c_zero_with_its_creep_as_the_uncertainty():
    floor = 0.01
    # creeps from one pillar to 2.5 pillars: lost, the half point's secant is c_res
    curve = lambda x: min(max(floor, 0.5 * x), 2.5 * floor)   # noqa: E731
    pre = [0.001, 0.01, 0.02, 0.04, 0.08, 0.16]
    r = rd.read_group(*_group(curve, pre), floor=floor)
    assert r.state == LOST and r.c == 0.0 and r.c0 == 0.0 and r.c_stage == 0.0 and r.c_chord == 0.0
    P = r.plateau
    assert P == pytest.approx(2.5 * floor) and r.n_rise == 0
    xh = _log_cross(0.02, 0.01, 0.04, 0.02, 0.5 * P)
    assert r.c_res == pytest.approx(0.5 * P / xh, rel=1e-12)
    assert r.notes[-1].startswith("adhesion lost: plateau F~_A = 0.025, within 3 pillars' pull-off "
                                  "(0.03; one pillar: 0.01); it creeps from 0.01 (a secant of ")
    assert r.c_notes == r.notes and r.plateau_from == 0.001 and r.F_P0 == 0.001
    assert r.c_detect == pytest.approx(max(2 * 0.02 * 2.5 * floor, 0.01 * P) / (0.16 - 0.001))
    # flat at one pillar: no creep, no c_res
    r = rd.read_group(*_group(lambda x: floor, pre), floor=floor)
    assert r.state == LOST and math.isnan(r.c_res) and r.plateau_state == "no rise"
    assert r.notes[-1].endswith("(0.03; one pillar: 0.01)")
    # exactly three pillars: still lost; a little more: not
    r = rd.read_group(*_group(lambda x: 3 * floor, pre, dev=(0.0, 0.0)), floor=floor)
    assert r.state == LOST
    r = rd.read_group(*_group(lambda x: 3.01 * floor, pre, dev=(0.0, 0.0)), floor=floor)
    assert r.state == UNRESOLVED


def test_without_a_floor_a_flat_group_is_undetermined_and_with_one_unresolved():
    pre = [0.01, 0.1, 1.0]
    r = rd.read_group(*_group(lambda x: 0.5, pre))
    assert r.state == UNDETERMINED and r.plateau_state == "no rise" and math.isnan(r.floor)
    assert r.notes == ["F~_A does not rise with preload over F~_P = 0.01 .. 1 (within the seed "
                       "scatter)"]
    assert r.c_notes == ["F~_A does not rise and no pillar floor was given: adhesion lost and a "
                         "rise below the smallest preload cannot be told apart"]
    assert r.c_lower == pytest.approx(50.0)
    r = rd.read_group(*_group(lambda x: 0.5, pre), floor=0.001)
    assert r.state == UNRESOLVED and r.plateau_from == 0.01 and r.n_rise == 0


def test_one_seed_uses_the_path_tolerance_and_no_spread():
    r = rd.read_group(*_group(lambda x: min(x, 1.0), dev=(0.0,)), floor=0.001)
    assert r.n_seeds == 1 and r.state == RESOLVED
    assert r.c_detect == pytest.approx(0.03 / (10 - 0.01), rel=1e-12)
    assert r.plateau_from == 1.0


def test_one_level_and_no_data():
    r = rd.read_group([0, 1], [1.0, 1.0], [1.0, 1.0], [0.5, 0.6], floor=0.001)
    assert r.plateau_state == "not reached" and r.n_levels == 1 and math.isnan(r.c)
    assert r.plateau == pytest.approx(0.55) and (r.top_lo, r.top_hi) == (0.5, 0.6)
    assert r.notes == ["one preload level: no rise or plateau can be read"] == r.c_notes
    assert r.state == UNDETERMINED and r.n_seeds == 2 and r.seeds == (2,)
    r = rd.read_group([0], [1.0], [np.nan], [0.5], floor=0.001)
    assert r.plateau_state == "no data" and r.notes == ["no finite F~_P, F~_A"] and r.n_seeds == 1
    assert math.isnan(r.plateau) and r.n_levels == 0 and r.state == UNDETERMINED
    assert r.n_plateau == 0 and r.n_rise == 0 and r.floor == 0.001
    for name in ("plateau_from", "c", "c0", "F_P0", "F_A0", "F_P_half", "c_detect", "top_lo",
                 "top_hi"):
        assert math.isnan(getattr(r, name)), name


def test_thin_levels_are_shown_but_not_read_while_two_full_ones_remain():
    seed, pre, x, y = _group(lambda v: min(v, 1.0), pre=[0.01, 0.1, 0.3, 1.0, 3.0])
    # seed 2 alone at an extra preload in the rise, far off the others' curve
    seed = np.append(seed, 2)
    pre = np.append(pre, 0.5)
    x = np.append(x, 0.5)
    y = np.append(y, 0.05)
    r = rd.read_group(seed, pre, x, y, floor=0.001)
    assert r.notes[0] == ("1 level(s) with fewer seeds than the group's 3 (F~_P = 0.5: 1): shown, "
                          "not read (a seed mean over other seeds is not comparable)")
    assert r.n_levels == 5 and r.seeds == (3, 3, 3, 1, 3, 3) and r.state == RESOLVED
    ref = rd.read_group(*_group(lambda v: min(v, 1.0), pre=[0.01, 0.1, 0.3, 1.0, 3.0]), floor=0.001)
    assert r.c == ref.c and r.plateau == ref.plateau
    # only one full level left: the thin ones are read
    r = rd.read_group([0, 1, 0], [1.0, 1.0, 2.0], [1.0, 1.0, 2.0], [0.5, 0.5, 1.0], floor=0.001)
    assert r.n_levels == 2 and r.seeds == (2, 1)


# ------------------------------------------------------------------------------ every field
def _same(r, **want):
    """Every field named, NaN-aware and type-strict (a count is an int, a number a float)."""
    for k, v in want.items():
        got = getattr(r, k)
        if isinstance(v, float) and math.isnan(v):
            assert isinstance(got, float) and math.isnan(got), (k, got)
        elif isinstance(v, float):
            assert isinstance(got, float) and got == pytest.approx(v, rel=1e-12), (k, got, v)
        else:
            assert got == v and type(got) is type(v), (k, got, v)


NAN = math.nan


def test_every_field_of_a_one_level_reading():
    r = rd.read_group([0, 1], [1.0, 1.0], [1.0, 1.0], [0.5, 0.6], floor=0.001)
    _same(r, plateau=0.55, plateau_state="not reached", plateau_from=1.0, n_plateau=1, c=NAN,
          c0=NAN, F_P0=1.0, F_A0=0.55, F_P_half=NAN, c_detect=NAN, n_levels=1, n_rise=0,
          top_lo=0.5, top_hi=0.6, state=UNDETERMINED, floor=0.001, seeds=(2,), n_seeds=2,
          c_lower=NAN, c_res=NAN, c_stage=NAN, c_chord=NAN, n_stage=0, resolve_below=NAN)


def test_every_field_of_a_lost_reading_and_its_creep_note():
    floor = 0.01
    curve = lambda x: min(max(floor, 0.5 * x), 2.5 * floor)   # noqa: E731
    pre = [0.001, 0.01, 0.02, 0.04, 0.08, 0.16]
    r = rd.read_group(*_group(curve, pre, dev=(-0.01, 0.01)), floor=floor)
    xh = _log_cross(0.02, 0.01, 0.04, 0.02, 0.5 * 0.025)
    _same(r, plateau=0.025, plateau_state="reached", plateau_from=0.001, n_plateau=2, c=0.0, c0=0.0,
          F_P0=0.001, F_A0=0.01, F_P_half=NAN, n_levels=6, n_rise=0, top_lo=0.99 * 0.025,
          top_hi=1.01 * 0.025, state=LOST, floor=floor, seeds=(2,) * 6, n_seeds=2, c_stage=0.0,
          c_chord=0.0, c_res=0.5 * 0.025 / xh, c_lower=NAN, n_stage=0, resolve_below=NAN)
    assert r.c_detect == pytest.approx(0.02 * 0.025 / (0.16 - 0.001), rel=1e-12)
    assert r.notes == [f"adhesion lost: plateau F~_A = 0.025, within 3 pillars' pull-off (0.03; one "
                       f"pillar: 0.01); it creeps from 0.01 (a secant of {0.0125 / xh:.3g} through "
                       "its half point: how loosely its c = 0 holds)"] == r.c_notes
    # exactly half the plateau at the smallest preload: no creep below half, no c_res
    r = rd.read_group(*_group(lambda x: 0.01 if x < 0.005 else 0.02, pre, dev=(0.0, 0.0)),
                      floor=floor)
    assert r.state == LOST and r.F_A0 == 0.5 * r.plateau and math.isnan(r.c_res)
    assert r.notes[-1].endswith("(0.03; one pillar: 0.01)")


def test_every_field_of_an_unresolved_reading_and_its_notes():
    curve = lambda x: min(1.2 + 0.2 * x, 2.0)   # noqa: E731    # 60 % of a plateau of 2 at once
    r = rd.read_group(*_group(curve), floor=0.001)
    lv = rd.levels(*_group(curve))
    _same(r, plateau=2.0, plateau_state="not reached", plateau_from=10.0, n_plateau=1, c=NAN,
          c0=rd._c0(lv, 2.0), F_P0=0.01, F_A0=1.202, F_P_half=NAN, n_levels=7, n_rise=6,
          top_lo=0.98 * 2, top_hi=1.02 * 2, state=UNRESOLVED, floor=0.001, seeds=(3,) * 7,
          n_seeds=3, c_lower=120.2, resolve_below=0.001, c_res=NAN, c_stage=NAN, c_chord=NAN,
          n_stage=0)
    assert r.c_detect == pytest.approx(0.08 / (10 - 0.01), rel=1e-12)
    assert r.c_notes[-1] == ("rise not resolved: F~_A = 1.2 at the smallest preload F~_P = 0.01 is "
                             "already 60% of the plateau 2; c >= 120 (a lower bound, out of the "
                             "fit); preloads at or below 0.001 (a tenth of the smallest reached) "
                             "would resolve it")
    # the overshot first contact
    pre = [0.01, 0.02, 0.1, 0.3, 1.0, 3.0]
    seed, p, x, y = _group(lambda v: min(1.4 + v, 2.0), pre, fp=lambda q: max(q, 0.2))
    y = y * (1 + 1e-3 * (np.arange(y.size) % 3))
    r = rd.read_group(seed, p, x, y, floor=0.001)
    assert r.c_notes[-1].endswith("; the first contact overshot the smallest preload asked for "
                                  "(0.01) to F~_P = 0.2: the brush saturates at first contact, no "
                                  "smaller preload is reachable on this scene")
    # a zero preload asked for is not an overshoot; F~_P = 0 reached: no lower bound of c
    r = rd.read_group(*_group(curve, [0.0, 0.1, 1.0, 10.0]), floor=0.001)
    assert r.state == UNRESOLVED and math.isnan(r.c_lower) and r.resolve_below == 0.0
    r = rd.read_group(*_group(curve, [0.0, 0.1, 1.0, 10.0], fp=lambda q: max(q, 0.05)),
                      floor=0.001)
    assert r.resolve_below == pytest.approx(0.005)


def test_a_resolved_rise_with_a_plateau_of_two_and_one_level_below_it():
    r = rd.read_group(*_group(lambda x: min(x, 2.0), [0.1, 2.0, 4.0, 8.0]), floor=0.001)
    xh = _log_cross(0.1, 0.1, 2.0, 2.0, 1.0)
    assert r.state == RESOLVED and r.n_rise == 1 and r.plateau == 2.0
    assert r.F_P_half == pytest.approx(xh, rel=1e-12) and r.c == pytest.approx(1.0 / xh, rel=1e-12)
    assert r.c_res == pytest.approx(abs(1.0 / xh - 1.0 / (0.1 + (0.9 / 1.9) * 1.9)), rel=1e-12)


def test_the_stage_starts_above_three_pillars_exactly():
    # floor 0.25: three pillars are 0.75, a level exactly there is not on the stage
    r = rd.read_group(*_group(lambda x: min(x, 4.0), [0.5, 0.75, 1.0, 1.5, 4.0, 8.0],
                              dev=(0.0, 0.0)), floor=0.25)
    assert r.state == RESOLVED and r.n_stage == 2
    assert r.c_stage == pytest.approx(1.0)


def test_the_detection_limit_with_two_seeds_and_equal_forces():
    # two seeds: the seeds' spread and the 1 % tolerance, not the one-path 3 %
    r = rd.read_group(*_group(lambda x: min(x, 1.0), dev=(0.0, 0.0)), floor=0.001)
    assert r.c_detect == pytest.approx(0.01 / (10 - 0.01), rel=1e-12)
    r = rd.read_group(*_group(lambda x: min(x, 1.0), dev=(-0.05, 0.05)), floor=0.001)
    assert r.c_detect == pytest.approx(0.1 / (10 - 0.01), rel=1e-12)
    # two levels reached at the same F~_P: no span, no detection limit
    r = rd.read_group([0, 0], [0.1, 1.0], [1.0, 1.0], [0.4, 0.5], floor=0.001)
    assert r.n_levels == 2 and math.isnan(r.c_detect)


def test_thin_levels_two_of_them_and_exactly_two_full_levels():
    seed = [0, 1, 0, 1, 0, 1]
    pre = [0.1, 0.1, 1.0, 1.0, 0.3, 0.5]
    r = rd.read_group(seed, pre, pre, [0.1, 0.1, 1.0, 1.0, 0.02, 0.9], floor=0.001)
    assert r.notes[0].startswith("2 level(s) with fewer seeds than the group's 2 (F~_P = 0.3: 1, "
                                 "0.5: 1): shown")
    assert r.n_levels == 2 and r.state == RESOLVED
    # one full level and a thin one above it: the plateau is the full level's
    r = rd.read_group([0, 1, 0], [1.0, 1.0, 2.0], [1.0, 1.0, 2.0], [0.5, 0.6, 1.0], floor=0.001)
    assert r.plateau == pytest.approx(0.55) and (r.top_lo, r.top_hi) == (0.5, 0.6)


def test_levels_are_floats_whatever_the_inputs():
    lv = rd.levels([0, 0, 1], [1, 2, 2], [1, 2, 3], [1, 2, 4])
    for name in ("preload", "F_P", "F_A", "sd", "lo", "hi"):
        assert getattr(lv, name).dtype == np.float64, name
    assert lv.preload.tolist() == [1.0, 2.0]


def test_a_merged_level_is_compared_with_the_next_not_the_previous():
    # the first two levels are one event; the third differs: levels 0.5 and 2
    lv = rd.levels([0, 0, 0], [0.1, 0.5, 2.0], [0.5, 0.5, 2.0], [0.2, 0.2, 0.9])
    assert lv.preload.tolist() == [0.5, 2.0]


def test_plateau_set_tolerances_scale_with_the_plateau_and_are_strict():
    lv = rd.levels([0] * 3, range(3), range(1, 4), [1.0, 9.75, 10.0])
    assert rd.plateau_set(lv, 1) == 1                 # 3 % of 10 is 0.3
    lv = rd.levels([0] * 3, range(3), range(1, 4), [1.0, 9.65, 10.0])
    assert rd.plateau_set(lv, 1) == 2
    # two seeds without scatter: 1 % of 100 is 1, and a level exactly 1 below joins
    lv = rd.levels([0, 1] * 3, [1, 1, 2, 2, 3, 3], [1, 1, 2, 2, 3, 3],
                   [0.0, 0.0, 99.0, 99.0, 100.0, 100.0])
    assert rd.plateau_set(lv, 2) == 1


def test_c0_runs_to_the_last_level_and_skips_a_zero_force():
    lv = rd.levels([0] * 3, range(3), [1, 2, 4], [0.1, 0.15, 0.2])
    want = math.exp(np.mean(np.log([0.1 / 1, 0.15 / 2, 0.2 / 4])))
    assert rd._c0(lv, 1.0) == pytest.approx(want, rel=1e-12)
    lv = rd.levels([0] * 3, range(3), [0, 1, 2], [0.1, 0.2, 1.0])
    assert rd._c0(lv, 1.0) == pytest.approx(0.2, rel=1e-12)


def test_c0_notes_and_the_coarse_half_point_at_its_edges():
    # c0 undefined: no force in the first quarter of the rise
    r = rd.read_group(*_group(lambda x: 0.0 if x < 0.2 else min(2 * x, 1.0)), floor=0.0001)
    assert r.state == RESOLVED and math.isnan(r.c0)
    assert r.c_notes[0] == "c0 undefined: F~_A or F~_P <= 0 at the smallest preload"
    # the first-contact floor, exactly 95 % of the next level
    r = rd.read_group(*_group(lambda x: {1.0: 19.0, 2.0: 20.0, 4.0: 40.0}.get(x, 100.0),
                              [1.0, 2.0, 4.0, 8.0, 16.0], dev=(0.0, 0.0)), floor=0.001)
    assert r.state == RESOLVED
    assert r.c_notes[0] == ("c0 read on the first-contact floor (F~_A hardly changes between the "
                            "two smallest preloads): a ratio F~_A/F~_P that grows as the preload "
                            "shrinks")
    # the half point between the two smallest levels (x 20 apart), and between the last two
    r = rd.read_group(*_group(lambda x: min(x, 2.0), [0.1, 2.0, 4.0, 8.0]), floor=0.001)
    assert r.c_notes[-1].startswith("the half point lies between preloads 0.1 and 2 (x 20 apart)")
    r = rd.read_group([0, 0, 0], [0.1, 0.2, 1.0], [0.1, 0.2, 1.0], [0.1, 0.2, 1.0], floor=0.001)
    assert r.plateau_state == "not reached" and r.state == RESOLVED
    assert r.c_notes[-1].startswith("the half point lies between preloads 0.2 and 1 (x 5 apart)")
    # exactly x 2.5: not coarse
    r = rd.read_group(*_group(lambda x: min(x, 1.0), [0.1, 0.2, 0.4, 1.0, 2.0], dev=(0.0, 0.0)),
                      floor=0.001)
    assert r.state == RESOLVED and not any("half point lies" in n for n in r.c_notes)
    # a level at F~_P = 0 below the half point: no ratio to judge
    r = rd.read_group([0, 0, 0], [0.0, 1.0, 2.0], [0.0, 1.0, 2.0], [0.1, 1.0, 1.0], floor=0.001)
    assert r.state == RESOLVED and not any("half point lies" in n for n in r.c_notes)


def test_a_rise_without_a_stage_has_no_stage_slope():
    r = rd.read_group(*_group(lambda x: min(x, 1.0), [0.1, 0.2, 0.4, 0.5, 0.8, 1.6, 3.2]),
                      floor=0.2)
    assert r.state == RESOLVED and r.n_stage == 0
    assert isinstance(r.c_stage, float) and math.isnan(r.c_stage)


def test_a_chord_of_no_length_is_undefined():
    r = rd.read_group(*_group(lambda x: min(0.1 * x, 1.0), [1.0, 2.0, 4.0, 8.0, 16.0]),
                      floor=0.001, half=0.0)
    assert r.state == RESOLVED and math.isnan(r.c_chord)

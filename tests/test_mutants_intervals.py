"""laws.intervals, pinned so that its one-line mutations fail (issue 34, item 6;
benchmarks/mutation.py): the preset bias and its reasons, the seed bootstrap over labels, the
paired bootstrap against a reconstruction from its docstring (one draw from the union of the
sets per replicate, each group taking the drawn labels it holds, a redraw of its own below two),
the percentile interval with unbounded and undefined replicates (an end interpolated towards an
unbounded replicate is unbounded), the small-sample factor against Student t, the widening, the
replicates' sd and which error dominates."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from fibril_hpc.campaign.laws import intervals as iv


# ---------------------------------------------------------------- preset bias

def test_each_preset_has_its_measured_bias_at_its_own_resolution():
    assert iv.PRESET_BIAS == {"fast": -0.036, "default": 0.009, "accurate": 0.013}
    for preset, epd in [("fast", 6), ("default", 8), ("accurate", 16)]:
        b, why = iv.preset_bias(preset, epd)
        assert b == iv.PRESET_BIAS[preset]
        assert why == (f"preset {preset}: F~_A {100 * b:+.1f} % against the converged "
                       "reference of the default scene")
        assert iv.preset_bias(preset, None)[0] == b
        assert iv.preset_bias(preset, epd * (1 + 1e-12))[0] == b
    b, why = iv.preset_bias("default", 12)
    assert math.isnan(b)
    assert why == ("elements_per_diameter 12 is not the default preset's 8: no measured "
                   "discretisation bias")
    b, why = iv.preset_bias("huge", 8)
    assert math.isnan(b) and why == "preset 'huge': no measured discretisation bias"


# ---------------------------------------------------------------- seed_replicates

def test_seed_replicates_resample_the_distinct_labels():
    assert iv.seed_replicates([3], lambda s: [1.0], 10) is None
    assert iv.seed_replicates([3, 3, 3], lambda s: [1.0], 10) is None
    assert iv.seed_replicates([3, 4], lambda s: [1.0], 0) is None
    seen = []

    def stat(picked):
        seen.append(np.asarray(picked).copy())
        return [float(np.min(picked)), float(np.max(picked)), math.inf]

    r = iv.seed_replicates([30, 10, 20, 10], stat, 40, rng_seed=3)
    assert r.shape == (3, 40)
    assert set(np.unique(r[:2])) <= {10.0, 20.0, 30.0} and np.all(r[2] == math.inf)
    assert all(p.size == 3 and set(p.tolist()) <= {10, 20, 30} for p in seen)
    assert len({tuple(sorted(p.tolist())) for p in seen}) > 3
    one = iv.seed_replicates([1, 2], lambda s: float(np.mean(s)), 1)
    assert one.shape == (1, 1)
    a = iv.seed_replicates([1, 2, 3, 4], lambda s: float(np.mean(s)), 30, rng_seed=5)
    b = iv.seed_replicates([1, 2, 3, 4], lambda s: float(np.mean(s)), 30, rng_seed=5)
    c = iv.seed_replicates([1, 2, 3, 4], lambda s: float(np.mean(s)), 30)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    d = iv.seed_replicates([1, 2, 3, 4], lambda s: float(np.mean(s)), 30, rng_seed=0)
    assert np.array_equal(c, d)
    # numpy's floating-point errors of the statistic are ignored, whatever the caller's setting
    with np.errstate(all="raise"):
        r = iv.seed_replicates([1, 2, 3], lambda s: np.float64(1.0) / (np.float64(s[0]) - 1), 20)
    assert np.isinf(r).any()


# ---------------------------------------------------------------- paired_replicates

def _paired_by_hand(sets, n_boot, rng_seed):
    sets = [np.asarray(sorted(set(s))) for s in sets]
    union = np.asarray(sorted(set().union(*(s.tolist() for s in sets))))
    rng = np.random.default_rng(rng_seed)
    out = []
    for _ in range(n_boot):
        drawn = union[rng.integers(0, union.size, union.size)]
        picks = []
        for s in sets:
            mine = np.array([d for d in drawn if d in set(s.tolist())], dtype=union.dtype)
            if mine.size < min(2, s.size):
                mine = s[rng.integers(0, s.size, s.size)]
            picks.append(mine)
        out.append(picks)
    return out


def test_paired_replicates_draw_once_from_the_union_and_each_group_takes_its_labels():
    sets = [[0, 1, 2, 3, 4, 5, 6, 7, 8, 9], [0, 1, 2], [7], [4, 5, 5]]
    got = []

    def stat(picks):
        got.append([p.copy() for p in picks])
        return [len(p) for p in picks] + [math.nan]

    r = iv.paired_replicates(sets, stat, 60, rng_seed=11)
    want = _paired_by_hand(sets, 60, 11)
    assert r.shape == (5, 60) and np.all(np.isnan(r[4]))
    for g, w in zip(got, want):
        assert len(g) == 4
        for a, b in zip(g, w):
            assert np.array_equal(a, b)
    # the full group takes every draw; the one-seed group always its seed
    assert np.all(r[0] == 10)
    assert all(len(g[2]) >= 1 and set(g[2].tolist()) == {7} for g in got)
    assert {len(g[2]) for g in got} >= {1, 2}
    # the three-seed group: its own labels, at least two, a binomial number of them
    assert all(len(g[1]) >= 2 and set(g[1].tolist()) <= {0, 1, 2} for g in got)
    assert len(set(r[1].tolist())) > 2
    # a redraw happened (fewer than two of 0-2 drawn) and was its own resample of three
    assert any(len(g[1]) == 3 and not set(g[1].tolist()) <= set(g[0].tolist()) for g in got)


def test_groups_with_the_same_seeds_get_the_same_multiset():
    r = iv.paired_replicates([[1, 2, 3, 4], [4, 3, 2, 1]],
                             lambda p: [float(np.sum(p[0])), float(np.sum(p[1]))], 50)
    assert np.array_equal(r[0], r[1]) and np.std(r[0]) > 0


def test_paired_replicates_need_a_set_of_two_and_a_resample():
    assert iv.paired_replicates([[1], [2]], lambda p: [1.0], 10) is None
    assert iv.paired_replicates([], lambda p: [1.0], 10) is None
    assert iv.paired_replicates([[1, 2]], lambda p: [1.0], 0) is None
    r = iv.paired_replicates([[1, 2], [3]], lambda p: float(p[1][0]), 1)
    assert r.shape == (1, 1) and r[0, 0] == 3.0
    a = iv.paired_replicates([[1, 2, 3]], lambda p: float(np.mean(p[0])), 20, rng_seed=4)
    assert not np.array_equal(a, iv.paired_replicates([[1, 2, 3]],
                                                      lambda p: float(np.mean(p[0])), 20))
    assert np.array_equal(iv.paired_replicates([[1, 2, 3]], lambda p: float(np.mean(p[0])), 20),
                          iv.paired_replicates([[1, 2, 3]], lambda p: float(np.mean(p[0])), 20,
                                               rng_seed=0))
    # replicates are numbers: a statistic's integers come back as floats, its None as NaN
    r = iv.paired_replicates([[1, 2, 3], [2, 3]], lambda p: [len(p[0]), None], 5)
    assert r.dtype == float and np.all(r[0] == 3.0) and np.all(np.isnan(r[1]))
    with np.errstate(all="raise"):
        r = iv.paired_replicates([[1, 2, 3]], lambda p: np.float64(1.0) / (np.float64(p[0][0]) - 1),
                                 20)
    assert np.isinf(r).any()


# ---------------------------------------------------------------- percentile_interval

def test_the_percentile_interval_at_its_level_without_undefined_replicates():
    r = np.arange(101, dtype=float)
    assert iv.percentile_interval(r) == pytest.approx((2.5, 97.5))
    assert iv.percentile_interval(r, level=0.5) == pytest.approx((25.0, 75.0))
    assert iv.percentile_interval(np.r_[r, [math.nan] * 50]) == pytest.approx((2.5, 97.5))
    assert iv.LEVEL == 0.95
    lo, hi = iv.percentile_interval([1.0, math.nan, 2.0])
    assert (lo, hi) == pytest.approx((1.025, 1.975))
    for few in ([1.0], [1.0, math.nan], []):
        assert all(math.isnan(v) for v in iv.percentile_interval(few))
    lo, hi = iv.percentile_interval([1.0, 2.0])
    assert isinstance(lo, float) and isinstance(hi, float)


def test_an_end_interpolated_towards_an_unbounded_replicate_is_unbounded():
    # 40 replicates, one of them inf: the 97.5th percentile lies between the largest finite
    # one and inf, the 2.5th between -inf and the smallest
    r = list(np.linspace(1.0, 2.0, 39))
    assert iv.percentile_interval(r + [math.inf]) == (pytest.approx(1.0 + 0.975 / 38), math.inf)
    assert iv.percentile_interval([-math.inf] + r) == (-math.inf, pytest.approx(2.0 - 0.975 / 38))
    # 200 replicates with one inf: both ends lie among finite ones
    r = list(np.linspace(1.0, 2.0, 199))
    lo, hi = iv.percentile_interval(r + [math.inf])
    assert math.isfinite(hi) and hi == pytest.approx(np.percentile(r + [2.0], 97.5))
    lo, hi = iv.percentile_interval([-math.inf] + r)
    assert math.isfinite(lo) and lo == pytest.approx(np.percentile([1.0] + r, 2.5))
    # a huge finite replicate is a number, not unbounded
    lo, hi = iv.percentile_interval(list(np.linspace(1.0, 2.0, 39)) + [1e299])
    assert math.isfinite(hi) and hi > 1e297
    lo, hi = iv.percentile_interval([-1e299] + list(np.linspace(1.0, 2.0, 39)))
    assert math.isfinite(lo) and lo < -1e297
    # 41 replicates: the 97.5th percentile is the 40th exactly, finite beside an inf 41st
    r = list(np.linspace(1.0, 2.0, 40))
    assert iv.percentile_interval(r + [math.inf])[1] == 2.0
    assert iv.percentile_interval([-math.inf] + r)[0] == 1.0
    # 120 replicates: the 2.5th percentile lies between the 3rd and 4th; three at -inf
    r = list(np.linspace(1.0, 2.0, 117))
    assert iv.percentile_interval([-math.inf] * 3 + r)[0] == -math.inf
    assert math.isfinite(iv.percentile_interval([-math.inf] * 2 + r + [5.0])[0])
    assert iv.percentile_interval(r + [math.inf] * 3)[1] == math.inf
    assert math.isfinite(iv.percentile_interval([0.0] + r + [math.inf] * 2)[1])


def test_when_most_replicates_are_unbounded_both_ends_are():
    # nearly every replicate at +inf: the lower end lies between unbounded ones (or towards
    # one), not at a huge number
    assert iv.percentile_interval([math.inf] * 5) == (math.inf, math.inf)
    assert iv.percentile_interval([1.0] + [math.inf] * 50) == (math.inf, math.inf)
    assert iv.percentile_interval([-math.inf] * 5) == (-math.inf, -math.inf)
    assert iv.percentile_interval([-math.inf] * 50 + [1.0]) == (-math.inf, -math.inf)
    lo, hi = iv.percentile_interval([1.0] * 3 + [math.inf] * 37)
    assert lo == pytest.approx(1.0) and hi == math.inf
    # 30 replicates: the lower end lies between the one finite and the first +inf
    assert iv.percentile_interval([1.0] + [math.inf] * 29) == (math.inf, math.inf)
    assert iv.percentile_interval([-math.inf] * 29 + [1.0]) == (-math.inf, -math.inf)
    # 120: the 2.5th percentile lies between the 3rd and the 4th, finite beside an inf 5th
    lo, hi = iv.percentile_interval([1.0, 2.0, 3.0, 4.0] + [math.inf] * 116)
    assert lo == pytest.approx(3.975) and hi == math.inf
    # 101: the 97.5th lies between the 98th (-inf) and the 99th
    assert iv.percentile_interval([-math.inf] * 98 + [1.0, 2.0, 3.0])[1] == -math.inf


# ---------------------------------------------------------------- widening

def test_the_small_sample_factor_is_student_t_over_the_normal_on_the_unbiased_sd():
    for n, approx in [(3, 2.69), (5, 1.58), (10, 1.22)]:
        assert iv.small_sample_factor(n) == pytest.approx(approx, abs=0.005)
    for n in (2, 4, 30):
        want = stats.t.ppf(0.975, n - 1) / stats.norm.ppf(0.975) * math.sqrt(n / (n - 1))
        assert iv.small_sample_factor(n) == pytest.approx(want, rel=1e-12)
    want = stats.t.ppf(0.95, 4) / stats.norm.ppf(0.95) * math.sqrt(5 / 4)
    assert iv.small_sample_factor(5, level=0.9) == pytest.approx(want, rel=1e-12)
    assert iv.small_sample_factor(1) == 1.0 and iv.small_sample_factor(0) == 1.0


def test_the_interval_is_widened_about_its_value_its_infinite_ends_stay():
    f = iv.small_sample_factor(4)
    assert iv.expanded(2.0, (1.5, 3.0), 4) == pytest.approx((2.0 - 0.5 * f, 2.0 + f))
    assert iv.expanded(2.0, (0.0, 6.0), 4) == pytest.approx((2.0 - 2 * f, 2.0 + 4 * f))
    g = iv.small_sample_factor(4, 0.8)
    assert iv.expanded(2.0, (1.5, 3.0), 4, level=0.8) == pytest.approx((2.0 - 0.5 * g, 2.0 + g))
    assert iv.expanded(2.0, (-math.inf, 3.0), 4) == pytest.approx((-math.inf, 2.0 + f))
    assert iv.expanded(2.0, (1.5, math.inf), 4) == pytest.approx((2.0 - 0.5 * f, math.inf))
    for v in (math.nan, math.inf):
        assert iv.expanded(v, (1.5, 3.0), 4) == (1.5, 3.0)
    assert iv.expanded(2.0, (1.5, 3.0), 1) == (1.5, 3.0)


def test_the_replicates_sd_is_the_unbiased_sd_of_the_finite_ones():
    assert iv.replicate_sd([1.0, 2.0, 3.0, math.inf, math.nan]) == pytest.approx(1.0)
    assert math.isnan(iv.replicate_sd([1.0, math.inf]))
    assert math.isnan(iv.replicate_sd([]))
    assert iv.replicate_sd([1.0, 3.0]) == pytest.approx(math.sqrt(2))


def test_the_dominant_error_is_the_larger_of_the_half_width_and_the_bias():
    assert iv.dominant(1.0, (0.9, 1.2), 0.15) == "seeds"          # the wider side counts
    assert iv.dominant(1.0, (0.8, 1.05), -0.15) == "seeds"
    assert iv.dominant(1.0, (0.9, 1.1), 0.15) == "discretisation"
    assert iv.dominant(2.0, (1.5, 2.5), 0.25) == "seeds"            # equal: the seeds
    assert iv.dominant(-2.0, (-2.5, -1.5), 0.2) == "seeds"
    assert iv.dominant(-2.0, (-2.5, -1.5), 0.3) == "discretisation"
    for args in [(math.nan, (0.9, 1.1), 0.1), (1.0, (0.9, 1.1), math.nan),
                 (1.0, (-math.inf, 1.1), 0.1), (1.0, (0.9, math.inf), 0.1),
                 (math.inf, (0.9, 1.1), 0.1)]:
        assert iv.dominant(*args) == "unknown", args

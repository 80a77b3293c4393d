"""laws.loss, pinned so that its one-line mutations fail (issue 34, item 6;
benchmarks/mutation.py). Exact inputs, no study: the bracket among states other than the three
read ones, the crossing's every branch (clipped and not, log-log and from the smooth limit, the
guards on plateaus that are no positive number), the interval another seed set would measure in
at its edges, which groups are certain, the span in each of the three kinds, and the measured
interval against a reconstruction from the module text (the replicates' crossings, their
percentile interval widened for the fewer seeds, cut at 0)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from fibril_hpc.campaign.laws import loss
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNDETERMINED, UNRESOLVED

THR = 1.0


def _t_factor(n):
    q = 0.975
    return stats.t.ppf(q, n - 1) / stats.norm.ppf(q) * math.sqrt(n / (n - 1))


# ---------------------------------------------------------------- bracket_indices

def test_the_bracket_takes_the_nearest_held_group_below_the_first_loss_with_one():
    # undetermined groups hold nothing: neither below the loss nor as the loss
    st = [RESOLVED, UNRESOLVED, UNDETERMINED, LOST, RESOLVED, LOST]
    assert loss.bracket_indices(range(6), st) == (1, 3)
    assert loss.bracket_indices(range(4), [UNDETERMINED, LOST, RESOLVED, LOST]) == (2, 3)
    assert loss.bracket_indices(range(3), [RESOLVED, UNDETERMINED, RESOLVED]) is None
    assert loss.bracket_indices(range(3), [RESOLVED, RESOLVED, RESOLVED]) is None
    assert loss.bracket_indices(range(3), [RESOLVED, RESOLVED, LOST]) == (1, 2)


# ---------------------------------------------------------------- crossing

def test_the_crossing_is_nan_where_a_plateau_or_the_threshold_is_no_positive_number():
    for p_lo, p_hi, thr in [(math.inf, 0.5, THR), (2.0, math.inf, THR), (2.0, math.nan, THR),
                            (0.0, 0.5, THR), (2.0, 0.0, THR), (-2.0, 0.5, THR),
                            (2.0, -0.5, THR), (2.0, 0.5, 0.0), (2.0, 0.5, -1.0)]:
        assert math.isnan(loss.crossing(1.0, 2.0, p_lo, p_hi, thr)), (p_lo, p_hi, thr)
        assert math.isnan(loss.crossing(1.0, 2.0, p_lo, p_hi, thr, clip=False))


def test_the_crossing_is_log_log_between_two_groups_and_linear_from_the_smooth_limit():
    # plateau 4 at 1, 1/4 at 2: p = 4 s^-4, crosses 1 at s = sqrt(2)
    assert loss.crossing(1.0, 2.0, 4.0, 0.25, THR) == pytest.approx(math.sqrt(2), rel=1e-12)
    # below 1 in sigma~ as well (log-log, not linear: linear would give 0.75)
    assert loss.crossing(0.5, 1.0, 4.0, 0.25, THR) == pytest.approx(math.sqrt(0.5), rel=1e-12)
    # from sigma~ = 0: t = ln 2 / ln 8 = 1/3 of the way in sigma~
    assert loss.crossing(0.0, 3.0, 2.0, 0.25, THR) == pytest.approx(1.0, rel=1e-12)
    assert loss.crossing(0.0, 3.0, 2.0, 0.25, THR, clip=False) == pytest.approx(1.0, rel=1e-12)
    # a plateau that rises across the threshold crosses where it rises through it
    assert loss.crossing(1.0, 2.0, 0.25, 4.0, THR) == pytest.approx(math.sqrt(2), rel=1e-12)


def test_a_clipped_crossing_stays_in_the_bracket_an_unclipped_one_extends_the_line():
    # both above and falling: the log-log line reaches the threshold at 4 (beyond hi = 2)
    assert loss.crossing(1.0, 2.0, 4.0, 2.0, THR) == 2.0
    assert loss.crossing(1.0, 2.0, 4.0, 2.0, THR, clip=False) == pytest.approx(4.0, rel=1e-12)
    # both below and falling: at 1/2 (below lo = 1)
    assert loss.crossing(1.0, 2.0, 0.5, 0.25, THR) == 1.0
    assert loss.crossing(1.0, 2.0, 0.5, 0.25, THR, clip=False) == pytest.approx(0.5, rel=1e-12)
    # from the smooth limit the extended line stops at sigma~ = 0
    assert loss.crossing(0.0, 1.0, 0.5, 0.25, THR, clip=False) == 0.0
    assert loss.crossing(0.0, 1.0, 0.5, 0.25, THR) == 0.0
    assert loss.crossing(0.0, 1.0, 4.0, 2.0, THR, clip=False) == pytest.approx(2.0, rel=1e-12)


def test_an_unclipped_plateau_that_does_not_fall_crosses_at_0_or_beyond_hi():
    assert loss.crossing(1.0, 2.0, 2.0, 2.0, THR, clip=False) == math.inf
    assert loss.crossing(1.0, 2.0, 2.0, 3.0, THR, clip=False) == math.inf
    assert loss.crossing(1.0, 2.0, 0.5, 0.5, THR, clip=False) == 0.0
    assert loss.crossing(1.0, 2.0, 0.25, 0.5, THR, clip=False) == 0.0
    # clipped: hi when above, lo when below, whichever way it goes
    assert loss.crossing(1.0, 2.0, 2.0, 3.0, THR) == 2.0
    assert loss.crossing(1.0, 2.0, 0.25, 0.5, THR) == 1.0
    # a plateau exactly at the threshold is not above it
    assert loss.crossing(1.0, 2.0, THR, THR, THR, clip=False) == 0.0


# ---------------------------------------------------------------- another_set

def test_another_seed_set_at_the_edges_of_its_interval():
    assert loss.another_set(2.0, (0.5, 8.0), factor=2.0) == pytest.approx((0.125, 32.0))
    assert loss.another_set(0.5, (0.25, 1.0), factor=2.0) == pytest.approx((0.125, 2.0))
    # ends at the estimate stay there; ends beyond it are not pulled in
    assert loss.another_set(2.0, (2.0, 2.0)) == (2.0, 2.0)
    assert loss.another_set(2.0, (3.0, 1.0)) == (2.0, 2.0)
    assert loss.another_set(2.0, (0.0, math.inf)) == (0.0, math.inf)
    # no positive estimate or an undefined end: no interval
    for s, ci in [(0.0, (0.0, 1.0)), (-1.0, (0.5, 2.0)), (math.inf, (0.5, 2.0)),
                  (2.0, (1.0, math.nan)), (math.nan, (1.0, 3.0))]:
        assert all(math.isnan(v) for v in loss.another_set(s, ci)), (s, ci)
    assert loss.ANOTHER == pytest.approx(math.sqrt(2))


# ---------------------------------------------------------------- certainty and the span

def _m(sig, states, plateaus, cis=None, **kw):
    return loss.measure(sig, states, plateaus, THR, plateau_cis=cis, **kw)


def test_a_state_is_uncertain_when_its_interval_holds_the_threshold_ends_included_below():
    sig = [1.0, 2.0, 3.0, 4.0, 5.0]
    st = [RESOLVED] * 5
    p = [2.0] * 5
    cis = [(1.0, 3.0), (0.5, 1.0), (-math.inf, 3.0), (0.5, math.inf), (1.5, 3.0)]
    m = _m(sig, st, p, cis)
    assert m.uncertain == (1.0,)
    # a list of intervals shorter than the groups: the groups beyond it are certain
    m = _m(sig, st, p, [(0.5, 3.0), (0.5, 3.0)])
    assert m.uncertain == (1.0, 2.0)
    assert _m(sig, st, p, None).uncertain == ()


def test_no_loss_spans_from_the_largest_certain_held_group_to_infinity():
    sig = [0.5, 1.0, 2.0, 3.0]
    st = [RESOLVED, UNRESOLVED, UNDETERMINED, RESOLVED]
    m = _m(sig, st, [2.0] * 4, [(1.5, 3.0), (1.5, 3.0), (1.5, 3.0), (0.5, 3.0)])
    assert m.kind == loss.NO_LOSS and m.bracket == (3.0, math.inf)
    assert m.span == (1.0, math.inf) and m.uncertain == (3.0,)
    assert math.isnan(m.sigma) and m.again == ()
    # every held group uncertain: from the smooth limit
    m = _m(sig, st, [2.0] * 4, [(0.5, 3.0)] * 4)
    assert m.span == (0.0, math.inf) and m.span[0] == 0.0
    # the largest read sigma~, not an undetermined one above it
    m = _m([0.5, 1.0, 2.0], [RESOLVED, RESOLVED, UNDETERMINED], [2.0] * 3)
    assert m.bracket == (1.0, math.inf) and m.span == (1.0, math.inf)


def test_all_lost_spans_from_0_to_the_smallest_certain_lost_group():
    sig = [0.5, 1.0, 2.0, 3.0]
    st = [UNDETERMINED, LOST, LOST, RESOLVED]
    m = _m(sig, st, [0.5, 0.5, 0.5, 2.0], [(0.4, 0.6), (0.4, 0.6), (0.4, 0.6), (1.5, 3.0)])
    assert m.kind == loss.ALL_LOST and m.bracket == (0.0, 1.0)
    assert m.span == (0.0, 1.0) and m.again == (3.0,)
    # the first lost group not certain: up to the next certain one
    m = _m(sig, st, [0.5, 0.5, 0.5, 2.0], [(0.4, 0.6), (0.4, 1.5), (0.4, 0.6), (1.5, 3.0)])
    assert m.span == (0.0, 2.0) and m.uncertain == (1.0,)
    m = _m(sig, st, [0.5] * 3 + [2.0], [(0.4, 0.6), (0.4, 1.5), (0.4, 1.5), (1.5, 3.0)])
    assert m.span == (0.0, math.inf)
    m = _m([1.0, 2.0], [LOST, LOST], [0.5, 0.5], [(0.4, 0.6), (0.4, 0.6)])
    assert m.span == (0.0, 1.0) and m.again == ()


def test_nothing_read_is_no_measurement():
    m = _m([1.0, 2.0], [UNDETERMINED, UNDETERMINED], [2.0, 0.5])
    assert m.kind == loss.NOT_READ and all(math.isnan(v) for v in m.bracket + m.span)
    assert math.isnan(m.sigma) and m.uncertain == () and m.threshold == THR


def test_the_bracket_span_reaches_the_certain_groups_around_it():
    sig = [0.5, 1.0, 2.0, 3.0, 4.0, 5.0]
    st = [RESOLVED, RESOLVED, LOST, LOST, RESOLVED, LOST]
    p = [4.0, 1.5, 0.5, 0.5, 2.0, 0.5]
    cert = [(3.0, 5.0), (1.2, 1.8), (0.4, 0.6), (0.4, 0.6), (1.5, 3.0), (0.4, 0.6)]
    m = _m(sig, st, p, cert)
    assert m.kind == loss.BRACKET and m.bracket == (1.0, 2.0) and m.span == (1.0, 2.0)
    assert m.again == (4.0,)
    assert m.sigma == pytest.approx(math.exp(math.log(1.5) / math.log(3.0) * math.log(2.0)))
    # both bracketing groups uncertain: out to the next certain ones
    unc = list(cert)
    unc[1], unc[2] = (0.8, 1.8), (0.4, 1.2)
    m = _m(sig, st, p, unc)
    assert m.span == (0.5, 3.0) and m.uncertain == (1.0, 2.0)
    # the upper certain group is the first certain lost one from hi on, not the last
    unc[3] = (0.4, 1.2)
    assert _m(sig, st, p, unc).span == (0.5, 5.0)
    unc[5] = (0.4, 1.2)
    unc[0] = (0.5, 5.0)
    assert _m(sig, st, p, unc).span == (0.0, math.inf)


# ---------------------------------------------------------------- the measured interval

def _reps(rng, n, p_lo, p_hi, scatter):
    return np.vstack([p_lo * np.exp(scatter * rng.standard_normal(n)),
                      p_hi * np.exp(scatter * rng.standard_normal(n))])


def _expected_ci(lo, hi, reps, s, n_seeds):
    rs = np.array([loss.crossing(lo, hi, a, b, THR, clip=False) for a, b in zip(*reps)])
    rs = rs[~np.isnan(rs)]
    q_lo, q_hi = np.percentile(rs, [2.5, 97.5])
    f = _t_factor(n_seeds)
    return max(s - f * (s - q_lo), 0.0), s + f * (q_hi - s)


@pytest.mark.parametrize("n_seeds", [(3, 10), (10, 3), (5, 5)])
def test_the_interval_is_the_replicates_crossings_widened_for_the_fewer_seeds(n_seeds):
    reps = _reps(np.random.default_rng(1), 300, 1.6, 0.6, 0.2)
    m = _m([0.5, 1.0, 2.0], [RESOLVED, RESOLVED, LOST], [3.0, 1.6, 0.6],
           reps=np.vstack([reps[0] * 2, reps]), n_seeds=(20,) + n_seeds)
    s = m.sigma
    assert s == pytest.approx(math.exp(math.log(1.6) / math.log(1.6 / 0.6) * math.log(2.0)))
    assert m.n_seeds == min(n_seeds)
    assert m.ci == pytest.approx(_expected_ci(1.0, 2.0, reps, s, min(n_seeds)), rel=1e-9)
    assert m.another == pytest.approx(loss.another_set(s, m.ci), rel=1e-12)
    # both groups count as certain (no plateau interval given): they bound the span
    assert m.span == (1.0, 2.0)


def test_an_interval_reaching_below_0_is_cut_at_0_and_spans_to_it():
    # from the smooth limit, a wide scatter and three seeds: the widened lower end is < 0
    reps = _reps(np.random.default_rng(2), 300, 1.5, 0.5, 0.8)
    m = _m([0.0, 1.0], [RESOLVED, LOST], [1.5, 0.5], reps=reps, n_seeds=(3, 3),
           cis=[(1.2, 1.8), (0.4, 0.6)])
    assert m.ci[0] == 0.0 and m.ci[1] > m.sigma > 0
    lo, hi = np.percentile([loss.crossing(0.0, 1.0, a, b, THR, clip=False)
                            for a, b in zip(*reps)], [2.5, 97.5])
    assert m.sigma - _t_factor(3) * (m.sigma - lo) < 0
    assert m.ci[1] == pytest.approx(m.sigma + _t_factor(3) * (hi - m.sigma), rel=1e-9)
    # the smooth limit below and a group lost for certain above bound the span
    assert m.span == (0.0, 1.0)


def test_without_seed_counts_or_replicates_there_is_no_interval():
    m = _m([1.0, 2.0], [RESOLVED, LOST], [4.0, 0.25], n_seeds=(5,))
    assert m.n_seeds == 0 and all(math.isnan(v) for v in m.ci + m.another)
    assert m.span == (1.0, 2.0) and m.sigma == pytest.approx(math.sqrt(2))
    m = _m([1.0, 2.0], [RESOLVED, LOST], [4.0, 0.25], n_seeds=(5, 4))
    assert m.n_seeds == 4 and all(math.isnan(v) for v in m.ci)
    # a crossing that cannot be formed has no interval, even with replicates
    reps = _reps(np.random.default_rng(3), 50, 4.0, 0.25, 0.1)
    m = _m([1.0, 2.0], [RESOLVED, LOST], [4.0, math.nan], reps=reps, n_seeds=(5, 5))
    assert math.isnan(m.sigma) and all(math.isnan(v) for v in m.ci + m.another)
    assert m.span == (1.0, 2.0)


def test_an_unbounded_interval_makes_the_span_unbounded_on_that_side():
    # most replicates hold both plateaus above the threshold and do not fall: crossing at inf
    rng = np.random.default_rng(4)
    reps = np.vstack([np.full(200, 2.0), np.where(rng.random(200) < 0.5, 3.0, 0.5)])
    m = _m([1.0, 2.0], [RESOLVED, LOST], [2.0, 0.5], reps=reps, n_seeds=(10, 10),
           cis=[(1.5, 2.5), (0.4, 3.2)])
    assert m.ci[1] == math.inf and m.another[1] == math.inf and m.span[1] == math.inf
    # the same replicates with the lost group certain of its state: it bounds the span
    m = _m([1.0, 2.0], [RESOLVED, LOST], [2.0, 0.5], reps=reps, n_seeds=(10, 10),
           cis=[(1.5, 2.5), (0.4, 0.6)])
    assert m.ci[1] == math.inf and m.span == (1.0, 2.0)
    assert m.span[0] == pytest.approx(min(1.0, m.another[0]))


def test_a_crossing_at_an_end_of_the_bracket_stays_inside_it_exactly():
    # the lost group exactly at the threshold: the crossing is hi itself, not hi + an ulp
    # (exp(log lo + log(hi / lo)) rounds above 1.0 here)
    assert loss.crossing(0.1, 1.0, 2.0, 1.0, THR) == 1.0
    assert loss.crossing(0.1, 0.35, 2.0, 1.0, THR) == 0.35
    assert loss.crossing(0.1, 1.0, 2.0, 1.0, THR) <= 1.0


def test_a_loss_below_the_first_held_group_does_not_bound_the_span():
    # a lost group below the bracket (before any group held) is not where adhesion is gone
    m = _m([0.5, 1.0, 2.0], [LOST, RESOLVED, LOST], [0.5, 2.0, 0.5],
           [(0.4, 0.6), (1.5, 2.5), (0.4, 0.6)])
    assert m.bracket == (1.0, 2.0) and m.span == (1.0, 2.0)
    m = _m([0.5, 1.0, 2.0], [LOST, RESOLVED, LOST], [0.5, 2.0, 0.5],
           [(0.4, 0.6), (1.5, 2.5), (0.4, 1.5)])
    assert m.span == (1.0, math.inf)


def test_no_loss_spans_from_the_last_group_when_it_holds_for_certain():
    m = _m([0.5, 1.0, 2.0], [RESOLVED, RESOLVED, UNRESOLVED], [2.0, 2.0, 2.0],
           [(1.5, 2.5)] * 3)
    assert m.kind == loss.NO_LOSS and m.span == (2.0, math.inf)

"""laws.study's loss bracket across different seed sets, pinned so that its one-line mutations
fail (issue 34, item 6; benchmarks/mutation.py): which of the bracket's two groups is the larger
where ``seeds: auto`` ran nested seed sets, the smaller group's plateau carried to the larger
group's seeds by their ratio where both ran (in the data and in every replicate), the seed
counts it names, the zero-width interval from seeds that scatter, and the study's small
helpers (the resample's relabelling, why a group is out of the fit, the interval cut at 0).
Brushes of fixed strength per seed (seed s holds w_s x the group's plateau), so the truth of a
crossing over the same brushes is known exactly."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from synthetic_campaigns import FLOOR, LOSS

from fibril_hpc.campaign.laws import study as sd
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNDETERMINED, UNRESOLVED

PRE = tuple(float(v) for v in np.geomspace(1e-3, 10.0, 13))


def _g(sigma, state):
    return SimpleNamespace(sigma_tilde=sigma, reading=SimpleNamespace(state=state))


def test_the_larger_of_the_brackets_two_nested_seed_sets_comes_first():
    gs = [_g(0.5, RESOLVED), _g(1.0, RESOLVED), _g(1.2, LOST)]
    ten, six = list(range(10)), list(range(6))
    assert sd._matched_pair(gs, [six, ten, six]) == (1, 2)
    assert sd._matched_pair(gs, [ten, six, ten]) == (2, 1)
    assert sd._matched_pair(gs, [six, ten, ten]) is None          # the same seeds
    assert sd._matched_pair(gs, [six, six, [3, 4, 5, 6]]) is None  # not nested
    assert sd._matched_pair(gs, [six, [0, 1], [1, 2]]) is None
    # no bracket: nothing to match
    assert sd._matched_pair([_g(0.5, RESOLVED), _g(1.0, UNRESOLVED)], [ten, six]) is None
    assert sd._matched_pair([_g(0.5, LOST), _g(1.0, LOST)], [ten, six]) is None
    # the bracket, not the first two groups
    gs = [_g(0.5, RESOLVED), _g(1.0, UNRESOLVED), _g(1.2, UNDETERMINED), _g(1.5, LOST)]
    assert sd._matched_pair(gs, [ten, six, ten, ten]) == (3, 1)


def test_the_other_plateau_is_carried_by_the_larger_groups_ratio_on_its_seeds():
    assert sd._matched(2.0, 3.0, 1.5) == pytest.approx(4.0)
    assert float(sd._matched(0.5, 1.0, 2.0)) == pytest.approx(0.25)
    got = sd._matched([2.0, 2.0, 2.0, 2.0, 2.0, 2.0], [3.0, 3.0, 0.0, -1.0, math.inf, 3.0],
                      [1.5, 0.0, 1.0, 1.0, 1.0, math.nan])
    assert got[0] == pytest.approx(4.0) and np.all(np.isnan(got[1:]))
    assert np.isnan(sd._matched(2.0, 0.0, 0.0))


def _brushes(groups, weights):
    """{sigma~: points}: seed s of a group with plateau P (LOSS units) holds w_s P, after a
    resolved rise (F~_A = p_s / 0.1 F~_P up to the plateau, the pillar floor below)."""
    out = {}
    for s, (P, seeds) in groups.items():
        rows = []
        for seed in seeds:
            p_s = weights[seed] * P * LOSS
            rows += [(seed, x, x, min(max(FLOOR, p_s / 0.1 * x), p_s)) for x in PRE]
        out[s] = tuple(np.array(c, dtype=float) for c in zip(*rows))
    return out


W = {s: (0.6 if s < 4 else 1.6 - 0.1 * s) for s in range(8)}         # seeds 0-3 weak
W_HELD = {s: (1.4 if s < 4 else 0.3 + 0.1 * (s - 4)) for s in range(8)}   # seeds 0-3 strong


def _truth(p_lo, p_hi, lo=1.0, hi=1.2):
    return math.exp(math.log(lo) + math.log(p_lo) / math.log(p_lo / p_hi) * math.log(hi / lo))


@pytest.mark.parametrize("fewer_at", ["lost", "held"])
def test_the_crossing_is_read_over_the_same_brushes_in_the_data_and_every_replicate(fewer_at):
    big, small = range(8), range(4)
    w = W if fewer_at == "lost" else W_HELD
    mean_all = np.mean([w[s] for s in big])
    mean_few = np.mean([w[s] for s in small])
    held, lost = (big, small) if fewer_at == "lost" else (small, big)
    pts = _brushes({0.5: (3.0, big), 1.0: (1.3, held), 1.2: (0.8, lost)}, w)
    st = sd.study_k(1.0, pts, n_boot=40, floor=FLOOR)
    assert st.loss.bracket == (1.0, 1.2) and st.loss.matched == (8, 4)
    # the group of four seeds carried to the eight: its plateau as the eight's mean would be
    p_lo, p_hi = 1.3 * mean_all, 0.8 * mean_all
    if fewer_at == "lost":
        assert st.groups[2].reading.plateau / LOSS == pytest.approx(0.8 * mean_few, rel=1e-6)
    else:
        assert st.groups[1].reading.plateau / LOSS == pytest.approx(1.3 * mean_few, rel=1e-6)
    assert st.sigma_loss == pytest.approx(_truth(p_lo, p_hi), rel=1e-6)
    # every replicate's crossing lies on the same brushes: they scatter about the truth
    assert st.sigma_loss_ci[0] < st.sigma_loss < st.sigma_loss_ci[1]
    assert st.loss.n_seeds == 4
    # the groups' own seed means would cross elsewhere
    own = (_truth(1.3 * mean_all, 0.8 * mean_few) if fewer_at == "lost"
           else _truth(1.3 * mean_few, 0.8 * mean_all))
    assert own != pytest.approx(st.sigma_loss, rel=2e-3)


def test_equal_seed_sets_and_no_bootstrap_are_read_as_they_are():
    pts = _brushes({1.0: (1.3, range(8)), 1.2: (0.8, range(4))}, W)
    st = sd.study_k(1.0, pts, n_boot=0, floor=FLOOR)
    assert st.loss.matched == (8, 4) and all(math.isnan(v) for v in st.loss.ci)
    m = np.mean(list(W.values()))
    assert st.sigma_loss == pytest.approx(_truth(1.3 * m, 0.8 * m), rel=1e-6)
    pts = _brushes({1.0: (1.3, range(8)), 1.2: (0.8, range(8))}, W)
    st = sd.study_k(1.0, pts, n_boot=30, floor=FLOOR)
    assert st.loss.matched == () and st.sigma_loss == pytest.approx(_truth(1.3 * m, 0.8 * m),
                                                                    rel=1e-6)


def test_a_zero_width_interval_from_seeds_that_scatter_is_no_interval():
    # threshold 1 (one pillar 1/3); powers of two keep the replicates' crossings exact
    gs = [SimpleNamespace(sigma_tilde=1.0, n_seeds=5, plateau_ci=(1.5, 2.5),
                          reading=SimpleNamespace(state=RESOLVED, plateau=2.0)),
          SimpleNamespace(sigma_tilde=1.2, n_seeds=5, plateau_ci=(0.4, 0.6),
                          reading=SimpleNamespace(state=LOST, plateau=0.5))]
    st = SimpleNamespace(groups=gs, loss=None)
    # the two plateaus scatter, but every replicate crosses at the same sigma~ (p_lo p_hi = 1:
    # half way in log sigma~)
    k = np.array([2.0, 4.0, 8.0] * 10)
    sd._measure_loss(st, np.vstack([k, 1 / k]), 1 / 3)
    assert st.loss.threshold == 1.0 and st.loss.sigma == pytest.approx(math.sqrt(1.2))
    assert all(math.isnan(v) for v in st.loss.ci + st.loss.another)
    # the same without scatter: a point interval stays
    sd._measure_loss(st, np.vstack([np.full(30, 2.0), np.full(30, 0.5)]), 1 / 3)
    assert st.loss.ci == (st.loss.sigma, st.loss.sigma)
    # only one of the two scatters: still scatter
    sd._measure_loss(st, np.vstack([np.full(30, 2.0), 0.5 * np.array([0.5, 1.0, 1.5] * 10)]),
                     1 / 3)
    assert st.loss.ci[0] < st.loss.sigma < st.loss.ci[1]
    sd._measure_loss(st, np.vstack([0.5 * k, np.full(30, 0.5)]), 1 / 3)
    assert st.loss.ci[0] < st.loss.sigma < st.loss.ci[1]
    assert st.loss.matched == ()
    # no replicates: no interval, no check
    sd._measure_loss(st, None, 1 / 3)
    assert all(math.isnan(v) for v in st.loss.ci) and st.loss.sigma == pytest.approx(
        math.sqrt(1.2))


def test_the_carried_replicates_take_the_ratio_replicate_by_replicate():
    gs = [SimpleNamespace(sigma_tilde=1.0, n_seeds=8, plateau_ci=loss_ci, reading=r)
          for loss_ci, r in [((1.2 * LOSS, 1.4 * LOSS),
                              SimpleNamespace(state=RESOLVED, plateau=1.3 * LOSS))]]
    gs.append(SimpleNamespace(sigma_tilde=1.2, n_seeds=4, plateau_ci=(0.3 * LOSS, 0.5 * LOSS),
                              reading=SimpleNamespace(state=LOST, plateau=0.4 * LOSS)))
    st = SimpleNamespace(groups=gs, loss=None)
    rng = np.random.default_rng(0)
    ref = 1.3 * LOSS * np.exp(0.05 * rng.standard_normal(60))
    other = 0.4 * LOSS * np.exp(0.05 * rng.standard_normal(60))
    on_other = 0.65 * LOSS * np.exp(0.05 * rng.standard_normal(60))
    sd._measure_loss(st, np.vstack([ref, other]), FLOOR, (0, 1), 0.65 * LOSS, on_other)
    assert st.loss.matched == (8, 4)
    assert st.loss.sigma == pytest.approx(_truth(1.3, 0.8), rel=1e-9)
    from fibril_hpc.campaign.laws import loss as _loss
    from fibril_hpc.campaign.laws.intervals import expanded, percentile_interval
    carried = other * ref / on_other
    rs = [_loss.crossing(1.0, 1.2, a, b, 3 * FLOOR, clip=False) for a, b in zip(ref, carried)]
    want = expanded(st.loss.sigma, percentile_interval(rs), 4)
    assert st.loss.ci == pytest.approx(want, rel=1e-9)
    # the replicates left as they were where none are given for the larger on the other's
    sd._measure_loss(st, np.vstack([ref, other]), FLOOR, (0, 1), 0.65 * LOSS, None)
    rs = [_loss.crossing(1.0, 1.2, a, b, 3 * FLOOR, clip=False) for a, b in zip(ref, other)]
    assert st.loss.ci == pytest.approx(expanded(st.loss.sigma, percentile_interval(rs), 4))


def test_the_study_helpers():
    seed = np.array([0, 0, 1, 1, 2])
    pre = np.arange(5.0)
    s, p, x, y = sd._resample((seed, pre, pre * 2, pre * 3), [2, 0, 0])
    assert s.tolist() == [0, 1, 1, 2, 2] and p.tolist() == [4.0, 0.0, 1.0, 0.0, 1.0]
    assert x.tolist() == [8.0, 0.0, 2.0, 0.0, 2.0] and y.tolist() == [12.0, 0.0, 3.0, 0.0, 3.0]
    s, p, x, y = sd._resample((seed, pre, pre, pre), [])
    assert len(s) == 0 and p.size == 0
    assert sd._nonneg((-1.0, 2.0)) == (0.0, 2.0)
    assert sd._nonneg((-math.inf, math.nan)) == (-math.inf, math.nan)
    assert all(math.isnan(v) for v in sd._spread((1.0, 1.0), True))
    assert sd._spread((1.0, 1.0), False) == (1.0, 1.0)
    assert sd._spread((1.0, 0.5), False) == (1.0, 0.5)
    assert all(math.isnan(v) for v in sd._spread((1.0, 0.5), True))
    assert sd._spread((1.0, 1.5), True) == (1.0, 1.5)
    assert sd._spread((1.0, math.inf), True) == (1.0, math.inf)
    assert sd._spread((-math.inf, -math.inf), True) == (-math.inf, -math.inf)


def _r(state=RESOLVED, plateau_state="reached", c=1.0):
    return SimpleNamespace(state=state, plateau_state=plateau_state, c=c)


def test_why_a_group_is_out_of_the_fit():
    O = sd.OutReason
    assert sd._out(0.0, _r()) == O.SMOOTH_LIMIT
    assert sd._out(-1.0, _r()) == O.SMOOTH_LIMIT
    assert sd._out(1.0, _r(plateau_state="no data")) == O.NO_DATA
    assert sd._out(1.0, _r(UNRESOLVED)) == O.UNRESOLVED
    assert sd._out(1.0, _r(UNDETERMINED)) == O.UNDETERMINED
    assert sd._out(1.0, _r(LOST, "not reached", math.nan)) == O.NONE
    assert sd._out(1.0, _r(plateau_state="not reached")) == O.NOT_REACHED
    assert sd._out(1.0, _r(c=math.nan)) == O.NO_C
    assert sd._out(1.0, _r(c=math.inf)) == O.NO_C
    assert sd._out(1e-9, _r()) == O.NONE

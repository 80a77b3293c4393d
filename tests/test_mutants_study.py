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

from synthetic_campaigns import FLOOR, LOSS, strength_campaign

from fibril_hpc.campaign.laws import study as sd
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNDETERMINED, UNRESOLVED

PRE = tuple(float(v) for v in np.geomspace(1e-3, 10.0, 13))


def _g(sigma, state):
    return SimpleNamespace(sigma_tilde=sigma, reading=SimpleNamespace(state=state))


def test_the_larger_of_the_brackets_two_nested_seed_sets_comes_first():
    gs = [_g(0.5, RESOLVED), _g(1.0, RESOLVED), _g(1.2, LOST)]
    ten, six = list(range(10)), list(range(6))
    assert sd._matched_pair(gs, [six, ten, six]) == (1, (2,))
    assert sd._matched_pair(gs, [ten, six, ten]) == (2, (1,))
    assert sd._matched_pair(gs, [six, ten, ten]) is None          # the same seeds
    assert sd._matched_pair(gs, [six, six, [3, 4, 5, 6]]) is None  # not nested
    assert sd._matched_pair(gs, [six, [0, 1], [1, 2]]) is None
    # no bracket: nothing to match
    assert sd._matched_pair([_g(0.5, RESOLVED), _g(1.0, UNRESOLVED)], [ten, six]) is None
    assert sd._matched_pair([_g(0.5, LOST), _g(1.0, LOST)], [ten, six]) is None
    # the bracket, not the first two groups
    gs = [_g(0.5, RESOLVED), _g(1.0, UNRESOLVED), _g(1.2, UNDETERMINED), _g(1.5, LOST)]
    assert sd._matched_pair(gs, [ten, six, ten, ten]) == (3, (1,))


def test_the_other_plateau_is_carried_by_the_larger_groups_ratio_on_its_seeds():
    assert sd._matched(2.0, 3.0, 1.5) == pytest.approx(4.0)
    assert float(sd._matched(0.5, 1.0, 2.0)) == pytest.approx(0.25)
    got = sd._matched([2.0, 2.0, 2.0, 2.0, 2.0, 2.0], [3.0, 3.0, 0.0, -1.0, math.inf, 3.0],
                      [1.5, 0.0, 1.0, 1.0, 1.0, math.nan])
    assert got[0] == pytest.approx(4.0) and np.all(np.isnan(got[1:]))
    assert np.isnan(sd._matched(2.0, 0.0, 0.0))



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
    pts = strength_campaign({0.5: (3.0, big), 1.0: (1.3, held), 1.2: (0.8, lost)}, w)
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
    # each seed's own crossing: unclipped (weak seeds lie below the threshold at both ends)
    both = sorted(set(held) & set(lost))
    assert [k for k, _ in st.loss.per_seed] == both
    for k, v in st.loss.per_seed:
        assert v == pytest.approx(_truth(1.3 * w[k], 0.8 * w[k]), rel=1e-6)
    assert min(v for _, v in st.loss.per_seed) < 1.0 or max(v for _, v in st.loss.per_seed) > 1.2
    own = (_truth(1.3 * mean_all, 0.8 * mean_few) if fewer_at == "lost"
           else _truth(1.3 * mean_few, 0.8 * mean_all))
    assert own != pytest.approx(st.sigma_loss, rel=2e-3)


def test_equal_seed_sets_and_no_bootstrap_are_read_as_they_are():
    pts = strength_campaign({1.0: (1.3, range(8)), 1.2: (0.8, range(4))}, W)
    st = sd.study_k(1.0, pts, n_boot=0, floor=FLOOR)
    assert st.loss.matched == (8, 4) and all(math.isnan(v) for v in st.loss.ci)
    m = np.mean(list(W.values()))
    assert st.sigma_loss == pytest.approx(_truth(1.3 * m, 0.8 * m), rel=1e-6)
    pts = strength_campaign({1.0: (1.3, range(8)), 1.2: (0.8, range(8))}, W)
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
    # every replicate at or below the threshold and rising: all cross at 0, a zero-width
    # interval from a plateau that scatters (by less than 1)
    sd._measure_loss(st, np.vstack([np.array([0.4, 0.5, 0.6] * 10), np.full(30, 0.9)]), 1 / 3)
    assert all(math.isnan(v) for v in st.loss.ci)
    # the groups' plateau intervals say which states are certain
    gs[1].plateau_ci = (0.4, 1.2)
    sd._measure_loss(st, None, 1 / 3)
    assert st.loss.uncertain == (1.2,) and st.loss.span == (1.0, math.inf)
    gs[1].plateau_ci = (0.4, 0.6)
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
    sd._measure_loss(st, np.vstack([ref, other]), FLOOR, (0, (1,)), [0.65 * LOSS], [on_other])
    assert st.loss.matched == (8, 4)
    assert st.loss.sigma == pytest.approx(_truth(1.3, 0.8), rel=1e-9)
    from fibril_hpc.campaign.laws import loss as _loss
    from fibril_hpc.campaign.laws.intervals import expanded, percentile_interval
    carried = other * ref / on_other
    rs = [_loss.crossing(1.0, 1.2, a, b, 3 * FLOOR, clip=False) for a, b in zip(ref, carried)]
    want = expanded(st.loss.sigma, percentile_interval(rs), 4)
    assert st.loss.ci == pytest.approx(want, rel=1e-9)
    # the replicates left as they were where none are given for the larger on the other's
    sd._measure_loss(st, np.vstack([ref, other]), FLOOR, (0, (1,)), [0.65 * LOSS], None)
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


def test_beta_is_zero_judges_beta_and_its_interval():
    def st(beta, ci, alpha=1.0, alpha_ci=(0.5, 1.5)):
        return SimpleNamespace(ab=SimpleNamespace(beta=beta, alpha=alpha), beta_ci=ci,
                               alpha_ci=alpha_ci)

    assert not sd.beta_is_zero(st(1.0, (0.5, 1.5)))
    assert sd.beta_is_zero(st(1.0, (-0.1, 1.5)))
    assert sd.beta_is_zero(st(-1.0, (-1.5, -0.5), alpha=-1.0, alpha_ci=(0.5, 1.5)))
    assert not sd.beta_is_zero(st(1.0, (0.5, 1.5), alpha=-1.0, alpha_ci=(-2.0, 1.5)))


def _tanh_points(k_scale, sigmas, seeds=4):
    """{sigma~: points}: F~_A = P tanh(F~_P / 0.1) (c depends on the half fraction), P falling
    with sigma~ past the loss threshold; seed s scales P by 1 + 0.05 s."""
    out = {}
    for s in sigmas:
        P = k_scale * LOSS * 3.0 * math.exp(-2.0 * s)
        rows = []
        for seed in range(seeds):
            p_s = P * (1 + 0.05 * seed)
            rows += [(seed, x, x, max(FLOOR, p_s * math.tanh(x / 0.1))) for x in PRE]
        out[s] = tuple(np.array(c, dtype=float) for c in zip(*rows))
    return out


def _same(a, b):
    return np.allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float), equal_nan=True,
                       rtol=1e-12, atol=0.0)


def test_the_campaign_study_is_each_k_studied_alone_stiff_first():
    sig = (0.2, 0.4, 0.6, 0.8)
    by_k = {1.0: _tanh_points(1.0, sig), 0.1: _tanh_points(2.0, sig)}
    points = {(k, s): p for k, g in by_k.items() for s, p in g.items()}
    kw = dict(n_boot=12, rng_seed=3, half=0.4, floor=FLOOR, lost="floor")
    got = sd.study(points, **kw)
    assert list(got) == [1.0, 0.1]
    for k, st in got.items():
        want = sd.study_k(k, by_k[k], **kw)
        assert st.k_tilde == k and st.n_resamples == 12
        assert _same([g.reading.c for g in st.groups], [g.reading.c for g in want.groups])
        assert _same([g.c_ci for g in st.groups], [g.c_ci for g in want.groups])
        assert _same(st.loss.ci + st.alpha_ci, want.loss.ci + want.alpha_ci)
        assert st.ab.lost == "floor" and st.loss.threshold == pytest.approx(3 * FLOOR)
    # the defaults are study_k's
    got = sd.study(points, n_boot=12)
    want = sd.study_k(1.0, by_k[1.0], n_boot=12)
    assert _same([g.c_ci for g in got[1.0].groups], [g.c_ci for g in want.groups])
    assert got[1.0].ab.lost == sd.LOST_MODE
    assert sd.study({}) == {}


def _reconstructed(points, n_boot, rng_seed, floor):
    """The groups' intervals from the module text: one seed_replicates over the labels (every
    group holds them all), each group read on the resample: plateau, c, c0."""
    from fibril_hpc.campaign.laws import intervals as iv
    from fibril_hpc.campaign.laws.reading import read_group

    sig = sorted(points)
    labels = sorted(set(points[sig[0]][0].tolist()))

    def stat(picked):
        out = []
        for s in sig:
            r = read_group(*sd._resample(points[s], picked), floor=floor)
            out += [r.plateau, r.c, r.c0]
        return np.array(out)

    reps = iv.seed_replicates(labels, stat, n_boot, rng_seed)
    want = []
    for i, s in enumerate(sig):
        r = read_group(*points[s], floor=floor)
        n = len(labels)
        want.append(dict(
            plateau_ci=sd._nonneg(iv.expanded(r.plateau, iv.percentile_interval(reps[3 * i]), n)),
            c_ci=sd._nonneg(iv.expanded(r.c, iv.percentile_interval(reps[3 * i + 1]), n)),
            c0_ci=sd._nonneg(iv.expanded(r.c0, iv.percentile_interval(reps[3 * i + 2]), n)),
            c_sd=iv.replicate_sd(reps[3 * i + 1])))
    return want


def test_each_groups_intervals_come_from_its_own_rows_of_one_bootstrap():
    pts = _tanh_points(1.0, (0.2, 0.4, 0.6, 0.8), seeds=5)
    for rng_seed in (0, 7):
        st = sd.study_k(0.5, pts, n_boot=15, rng_seed=rng_seed, floor=FLOOR)
        want = _reconstructed(pts, 15, rng_seed, FLOOR)
        assert st.ci_kind == sd.CIKind.SAME_SEEDS and st.n_labels == 5 and st.min_seeds == 5
        for g, w in zip(st.groups, want):
            assert g.k_tilde == 0.5 and isinstance(g.k_tilde, float) and g.n_seeds == 5
            for key, v in w.items():
                assert _same(getattr(g, key), v), (rng_seed, g.sigma_tilde, key)
    # the default stream is rng_seed 0
    st = sd.study_k(0.5, pts, n_boot=15, floor=FLOOR)
    assert _same([g.c_ci for g in st.groups], [w["c_ci"] for w in _reconstructed(pts, 15, 0,
                                                                                 FLOOR)])


def test_the_half_fraction_reaches_the_chord():
    from fibril_hpc.campaign.laws.reading import read_group

    pts = _tanh_points(1.0, (0.2, 0.4))
    st = sd.study_k(1.0, pts, n_boot=0, half=0.3, floor=FLOOR)
    for g in st.groups:
        want = read_group(*pts[g.sigma_tilde], half=0.3, floor=FLOOR).c_chord
        assert g.reading.c_chord == pytest.approx(want, rel=1e-12)
        assert want != pytest.approx(read_group(*pts[g.sigma_tilde], floor=FLOOR).c_chord)


def test_how_the_intervals_were_made_is_said():
    pts = _tanh_points(1.0, (0.2, 0.4), seeds=2)
    assert sd.study_k(1.0, pts, n_boot=5, floor=FLOOR).ci_kind == sd.CIKind.SAME_SEEDS
    assert sd.study_k(1.0, pts, n_boot=0, floor=FLOOR).ci_kind == sd.CIKind.OFF
    one = _tanh_points(1.0, (0.2, 0.4), seeds=1)
    st = sd.study_k(1.0, one, n_boot=5, floor=FLOOR)
    assert st.ci_kind == sd.CIKind.ONE_SEED and st.n_resamples == 0
    mixed = dict(pts)
    mixed[0.4] = _tanh_points(1.0, (0.4,), seeds=4)[0.4]
    st = sd.study_k(1.0, mixed, n_boot=5, floor=FLOOR)
    assert st.ci_kind == sd.CIKind.PAIRED_MIXED and st.n_labels == 4 and st.min_seeds == 2
    assert st.n_resamples == 5


def test_the_fit_points_and_their_sd():
    def g(sigma, in_fit, c, c_sd, c_detect, c_res, n):
        return SimpleNamespace(sigma_tilde=sigma, in_fit=in_fit, c_sd=c_sd, n_seeds=n,
                               reading=SimpleNamespace(c=c, c_detect=c_detect, c_res=c_res))

    gs = [g(0.1, True, 2.0, 0.3, 0.1, 0.4, 5), g(0.2, False, 1.0, 0.1, 0.1, 0.1, 4),
          g(0.3, True, 1.0, 0.05, 0.2, math.nan, 3), g(0.4, True, 0.5, math.nan, 0.1, 0.1, 6),
          g(0.5, True, 0.0, 0.0, 0.01, 0.02, 7)]
    s, c, sdev, n = sd._ab_points(gs)
    assert s == [0.1, 0.3, 0.4, 0.5] and c == [2.0, 1.0, 0.5, 0.0] and n == [5, 3, 6, 7]
    assert sdev[0] == pytest.approx(0.5) and sdev[1] == pytest.approx(0.2)
    assert math.isnan(sdev[2]) and sdev[3] == pytest.approx(math.hypot(0.01, 0.02))
    s, c, sdev2, n = sd._ab_points(gs, [9.0, 8.0, 7.0, 6.0])
    assert c == [9.0, 8.0, 7.0, 6.0] and _same(sdev, sdev2)


def _law_points(sigmas, seeds, beta=0.05, spread=0.6, bent=False):
    """{sigma~: points}: a sharp rise of slope c = 10 (1/sigma~ - beta) (x 1.3, 0.8 in turn where
    ``bent``: no line fits) x a seed factor that
    tilts with sigma~ (so resamples move alpha and beta apart, some to beta <= 0), plateau
    8 c x 0.1; ``seeds``: {sigma~: seed labels}."""
    out = {}
    for s in sorted(seeds):
        rows = []
        if s not in sigmas:             # lost: one pillar's pull-off at every preload
            rows = [(seed, x, x, FLOOR * (1 + 0.01 * seed)) for seed in seeds[s] for x in PRE]
            out[s] = tuple(np.array(v, dtype=float) for v in zip(*rows))
            continue
        for seed in seeds[s]:
            f = 1 + spread * (seed - 2) * (s - 0.5)
            zig = 1.0 if not bent else (1.3 if round(10 * s) % 4 == 1 else 0.8)
            c = 10 * (1 / s - beta) * zig * f * LOSS
            p = 0.8 * c
            rows += [(seed, x, x, min(max(FLOOR, c * x), p)) for x in PRE]
        out[s] = tuple(np.array(v, dtype=float) for v in zip(*rows))
    return out


def _ab_by_hand(pts, n_boot, rng_seed, floor, lost):
    """alpha, beta and alpha/beta with their intervals, from the module text."""
    from fibril_hpc.campaign.laws import intervals as iv
    from fibril_hpc.campaign.laws.alphabeta import fit_alpha_beta, t_interval
    from fibril_hpc.campaign.laws.reading import read_group

    sig = sorted(pts)
    sets = [sorted(set(pts[s][0].tolist())) for s in sig]
    uneven = any(x != sets[0] for x in sets)

    def stat(picked):
        out = []
        for i, s in enumerate(sig):
            r = read_group(*sd._resample(pts[s], picked[i] if uneven else picked), floor=floor)
            out += [r.plateau, r.c, r.c0]
        return np.array(out)

    labels = sorted(set().union(*map(set, sets)))
    reps = (iv.paired_replicates(sets, stat, n_boot, rng_seed) if uneven
            else iv.seed_replicates(labels, stat, n_boot, rng_seed))
    reads = [read_group(*pts[s], floor=floor) for s in sig]
    fit = [i for i, (s, r) in enumerate(zip(sig, reads)) if sd._out(s, r) == sd.OutReason.NONE]
    c_sd = [iv.replicate_sd(reps[3 * i + 1]) for i in range(len(sig))]
    sdev = [math.hypot(max(c_sd[i], reads[i].c_detect),
                       reads[i].c_res if math.isfinite(reads[i].c_res) else 0.0) for i in fit]
    x = [sig[i] for i in fit]
    ns = [len(sets[i]) for i in fit]
    ab = fit_alpha_beta(x, [reads[i].c for i in fit], sdev, lost=lost, n_seeds=ns)
    abr = []
    for b in range(n_boot):
        f = fit_alpha_beta(x, [reps[3 * i + 1, b] for i in fit], sdev, lost=lost, n_seeds=ns)
        abr.append((f.alpha, f.beta, f.alpha / f.beta if f.beta > 0 and f.alpha > 0
                    else (math.inf if f.ok and f.beta <= 0 else math.nan)))
    abr = np.array(abr).T
    n_l = min(len(sets[i]) for i in fit if reads[i].c > 0)
    sc = any(c_sd[i] > 0 for i in fit if reads[i].c > 0)
    a = sd._spread(iv.expanded(ab.alpha, iv.percentile_interval(abr[0]), n_l), sc)
    b = sd._spread(iv.expanded(ab.beta, iv.percentile_interval(abr[1]), n_l), sc)
    z = sd._spread(sd._nonneg(iv.expanded(ab.sigma_c, iv.percentile_interval(abr[2]), n_l)), sc)
    if ab.poor:
        ca, cb = t_interval(ab.alpha, ab.alpha_se, ab.dof), t_interval(ab.beta, ab.beta_se, ab.dof)
        a, b = (min(a[0], ca[0]), max(a[1], ca[1])), (min(b[0], cb[0]), max(b[1], cb[1]))
    return ab, a, b, z, float(np.mean(np.isinf(abr[2]))), len(labels), min(map(len, sets))


@pytest.mark.parametrize("uneven,lost,bent", [(False, "out", False), (True, "out", False),
                                               (True, "floor", False), (False, "out", True)])
def test_alpha_beta_and_their_intervals_against_the_module_text(uneven, lost, bent):
    sig = (0.3, 0.5, 0.7, 0.9, 1.1)
    seeds = {s: range(5) for s in sig + (1.5,)}       # lost at 1.5
    if uneven:          # seeds: auto: fewer seeds where c is largest, more at the end
        seeds[0.3] = range(3)
        seeds[1.1] = range(7)
        seeds[1.5] = range(2)
    pts = _law_points(sig, seeds, spread=0.6 if not bent else 0.02, bent=bent)
    st = sd.study_k(2.0, pts, n_boot=40, rng_seed=5, floor=FLOOR, lost=lost)
    ab, a, b, z, share, n_labels, min_seeds = _ab_by_hand(pts, 40, 5, FLOOR, lost)
    assert ab.ok and st.ab.alpha == pytest.approx(ab.alpha, rel=1e-12)
    assert st.groups[-1].reading.state == LOST and st.groups[-1].in_fit
    assert st.ab.beta == pytest.approx(ab.beta, rel=1e-12) and st.ab.lost == lost
    assert _same(st.alpha_ci, a) and _same(st.beta_ci, b) and _same(st.sigma_c_ci, z)
    assert st.unbounded_share == pytest.approx(share)
    if bent:        # c bends away from the line, seeds agree: a poor fit, widened
        assert ab.poor and st.widened_poor is True
    else:
        assert 0 < share < 0.5 if lost == "out" else share == 0.0
        assert not ab.poor and st.widened_poor is False
    assert (st.n_labels, st.min_seeds, st.n_resamples) == (n_labels, min_seeds, 40)
    assert st.k_tilde == 2.0 and not st.ab_from_cov and st.widened_poor == ab.poor
    # without resamples: the fit's own Student-t intervals
    from fibril_hpc.campaign.laws.alphabeta import t_interval
    st = sd.study_k(2.0, pts, n_boot=0, floor=FLOOR)
    assert st.ab_from_cov and st.n_resamples == 0
    assert _same(st.alpha_ci, t_interval(st.ab.alpha, st.ab.alpha_se, st.ab.dof))
    assert _same(st.beta_ci, t_interval(st.ab.beta, st.ab.beta_se, st.ab.dof))


def test_identical_seeds_give_point_intervals_not_none():
    # every seed the same brush: no scatter, so a zero-width interval is the answer (4 seeds
    # and 16 resamples: their means are exact, the sd exactly 0)
    sig = (0.3, 0.5, 0.7, 0.9)
    pts = _law_points(sig, {s: range(4) for s in sig}, spread=0.0)
    st = sd.study_k(1.0, pts, n_boot=16, floor=FLOOR)
    assert all(g.c_sd == 0.0 for g in st.groups)
    assert st.alpha_ci == pytest.approx((st.ab.alpha, st.ab.alpha), rel=1e-9)
    assert st.beta_ci == pytest.approx((st.ab.beta, st.ab.beta), rel=1e-9)


def test_a_k_without_points_is_no_study():
    st = sd.study_k(1.0, {}, n_boot=5)
    assert (st.min_seeds, st.n_labels, st.n_resamples) == (0, 0, 0)
    assert st.ci_kind == sd.CIKind.ONE_SEED and not st.ab.ok and st.groups == []

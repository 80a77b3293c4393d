"""laws.precision, pinned so that its one-line mutations fail (issue 34; benchmarks/mutation.py):
what ``seeds: auto`` asks of a group - the seed intervals widened for the seed count, the widths
against the target, the "is the state certain" rule for lost and for rising groups (borderline
plateaus that straddle the loss threshold, not assumed away), and the seed count it predicts
with the small-sample factor, at its exact boundaries."""

import math

import numpy as np
import pytest

from fibril_hpc.campaign.laws import precision as pr
from fibril_hpc.campaign.laws.intervals import (
    expanded,
    percentile_interval,
    seed_replicates,
    small_sample_factor,
)
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, UNDETERMINED, UNRESOLVED, read_group

from synthetic_campaigns import FLOOR, Truth, group

PRE = tuple(float(v) for v in np.geomspace(1e-3, 10.0, 9))
NB = 40          # resamples where the test is not of the default
THR = 3.0 * FLOOR


def _reference(pts, floor, n_boot=pr.N_BOOT, rng_seed=0):
    """The seed intervals of plateau and c as the module text defines them: a bootstrap over
    the group's seed labels (each drawn seed a seed of its own), widened for n seeds."""
    seed = np.asarray(pts[0])
    labels = sorted(set(seed.tolist()))

    def stat(picked):
        sel, lab = [], []
        for j, s in enumerate(picked):
            i = np.flatnonzero(seed == s)
            sel += i.tolist()
            lab += [j] * i.size
        r = read_group(np.array(lab), *(np.asarray(a, float)[sel] for a in pts[1:]), floor=floor)
        return [r.plateau, r.c]

    r = read_group(*pts, floor=floor)
    reps = seed_replicates(labels, stat, n_boot, rng_seed)
    n = len(labels)
    return (expanded(r.plateau, percentile_interval(reps[0]), n),
            expanded(r.c, percentile_interval(reps[1]), n))


def test_relative_width_is_full_width_over_the_magnitude_and_inf_where_undefined():
    assert pr.relative_width(2.0, (1.0, 2.5)) == 0.75
    assert pr.relative_width(-2.0, (-2.5, -1.0)) == 0.75           # over |value|
    for v, ci in [(0.0, (1.0, 2.0)), (math.nan, (1.0, 2.0)), (math.inf, (1.0, 2.0)),
                  (1.0, (math.nan, 2.0)), (1.0, (1.0, math.nan)), (1.0, (-math.inf, 2.0)),
                  (1.0, (1.0, math.inf))]:
        assert pr.relative_width(v, ci) == math.inf, (v, ci)


def test_intervals_are_the_seed_bootstrap_widened_for_the_seed_count():
    t = Truth("sharp", 1.0, 1.5, c_sd=0.1, P_sd=0.05)
    seed, pre, x, y = group(t, 4, PRE, rng=3)
    # the reached F~_P is not the preload asked for (each seed's own, as in real records):
    # the levels are the requested preloads, never the reached forces
    x = x * (1 + 0.01 * np.random.default_rng(9).standard_normal(x.size))
    pts = (seed, pre, x, y)
    p = pr.group_precision(*pts, floor=FLOOR, width=0.2)
    p_ci, c_ci = _reference(pts, FLOOR)
    assert p.state == RESOLVED and p.n_seeds == 4
    np.testing.assert_allclose(p.plateau_ci, p_ci, rtol=1e-12)
    np.testing.assert_allclose(p.c_ci, c_ci, rtol=1e-12)
    r = read_group(*pts, floor=FLOOR)
    assert p.plateau == r.plateau and p.c == r.c and p.threshold == THR
    # wider than the bare bootstrap by the 4-seed factor (not 3's or 5's)
    raw_hi = r.plateau + (p_ci[1] - r.plateau) / small_sample_factor(4)
    assert (p.plateau_ci[1] - r.plateau) / (raw_hi - r.plateau) == pytest.approx(
        small_sample_factor(4), rel=1e-9)
    # the defaults are the module's fixed bootstrap: the same numbers every time
    again = pr.group_precision(*pts, floor=FLOOR, width=0.2, n_boot=pr.N_BOOT, rng_seed=0)
    assert again.plateau_ci == p.plateau_ci and again.c_ci == p.c_ci
    fewer = pr.group_precision(*pts, floor=FLOOR, width=0.2, n_boot=NB)
    np.testing.assert_allclose(fewer.plateau_ci, _reference(pts, FLOOR, n_boot=NB)[0], rtol=1e-12)
    other = pr.group_precision(*pts, floor=FLOOR, width=0.2, n_boot=NB, rng_seed=1)
    assert other.plateau_ci != fewer.plateau_ci


def test_a_resampled_seed_drawn_twice_counts_twice():
    """Seeds whose labels are not 0..n-1 and a resample holding one seed twice: the reading of
    a resample treats each draw as its own seed (a merged label would halve its weight)."""
    t = Truth("sharp", 1.0, 1.5, c_sd=0.2, P_sd=0.2)
    seed, pre, x, y = group(t, 3, PRE, rng=11)
    pts = (seed * 7 + 5, pre, x, y)                      # labels 5, 12, 19
    p = pr.group_precision(*pts, floor=FLOOR, width=0.2, n_boot=NB)
    p_ci, c_ci = _reference(pts, FLOOR, n_boot=NB)
    np.testing.assert_allclose(p.plateau_ci, p_ci, rtol=1e-12)
    np.testing.assert_allclose(p.c_ci, c_ci, rtol=1e-12)


def test_widths_name_what_is_short_in_order_and_their_values():
    t = Truth("sharp", 1.0, 1.5, c_sd=0.3, P_sd=0.3)
    p = pr.group_precision(*group(t, 3, PRE, rng=2), n_boot=NB, floor=FLOOR, width=0.05)
    assert p.state == RESOLVED and p.short == ("plateau", "c") and not p.met
    assert p.widths == (pr.relative_width(p.plateau, p.plateau_ci), pr.relative_width(p.c, p.c_ci))
    assert all(w > 0.05 for w in p.widths)
    # the same group against a target wider than both: met, nothing short
    wide = pr.group_precision(*group(t, 3, PRE, rng=2), n_boot=NB, floor=FLOOR, width=max(p.widths) * 1.01)
    assert wide.met and wide.short == () and wide.widths == ()
    # only c short: a target between the two widths
    wp, wc = p.widths
    if wp < wc:
        mid = pr.group_precision(*group(t, 3, PRE, rng=2), n_boot=NB, floor=FLOOR, width=(wp + wc) / 2)
        assert mid.short == ("c",) and mid.widths == (wc,)


def _flat_seeds(values, n_seeds=3, floor=1.0, rise=True):
    """A group whose every seed draws exactly the same curve: zero seed scatter, intervals of
    width 0 exactly at the value (the boundaries of the target and of the threshold)."""
    rows = []
    for s in range(n_seeds):
        for p, v in zip((0.01, 0.1, 1.0, 10.0, 100.0), values):
            rows.append((s, p, p, v))
    return tuple(np.array(c) for c in zip(*rows))


def test_a_zero_width_meets_a_zero_target_exactly():
    pts = _flat_seeds([0.2, 2.0, 8.0, 8.0, 8.0])            # resolved, plateau 8 > 3 floors of 1
    p = pr.group_precision(*pts, n_boot=NB, floor=1.0, width=0.0)
    assert p.state == RESOLVED and p.plateau_ci == (8.0, 8.0)
    assert p.c_ci[0] == p.c_ci[1] == p.c
    assert p.met and p.short == ()                          # 0 > 0 is false: nothing short


def test_a_lost_plateau_exactly_at_the_threshold_is_certainly_lost():
    pts = _flat_seeds([1.0, 2.0, 3.0, 3.0, 3.0])            # plateau 3 = 3 pillars of 1
    p = pr.group_precision(*pts, n_boot=NB, floor=1.0, width=0.2)
    assert p.state == LOST and p.plateau_ci == (3.0, 3.0) and p.threshold == 3.0
    assert p.met and p.short == ()


def test_lost_groups_are_short_only_of_their_state():
    """A lost group's plateau of one to three pillars scatters widely whatever the seeds: only
    whether it is lost counts; certain when the plateau interval lies below the threshold."""
    tight = pr.group_precision(*group(Truth("lost", 0.0, FLOOR), 3, PRE, rng=1), n_boot=NB, floor=FLOOR,
                               width=0.01)
    assert tight.state == LOST and tight.plateau_ci[1] < THR
    assert tight.met and tight.short == () and tight.widths == ()
    assert tight.c == 0.0 and tight.c_ci == (0.0, 0.0)        # resamples read as lost too
    # borderline: a plateau of 2.7 pillars scattering 20 % over seeds reaches above 3 pillars
    loud = Truth("sharp", 50.0, 2.7 * FLOOR, c_sd=0.05, P_sd=0.2)
    p = pr.group_precision(*group(loud, 3, PRE, rng=4), n_boot=NB, floor=FLOOR, width=10.0)
    assert p.state == LOST and p.plateau <= THR < p.plateau_ci[1]
    assert p.short == ("state",) and p.widths == (math.inf,)
    # one seed: no interval, so the state is not certain
    one = pr.group_precision(*group(Truth("lost", 0.0, FLOOR), 1, PRE, rng=1), n_boot=NB, floor=FLOOR,
                             width=10.0)
    assert one.state == LOST and math.isnan(one.plateau_ci[1]) and one.short == ("state",)


@pytest.mark.parametrize("shape", ["sharp", "instant"])
def test_a_rising_group_whose_plateau_interval_reaches_the_threshold_is_not_certain(shape):
    """Borderline rises (a plateau of 3.3 pillars, 15 % seed scatter): the interval straddles
    the threshold, so the group is not yet told from a lost one, whatever the widths."""
    c = 1.0 if shape == "sharp" else math.nan
    t = Truth(shape, c, 3.3 * FLOOR, c_sd=0.05, P_sd=0.15)
    p = pr.group_precision(*group(t, 3, PRE, rng=5), n_boot=NB, floor=FLOOR, width=10.0)
    assert p.state == (RESOLVED if shape == "sharp" else UNRESOLVED)
    assert p.plateau > THR and p.plateau_ci[0] <= THR
    assert p.short == ("state",) and p.widths == (math.inf,)
    # the same rise well above the threshold: certain, met
    t = Truth(shape, c, 30 * FLOOR, c_sd=0.05, P_sd=0.15)
    p = pr.group_precision(*group(t, 3, PRE, rng=5), n_boot=NB, floor=FLOOR, width=10.0)
    assert p.plateau_ci[0] > THR and p.met


def test_without_a_floor_a_rise_has_no_state_to_be_certain_of():
    t = Truth("sharp", 1.0, 1.5, c_sd=0.05, P_sd=0.05)
    p = pr.group_precision(*group(t, 3, PRE, rng=6), n_boot=NB, floor=math.nan, width=10.0)
    assert p.state == RESOLVED and math.isnan(p.threshold) and p.met
    flat = pr.group_precision(*group(Truth("lost", 0.0, FLOOR), 3, PRE, rng=6), n_boot=NB, floor=math.nan,
                              width=0.0)
    assert flat.state == UNDETERMINED and flat.met and flat.short == ()


def test_an_unresolved_rise_is_judged_on_its_plateau_only():
    t = Truth("instant", math.nan, 1.5, P_sd=0.3)
    p = pr.group_precision(*group(t, 3, PRE, rng=7), n_boot=NB, floor=FLOOR, width=0.01)
    assert p.state == UNRESOLVED and p.short == ("plateau",)
    assert p.widths == (pr.relative_width(p.plateau, p.plateau_ci),)


def _prec(n, widths, short=None):
    short = short if short is not None else tuple("plateau" for _ in widths)
    return pr.Precision(RESOLVED, n, 1.0, (0.9, 1.1), 1.0, (0.9, 1.1), THR, short, tuple(widths))


def _predicted(n, w, width, mx, factor=True):
    f = small_sample_factor if factor else (lambda m: 1.0)
    for m in range(n + 1, mx + 1):
        if w * f(m) / f(n) * math.sqrt(n / m) <= width:
            return m
    return mx


def test_seeds_needed_keeps_a_met_group_and_one_at_the_max():
    assert pr.seeds_needed(_prec(3, ()), 0.2, 10) == 3
    assert pr.seeds_needed(_prec(10, (5.0,)), 0.2, 10) == 10
    assert pr.seeds_needed(_prec(12, (5.0,)), 0.2, 10) == 12


def test_seeds_needed_doubles_without_a_finite_width():
    assert pr.seeds_needed(_prec(3, (math.inf,), ("state",)), 0.2, 10) == 6
    assert pr.seeds_needed(_prec(3, (0.3, math.inf)), 0.2, 10) == 6       # the largest decides
    assert pr.seeds_needed(_prec(4, (math.inf,)), 0.2, 7) == 7           # at most max
    assert pr.seeds_needed(_prec(1, (0.5,)), 0.2, 10) == 2               # one seed: no scaling
    assert pr.seeds_needed(_prec(1, (math.inf,)), 0.2, 10) == 2
    assert pr.seeds_needed(_prec(0, (math.inf,)), 0.2, 10) == 1          # at least one more


def test_seeds_needed_predicts_with_the_small_sample_factor():
    """The referee's survivor: the prediction without f(n')/f(n) asks for more seeds."""
    n, w, width, mx = 3, 0.45, 0.2, 30
    want = _predicted(n, w, width, mx)
    assert want == pr.seeds_needed(_prec(n, (w,)), width, mx)
    assert want != _predicted(n, w, width, mx, factor=False)            # the case tells them apart
    # the largest width decides, not the smallest
    assert pr.seeds_needed(_prec(n, (0.21, w)), width, mx) == want
    # two seeds scale too (not doubled)
    two = _predicted(2, 0.3, width, mx)
    assert pr.seeds_needed(_prec(2, (0.3,)), width, mx) == two and two != 4


def test_seeds_needed_boundaries_are_exact():
    n, mx = 3, 20
    # a target met exactly at m seeds: m, not m + 1
    for m in (4, 6):
        width = 0.5 * small_sample_factor(m) / small_sample_factor(n) * math.sqrt(n / m)
        assert pr.seeds_needed(_prec(n, (0.5,)), width, mx) == m
    # met already at one more seed: n + 1
    assert pr.seeds_needed(_prec(n, (0.21,)), 0.2, mx) == n + 1
    # met first at max + 1: max
    w = 0.2 / (small_sample_factor(mx + 1) / small_sample_factor(n) * math.sqrt(n / (mx + 1)))
    assert _predicted(n, w, 0.2, mx + 1) == mx + 1
    assert pr.seeds_needed(_prec(n, (w,)), 0.2, mx) == mx
    # met first at max - 1: max - 1
    w = 0.2 / (small_sample_factor(mx - 1) / small_sample_factor(n) * math.sqrt(n / (mx - 1)))
    w *= 1 - 1e-12
    assert _predicted(n, w, 0.2, mx) == mx - 1
    assert pr.seeds_needed(_prec(n, (w,)), 0.2, mx) == mx - 1
    # never met: max
    assert pr.seeds_needed(_prec(n, (100.0,)), 0.2, mx) == mx

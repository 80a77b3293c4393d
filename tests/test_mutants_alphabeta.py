"""laws.alphabeta, pinned so that its one-line mutations fail (issue 34, item 6;
benchmarks/mutation.py): the law and its cut at 0, every field of a fit that is no line, how
lost groups enter in each mode (left out, floored at the finest rising sd, held at or below 0
from the first lost sigma~), the active points and the degrees of freedom, the weights and the
small-sample widening, the poor-fit test and its threshold, the covariance and the t interval
against synthetic truth (a line with known seed scatter, its intervals covering alpha and beta
at the rate they claim), and the zero alpha/beta with its notes."""

import math

import numpy as np
import pytest
from scipy import stats

from fibril_hpc.campaign.laws import alphabeta as ab
from fibril_hpc.campaign.laws.alphabeta import Note, fit_alpha_beta, poor_threshold, t_interval

S = np.array([0.2, 0.3, 0.45, 0.6, 0.8])
A_TRUE, B_TRUE = 1.0, 0.9                     # zero at 1.111
C_TRUE = A_TRUE / S - B_TRUE


def _wls(s, c, sd):
    """Weighted least squares of c = alpha/s - beta (no cut), and its covariance: the textbook
    solution, independent of the module's optimiser."""
    s, c, sd = (np.asarray(v, float) for v in (s, c, sd))
    X = np.column_stack([1 / s, -np.ones_like(s)]) / sd[:, None]
    coef, *_ = np.linalg.lstsq(X, c / sd, rcond=None)
    return coef, np.linalg.inv(X.T @ X)


def test_the_law_is_the_line_cut_at_zero():
    s = [0.5, 1.0, 2.0, 4.0]
    np.testing.assert_array_equal(ab.model(s, 1.0, 0.75), [1.25, 0.25, 0.0, 0.0])
    assert ab.model(2, 1.0, 0.25) == pytest.approx(0.25)       # a scalar sigma~
    np.testing.assert_array_equal(ab.model(np.array([1, 2]), 3, 1), [2.0, 0.5])


def test_a_fit_of_fewer_than_two_rising_points_is_no_line_and_says_so():
    f = fit_alpha_beta([0.3, 0.9, 1.5, 0.0, -1.0, math.nan], [0.4, 0.0, 0.0, 2.0, 1.0, 1.0],
                       [0.1, 1e-5, 1e-5, 0.1, 0.1, 0.1], lost="floor")
    assert not f.ok and not f.enough
    for v in (f.alpha, f.beta, f.sigma_c, f.alpha_se, f.beta_se, f.chi2_red):
        assert math.isnan(v)
    assert f.n_points == 3 and f.n_zero == 2          # sigma~ <= 0 and NaN are no points
    assert f.sigmas == (0.3, 0.9, 1.5) and f.residuals == ()
    assert f.poor is False and f.weighted is False
    assert f.bracket == (0.3, 0.9)
    assert f.notes == [Note.TOO_FEW_RISING, Note.LOST_IN]
    assert f.n_active == 0 and f.dof == 0 and f.lost == "floor"
    none = fit_alpha_beta([0.5, 1.0], [0.0, 0.0])
    assert none.notes == [Note.TOO_FEW_RISING, Note.LOST_OUT] and none.lost == "out"
    assert math.isnan(none.bracket[0]) and none.bracket[1] == 0.5     # lost from the first
    one = fit_alpha_beta([0.5], [1.0])
    assert one.notes == [Note.TOO_FEW_RISING] and one.n_zero == 0 and one.n_points == 1
    assert one.bracket[0] == 0.5 and math.isnan(one.bracket[1])


def test_an_unknown_lost_mode_is_refused_by_name():
    with pytest.raises(ValueError, match=r"^lost: 'in' is not one of \('out', 'floor', "
                                         r"'censored', 'own'\)$"):
        fit_alpha_beta(S, C_TRUE, lost="in")


def test_an_exact_line_is_recovered_with_every_field():
    sd = np.full(S.size, 0.05)
    s = np.append(S, [1.3, 2.0, 1.2])          # three lost points beyond the line's zero
    c = np.append(C_TRUE, [0.0, 0.0, 0.0])
    sd = np.append(sd, [1e-5, 1e-5, 1e-5])
    for mode in ab.LOST_MODES:
        f = fit_alpha_beta(s, c, sd, lost=mode)
        assert f.ok and f.enough and f.weighted and not f.poor, mode
        assert f.alpha == pytest.approx(A_TRUE, rel=1e-7), mode
        assert f.beta == pytest.approx(B_TRUE, rel=1e-7), mode
        assert f.sigma_c == pytest.approx(A_TRUE / B_TRUE, rel=1e-7)
        assert f.n_points == 8 and f.n_zero == 3 and f.lost == mode
        assert f.bracket == (0.8, 1.2)
        assert f.sigmas == tuple(float(v) for v in s)
        np.testing.assert_allclose(f.residuals, 0.0, atol=1e-7)
        assert f.chi2_red == pytest.approx(0.0, abs=1e-9)
        assert f.notes == [Note.LOST_OUT if mode == "out" else Note.LOST_IN], mode
        # the lost points lie where the line is below 0 (and the censored line's zero, 1.11,
        # is below the first lost sigma~, 1.2: the constraint does not bind): none is active
        assert f.n_active == 5 and f.dof == 3, mode
        # the covariance is the textbook one of the five rising points (chi^2/dof < 1: not
        # scaled)
        _, cov = _wls(S, C_TRUE, np.full(S.size, 0.05))
        assert (f.alpha_se, f.beta_se) == pytest.approx(np.sqrt(np.diag(cov)), rel=1e-6)


def test_standard_errors_and_t_intervals_cover_alpha_and_beta_at_their_rate():
    """Synthetic truth: the same line with normal scatter of a known sd per point. The fit's
    alpha, beta and standard errors are the weighted least-squares ones (scaled by chi^2/dof
    where it exceeds 1): the unscaled ones are right, alpha -+ 1.96 se holding the truth about
    95 % of the time; t_interval's 95 % intervals (Student t with the fit's dof, the scaled se)
    hold it at least that often (conservative where the sd is known)."""
    rng = np.random.default_rng(7)
    sd = np.array([0.4, 0.2, 0.1, 0.06, 0.04])
    held_a = held_b = z_a = z_b = n = 0
    draws = 200
    for _ in range(draws):
        c = C_TRUE + sd * rng.standard_normal(S.size)
        f = fit_alpha_beta(S, c, sd)
        if not np.all(c > 0):
            continue
        n += 1
        coef, cov = _wls(S, c, sd)
        assert (f.alpha, f.beta) == pytest.approx(tuple(coef), rel=1e-6, abs=1e-9)
        scale = max(f.chi2_red, 1.0)
        assert (f.alpha_se, f.beta_se) == pytest.approx(tuple(np.sqrt(np.diag(cov) * scale)),
                                                        rel=1e-6)
        assert f.dof == 3 and f.n_active == 5
        z_a += abs(f.alpha - A_TRUE) <= 1.96 * f.alpha_se / math.sqrt(scale)
        z_b += abs(f.beta - B_TRUE) <= 1.96 * f.beta_se / math.sqrt(scale)
        held_a += t_interval(f.alpha, f.alpha_se, f.dof)[0] <= A_TRUE <= \
            t_interval(f.alpha, f.alpha_se, f.dof)[1]
        held_b += t_interval(f.beta, f.beta_se, f.dof)[0] <= B_TRUE <= \
            t_interval(f.beta, f.beta_se, f.dof)[1]
    assert n >= 0.9 * draws
    assert 0.9 * n <= z_a <= 0.99 * n and 0.9 * n <= z_b <= 0.99 * n, (z_a, z_b, n)
    assert held_a >= 0.95 * n and held_b >= 0.95 * n, (held_a, held_b, n)


def test_t_interval_is_student_t_about_the_value():
    for v, se, dof, level in ((2.0, 0.5, 1, 0.95), (-1.0, 0.1, 7, 0.9), (0.0, 3.0, 30, 0.5)):
        assert t_interval(v, se, dof, level) == pytest.approx(
            stats.t.interval(level, dof, loc=v, scale=se), rel=1e-12)
    assert t_interval(2.0, 0.5, 4) == pytest.approx(stats.t.interval(0.95, 4, loc=2.0, scale=0.5))
    for args in ((2.0, 0.5, 0), (math.nan, 0.5, 3), (2.0, math.nan, 3), (math.inf, 0.5, 3),
                 (2.0, math.inf, 3)):
        lo, hi = t_interval(*args)
        assert math.isnan(lo) and math.isnan(hi), args


def test_a_poor_fit_is_flagged_and_its_errors_scaled_by_chi2_per_dof():
    sd = np.full(S.size, 0.01)
    wiggle = np.array([0.1, -0.1, 0.1, -0.1, 0.1])
    f = fit_alpha_beta(S, C_TRUE + wiggle, sd)
    coef, cov = _wls(S, C_TRUE + wiggle, sd)
    chi2 = float(np.sum(((C_TRUE + wiggle - (coef[0] / S - coef[1])) / sd) ** 2))
    assert f.poor and f.notes == [Note.POOR] and f.weighted
    assert f.chi2_red == pytest.approx(chi2 / 3, rel=1e-6)
    assert f.chi2_red * 3 > poor_threshold(3, [math.nan] * 5)
    assert (f.alpha_se, f.beta_se) == pytest.approx(tuple(np.sqrt(np.diag(cov) * chi2 / 3)),
                                                    rel=1e-6)
    np.testing.assert_allclose(f.residuals, C_TRUE + wiggle - (coef[0] / S - coef[1]),
                               atol=1e-8)
    # just below the threshold: not poor, still scaled (chi^2/dof > 1)
    thr = poor_threshold(3, [math.nan] * 5)
    under = fit_alpha_beta(S, C_TRUE + wiggle * math.sqrt(0.95 * thr / chi2), sd)
    assert not under.poor and under.notes == [] and under.chi2_red > 1
    c_u = C_TRUE + wiggle * math.sqrt(0.95 * thr / chi2)
    coef_u, cov_u = _wls(S, c_u, sd)
    assert under.alpha_se == pytest.approx(math.sqrt(cov_u[0, 0] * under.chi2_red), rel=1e-6)
    over = fit_alpha_beta(S, C_TRUE + wiggle * math.sqrt(1.05 * thr / chi2), sd)
    assert over.poor


def test_one_seed_is_unweighted_with_errors_from_the_residuals():
    wiggle = np.array([0.05, -0.05, 0.05, -0.05, 0.05])
    for sd in (None, [0.1, 0.1, math.nan, 0.1, 0.1], [0.1, 0.1, 0.0, 0.1, 0.1]):
        f = fit_alpha_beta(S, C_TRUE + wiggle, sd)
        coef, cov = _wls(S, C_TRUE + wiggle, np.ones(S.size))
        r = C_TRUE + wiggle - (coef[0] / S - coef[1])
        assert not f.weighted and f.poor is False and f.notes == [Note.UNWEIGHTED]
        assert (f.alpha, f.beta) == pytest.approx(tuple(coef), rel=1e-7)
        assert f.chi2_red == pytest.approx(float(np.sum(r ** 2)) / 3, rel=1e-6)
        assert (f.alpha_se, f.beta_se) == pytest.approx(
            tuple(np.sqrt(np.diag(cov) * np.sum(r ** 2) / 3)), rel=1e-6)


def test_few_seeds_widen_each_sd_and_the_poor_test_knows_it():
    sd = np.full(S.size, 0.01)
    wiggle = np.array([0.01, -0.01, 0.01, -0.01, 0.01])
    plain = fit_alpha_beta(S, C_TRUE + wiggle, sd)
    for n, factor in ((2, 2.0), (3, 1.5), (10, 10 / 9)):
        f = fit_alpha_beta(S, C_TRUE + wiggle, sd, n_seeds=[n] * 5)
        assert f.chi2_red == pytest.approx(plain.chi2_red / factor, rel=1e-9), n
        assert (f.alpha, f.beta) == pytest.approx((plain.alpha, plain.beta), rel=1e-9)
    one = fit_alpha_beta(S, C_TRUE + wiggle, sd, n_seeds=[1] * 5)
    assert one.chi2_red == pytest.approx(plain.chi2_red, rel=1e-12)
    # the seeds of invalid points are dropped with the points, not shifted onto others
    s = np.append([0.0], S)
    shifted = fit_alpha_beta(s, np.append([9.0], C_TRUE + wiggle), np.append([0.01], sd),
                             n_seeds=[3] + [2] * 5)
    assert shifted.chi2_red == pytest.approx(plain.chi2_red / 2, rel=1e-9)
    # flagged poor by chi^2 but not by the sum of t^2 of 3-seed sds
    thr_n = poor_threshold(3, [math.nan] * 5)
    thr_3 = poor_threshold(3, [3] * 5)
    scale = math.sqrt(1.2 * thr_n / (plain.chi2_red * 3))
    c = C_TRUE + wiggle * scale
    assert fit_alpha_beta(S, c, sd).poor
    k = math.sqrt(0.9 * thr_3 * 1.5 / (thr_n * 1.2))      # 3-seed chi^2 at 0.9 of its threshold
    assert not fit_alpha_beta(S, C_TRUE + wiggle * scale * k, sd, n_seeds=[3] * 5).poor
    assert fit_alpha_beta(S, C_TRUE + wiggle * scale * k * 1.2, sd, n_seeds=[3] * 5).poor


def test_the_poor_threshold_is_the_quantile_of_a_sum_of_t_squares():
    """Against an independent Monte Carlo (another stream, 10 x the draws): the threshold is the
    ``quantile`` point of dof/m sum_i t_(n_i - 1)^2; points of 30 seeds or more, of fewer than
    2, or of unknown seeds count as normal, and all normal is the chi^2 quantile exactly."""
    rng = np.random.default_rng(12345)

    def reference(dof, ns, q=0.99, size=200_000):
        t2 = np.zeros(size)
        for n in ns:
            t2 += (rng.standard_t(n - 1, size) if 2 <= n < 30 else rng.standard_normal(size)) ** 2
        return float(np.quantile(t2 * dof / len(ns), q))

    for dof, ns, q in ((3, [3] * 5, 0.99), (2, [4, 4, 10, 40], 0.99), (5, [5] * 7, 0.9),
                       (1, [6, 6, 6], 0.99)):
        assert poor_threshold(dof, ns, q) == pytest.approx(reference(dof, ns, q), rel=0.05), \
            (dof, ns, q)
    for ns in ([30] * 5, [1] * 5, [math.nan] * 5, [math.inf] * 5, [100, 1, 30, math.nan, 31]):
        assert poor_threshold(3, ns) == stats.chi2.ppf(0.99, 3), ns
    assert poor_threshold(4, [40] * 6, 0.9) == stats.chi2.ppf(0.9, 4)
    assert poor_threshold(4.7, [40] * 6) == stats.chi2.ppf(0.99, 4)          # dof is a count
    # the boundaries of "a few seeds": 2 seeds are t with 1 dof (far heavier than normal),
    # 29 are t, 30 are normal; the order of the points does not matter
    assert poor_threshold(3, [2, 5]) > 2 * poor_threshold(3, [1, 5])
    assert poor_threshold(3, [5, 30]) == poor_threshold(3, [5, 1000]) == poor_threshold(
        3, [5, math.nan]) == poor_threshold(3, [30, 5])
    assert poor_threshold(3, [5, 29]) != poor_threshold(3, [5, 30])
    assert poor_threshold(3, [3, 5, 7]) == poor_threshold(3, (7, 3, 5))
    for dof in (0, -1):
        assert math.isnan(poor_threshold(dof, [3] * 4)) and math.isnan(poor_threshold(dof, [50]))


def test_lost_groups_enter_as_their_mode_says():
    """c levels off: the free line's zero lies beyond the first lost sigma~ (1.2)."""
    s = [0.2, 0.3, 0.5, 0.7, 0.9, 1.2, 1.6]
    c = [4.1, 2.2, 1.1, 0.65, 0.5, 0.0, 0.0]
    sd_r = [0.2, 0.1, 0.05, 0.03, 0.02]
    out = fit_alpha_beta(s, c, sd_r + [7.0, 3.0])
    free, _ = _wls(s[:5], c[:5], sd_r)
    assert (out.alpha, out.beta) == pytest.approx(tuple(free), rel=1e-6)
    assert out.sigma_c > 1.6 and out.n_active == 5 and out.dof == 3
    np.testing.assert_allclose(out.residuals[5:], -(free[0] / np.array([1.2, 1.6]) - free[1]),
                               rtol=1e-6)
    # floor: each lost point weighs as the finest rising sd, whatever its own sd
    floor = fit_alpha_beta(s, c, sd_r + [7.0, math.nan], lost="floor")
    own = fit_alpha_beta(s, c, sd_r + [0.02, 0.02], lost="own")
    assert (floor.alpha, floor.beta) == pytest.approx((own.alpha, own.beta), rel=1e-7)
    assert floor.chi2_red == pytest.approx(own.chi2_red, rel=1e-7) and floor.weighted
    not_max = fit_alpha_beta(s, c, sd_r + [0.2, 0.2], lost="own")
    assert floor.beta != pytest.approx(not_max.beta, rel=1e-3)
    assert floor.n_active == 6 and floor.dof == 4     # above 0 at 1.2, not at 1.6
    assert 1.2 < floor.sigma_c < 1.6
    assert floor.sigma_c < out.sigma_c
    # floor with a rising sd that is not finite: no weights, the lost points unweighted too
    nan_sd = fit_alpha_beta(s, c, [0.2, math.nan, 0.05, 0.03, 0.02, 1.0, 1.0], lost="floor")
    unw = fit_alpha_beta(s, c, None, lost="own")
    assert not nan_sd.weighted and nan_sd.beta == pytest.approx(unw.beta, rel=1e-7)
    # censored: the line is held at or below 0 from 1.2 on; it binds and counts as a point
    cen = fit_alpha_beta(s, c, sd_r + [7.0, 3.0], lost="censored")
    assert cen.sigma_c == pytest.approx(1.2, rel=1e-6) and cen.n_active == 6 and cen.dof == 4
    assert cen.notes == [Note.LOST_IN, Note.POOR]          # c levels off: not the law
    # where the free line already reaches 0 below 1.2, the constraint does not bind
    c2 = list(ab.model(s[:5], 1.0, 1.0)) + [0.0, 0.0]
    loose = fit_alpha_beta(s, c2, sd_r + [1.0, 1.0], lost="censored")
    assert loose.sigma_c == pytest.approx(1.0, rel=1e-6) and loose.n_active == 5


def test_a_lost_point_is_active_only_where_the_line_is_above_zero():
    s = [0.2, 0.3, 0.5, 0.7, 1.2, 3.0]
    c = list(ab.model(s[:4], 1.0, 1.0)) + [0.0, 0.0]      # the line's zero at 1.0
    f = fit_alpha_beta(s, c, [0.1, 0.05, 0.03, 0.02, 0.02, 0.02], lost="own")
    assert f.sigma_c == pytest.approx(1.0, rel=1e-6)
    assert f.n_active == 4 and f.dof == 2 and f.enough


def test_the_zero_and_its_notes():
    up = fit_alpha_beta(S, 1.0 / S + 0.5, [0.05] * 5)        # beta < 0: never reaches 0
    assert up.beta == pytest.approx(-0.5, rel=1e-6) and math.isnan(up.sigma_c)
    assert up.notes == [Note.BETA_NONPOS]
    flat = fit_alpha_beta(S, 0.0 / S + 1.0, [0.05] * 5)      # beta = -1 exactly, alpha = 0
    assert flat.alpha == pytest.approx(0.0, abs=1e-7) and math.isnan(flat.sigma_c)
    rising = fit_alpha_beta(S, -0.5 / S + 4.0, [0.05] * 5)   # alpha < 0, beta < 0
    assert rising.notes == [Note.BETA_NONPOS]
    odd = fit_alpha_beta([0.2, 0.3, 0.5], [0.5, 1.0, 1.5], [0.05] * 3)   # c rises with sigma~
    assert odd.alpha < 0 and odd.beta < 0 and odd.notes == [Note.POOR, Note.BETA_NONPOS] or \
        odd.notes == [Note.BETA_NONPOS]
    # (alpha <= 0 < beta puts the line below 0 at every sigma~: no fit of c > 0 ends there)


def test_enough_needs_three_active_points_and_one_dof():
    two = fit_alpha_beta([0.3, 0.6], [2.0, 0.5], [0.05, 0.05])
    assert two.ok and not two.enough and two.n_active == 2 and two.dof == 0
    assert Note.TOO_FEW_ACTIVE in two.notes and math.isnan(two.chi2_red)
    assert Note.UNWEIGHTED not in two.notes and Note.POOR not in two.notes
    three = fit_alpha_beta([0.3, 0.6, 0.9], [2.0, 0.5, 0.1], [0.05] * 3)
    assert three.enough and three.dof == 1 and Note.TOO_FEW_ACTIVE not in three.notes
    fake = ab.ABFit(1.0, 0.5, 2.0, 0.1, 0.1, 3, 0, (), (), 0.5, False, True, (1, 2),
                    n_active=3, dof=0)
    assert fake.ok and not fake.enough
    fake.dof = 1
    assert fake.enough
    fake.n_active = 2
    assert not fake.enough
    fake.n_active, fake.beta = 3, math.nan
    assert not fake.ok and not fake.enough


def test_the_bracket_is_the_largest_rising_and_the_first_lost_above_it():
    """A lost group below a rising one (c not monotone in sigma~) is not the loss's upper end."""
    s = [0.2, 0.3, 0.5, 0.7, 0.9, 1.2]
    c = [4.0, 2.5, 0.0, 0.8, 0.0, 0.0]
    f = fit_alpha_beta(s, c, [0.1] * 6)
    assert f.bracket == (0.7, 0.9) and f.n_zero == 3
    assert fit_alpha_beta(s[:4], c[:4], [0.1] * 4).bracket[0] == 0.7
    assert math.isnan(fit_alpha_beta(s[:4], c[:4], [0.1] * 4).bracket[1])


def test_floor_without_any_sd_is_the_unweighted_fit():
    s = [0.2, 0.3, 0.5, 0.7, 0.9, 1.2, 1.6]
    c = [4.1, 2.2, 1.1, 0.65, 0.5, 0.0, 0.0]
    floor = fit_alpha_beta(s, c, None, lost="floor")
    own = fit_alpha_beta(s, c, None, lost="own")
    assert not floor.weighted and Note.UNWEIGHTED in floor.notes
    assert (floor.alpha, floor.beta) == pytest.approx((own.alpha, own.beta), rel=1e-9)


def test_one_dof_has_its_chi2_per_dof_and_scales_the_errors():
    s, sd = [0.3, 0.6, 0.9], [0.05, 0.05, 0.05]
    c = [1 / 0.3 - 0.8 + 0.2, 1 / 0.6 - 0.8 - 0.2, 1 / 0.9 - 0.8 + 0.2]
    f = fit_alpha_beta(s, c, sd)
    coef, cov = _wls(s, c, sd)
    chi2 = float(np.sum(((np.array(c) - (coef[0] / np.array(s) - coef[1])) / 0.05) ** 2))
    assert f.dof == 1 and f.chi2_red == pytest.approx(chi2, rel=1e-6) and chi2 > 1
    assert (f.alpha_se, f.beta_se) == pytest.approx(tuple(np.sqrt(np.diag(cov) * chi2)),
                                                    rel=1e-6)


def test_a_rising_point_where_the_line_is_cut_adds_nothing_to_the_errors():
    """The line reaches 0 before the last rising sigma~ (c levels off): there the law's c is
    the cut's 0, whatever alpha and beta, so that point carries no information on them."""
    s = np.array([0.2, 0.3, 0.5, 0.7, 2.0])
    c = np.append(1 / s[:4] - 1.0 + np.array([0.01, -0.01, 0.01, -0.01]), 0.3)
    sd = np.array([0.01, 0.01, 0.01, 0.01, 0.1])
    f = fit_alpha_beta(s, c, sd)
    assert 0.9 < f.sigma_c < 1.1 and f.n_active == 5 and f.residuals[4] == pytest.approx(0.3)
    _, cov = _wls(s[:4], c[:4], sd[:4])          # the Jacobian of the points above the cut
    scale = max(f.chi2_red, 1.0)
    assert (f.alpha_se, f.beta_se) == pytest.approx(tuple(np.sqrt(np.diag(cov) * scale)),
                                                    rel=1e-6)


def test_one_seed_and_one_dof_is_still_unweighted_and_scaled():
    s = [0.3, 0.6, 0.9]
    c = [1 / 0.3 - 0.8 + 0.2, 1 / 0.6 - 0.8 - 0.2, 1 / 0.9 - 0.8 + 0.2]
    f = fit_alpha_beta(s, c)
    coef, cov = _wls(s, c, np.ones(3))
    r2 = float(np.sum((np.array(c) - (coef[0] / np.array(s) - coef[1])) ** 2))
    assert f.dof == 1 and f.notes == [Note.UNWEIGHTED] and f.poor is False
    assert (f.alpha_se, f.beta_se) == pytest.approx(tuple(np.sqrt(np.diag(cov) * r2)), rel=1e-6)


def test_points_that_say_nothing_of_the_slope_give_no_errors():
    """Rising groups all at one sigma~: alpha and beta are not separable, the covariance does
    not exist, and the errors are NaN rather than an exception or a number."""
    for c in ([1.0, 1.2], [1.0, 1.2, 1.1]):
        f = fit_alpha_beta([0.5] * len(c), c, [1.0] * len(c))
        assert f.ok and math.isnan(f.alpha_se) and math.isnan(f.beta_se)
        assert f.dof == len(c) - 2

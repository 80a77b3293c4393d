"""benchmarks/paper_table.py: the paper's Table 1 as transcribed, the secant readings of c, and
alpha, beta and the ratio alpha(k~)/alpha(k~_ref) recovered per reading on synthetic truth."""

import math

import numpy as np
import pytest

from benchmarks import paper_table
from fibril_hpc.campaign.laws import reading
from tests.synthetic_campaigns import FLOOR, law_campaign

PRE = [0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0]


def test_the_transcribed_table_is_consistent_with_its_own_sigma_c():
    rows = paper_table.paper_table()
    assert len(rows) == 9
    for r in rows:          # the paper prints sigma~_c = alpha/beta to 2-3 digits
        assert r["alpha"] / r["beta"] == pytest.approx(r["sigma_c"], rel=0.005)
    stiff = paper_table.paper_row(10.0, rows)
    assert stiff is paper_table.paper_row(0.55, rows) is paper_table.paper_row(1.0, rows)
    assert stiff["alpha"] == 0.11
    assert paper_table.paper_row(0.001, rows)["alpha"] / stiff["alpha"] == pytest.approx(30.18, abs=0.01)
    assert paper_table.paper_row(0.3, rows) is None         # no column between 0.1 and 0.55


def test_the_secant_at_a_fraction_of_the_plateau():
    # a curve with a first-contact jump: 0.2 at 0.001, then rising to 1 by 1
    x = np.array(PRE)
    y = np.array([0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.0])
    lv = reading.levels(np.zeros(7, int), x, x, y)
    r = reading.read_group(np.zeros(7, int), x, x, y, floor=FLOOR)
    assert reading.secant(lv, r.plateau, reading.HALF) == pytest.approx(r.c)
    # 0.9 of the plateau: between 0.25 (0.8) and 1 (1.0), log interpolation half way: F~_P 0.5
    assert reading.secant(lv, 1.0, 0.9) == pytest.approx(0.9 / 0.5)
    assert math.isnan(reading.secant(lv, 1.0, 0.1))          # the first level is already there
    assert math.isnan(reading.secant(lv, 2.0, 0.9))          # never reached


def _campaign(alphas, beta=0.1, shape="sharp", c_sd=0.02):
    pts = {}
    for i, (k, a) in enumerate(alphas.items()):
        groups, _ = law_campaign(a, beta, (0.1, 0.2, 0.4, 0.8), seeds=4, shape=shape,
                                 plateau=1.5, rng=i, c_sd=c_sd)
        pts.update({(k, s): g for s, g in groups.items()})
    return pts


def test_alpha_beta_and_the_ratio_are_recovered_for_every_secant_reading():
    # a sharp rise min(c F~_P, P) has every secant through the origin below the plateau = c
    pts = _campaign({1.0: 0.4, 0.001: 12.0})
    res = paper_table.analyse(pts, FLOOR, n_boot=20)
    assert res["k_ref"] == 1.0
    for name in ("c", "sec70", "sec90"):
        f1, f2 = res["fits"][name][1.0], res["fits"][name][0.001]
        assert f1["alpha"] == pytest.approx(0.4, rel=0.1), name
        assert f2["alpha"] == pytest.approx(12.0, rel=0.1), name
        assert f2["ratio"] == pytest.approx(f2["alpha"] / f1["alpha"])
        assert f2["ratio"] == pytest.approx(30, rel=0.15), name
        lo, hi = f2["ratio_ci"]
        assert lo <= f2["ratio"] <= hi and hi > lo
        assert f1["ratio"] == 1.0
    lines, rows = paper_table.report(res, paper_table.paper_table())
    assert {r["reading"] for r in rows} == set(paper_table.READINGS)
    stiff = [r for r in rows if r["reading"] == "c" and r["k_tilde"] == 0.001][0]
    assert stiff["paper_alpha"] == 3.32 and stiff["paper_ratio"] == pytest.approx(3.32 / 0.11)


def test_a_smooth_rise_orders_the_secants_and_the_ratio_does_not_depend_on_the_fraction():
    # tanh rises: the secant to a higher fraction of the plateau is shallower (absolute alpha
    # depends on the reading), but the same shape at every k~ leaves the ratio alone
    pts = _campaign({1.0: 0.4, 0.01: 1.6}, shape="smooth")
    res = paper_table.analyse(pts, FLOOR, n_boot=10)
    a = {n: res["fits"][n][0.01]["alpha"] for n in ("c", "sec70", "sec90")}
    assert a["c"] > a["sec70"] > a["sec90"]
    ratios = [res["fits"][n][0.01]["ratio"] for n in ("c", "sec70", "sec90")]
    assert max(ratios) / min(ratios) < 1.1

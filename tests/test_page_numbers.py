"""Numbers of the report page that a referee recomputed (session of 2026-11-27): the laws'
median, the finite-size change's precision, the reference brush of a merged file."""

from __future__ import annotations

import math
from types import SimpleNamespace as NS

from fibril_hpc.campaign.analysis import tables


def _lr(rel):
    fit = NS(c=1.0, plateau=1.0, kink=0.1, rms_log=0.1)
    return NS(fit=fit, seed_log_sd=0.1, poor=False, plateau_vs_read=rel)


def test_the_laws_median_of_an_even_count_is_the_mean_of_the_middle_two():
    rels = [-0.29, -0.20, -0.18, -0.16]                 # median -0.19, not the upper -0.18
    d = NS(laws={(1.0, 0.1 * i): {"tanh": _lr(r)} for i, r in enumerate(rels)})
    row = tables.law_comparison(d).page_rows[1]
    assert row[4] == "-19.0 % (-29 … -16 %)"
    d = NS(laws={(1.0, 0.1 * i): {"tanh": _lr(r)} for i, r in enumerate(rels[:3])})
    assert tables.law_comparison(d).page_rows[1][4] == "-20.0 % (-29 … -18 %)"
    d = NS(laws={(1.0, 0.1): {"tanh": _lr(math.nan)}})
    assert tables.law_comparison(d).page_rows[1][4] == "—"


def test_a_size_change_has_three_significant_figures():
    assert [tables.pct(v) for v in (0.0035, -0.0035, 0.123, 1.6785, 14.1869, 456.66, 0.0)] == [
        "+0.35", "-0.35", "+12.3", "+168", "+1419", "+45666", "+0.00"]
    assert tables.pct(0.00001) == "+0.00"
    assert tables.pct(-0.2168) == "-21.7"

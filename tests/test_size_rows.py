"""The finite-size table's verdict (:func:`fibril_hpc.campaign.laws.size.size_rows`): a change is
read against the largest brush only where that brush's plateau is resolved above its loss
threshold; a ratio to a plateau that may be the 3-pillar floor is *not resolved*, never
"within the seed scatter"."""

from __future__ import annotations

import math
from types import SimpleNamespace as NS

import pytest

from fibril_hpc.campaign.laws.size import AT_FLOOR, DIFFERS, REFERENCE, WITHIN, size_rows

NAN = math.nan


def _group(sigma, plateau, ci, state="reached"):
    return NS(sigma_tilde=sigma, n_seeds=4, plateau_ci=ci,
              reading=NS(plateau=plateau, plateau_state=state))


def _study(groups, thr=0.0037):
    return NS(groups=groups, loss=NS(threshold=thr))


def _by_n(ref_ci, small_ci=(0.0118, 0.0633), thr=0.0037):
    return {32: {1.0: _study([_group(0.6, 0.0386, small_ci)], thr)},
            64: {1.0: _study([_group(0.6, 0.0072, ref_ci)], thr)}}


def test_a_reference_at_the_floor_is_not_resolved():
    """The 64 x 64 k~ = 1 file: +438 % [-22, +45 666] % was read 'within the seed scatter'."""
    rows = size_rows(_by_n((0.000138, 0.0151)))
    small, ref = rows
    assert ref.verdict == REFERENCE
    assert small.verdict == AT_FLOOR
    assert small.rel == pytest.approx(0.0386 / 0.0072 - 1)
    assert small.rel_ci == pytest.approx((0.0118 / 0.0151 - 1, 0.0633 / 0.000138 - 1))
    assert small.notes == ["the n_side = 64 plateau's seed interval reaches 3 pillars' pull-off "
                           "(0.0037): the change is not resolved against a plateau that may "
                           "be that floor"]


@pytest.mark.parametrize("ref_ci, small_ci, thr, want", [
    ((0.004, 0.0151), (0.0118, 0.0633), 0.0037, WITHIN),      # above the floor: read as before
    ((0.0037, 0.0151), (0.0118, 0.0633), 0.0037, AT_FLOOR),   # at it (<=)
    ((0.004, 0.0151), (0.0200, 0.0633), 0.0037, DIFFERS),
    ((0.000138, 0.0151), (0.0200, 0.0633), 0.0037, DIFFERS),   # holds more than the floor can
    ((0.000138, 0.0151), (0.0118, 0.0633), NAN, WITHIN),      # no threshold known: as before
])
def test_the_verdict_at_the_floor_s_edge(ref_ci, small_ci, thr, want):
    assert size_rows(_by_n(ref_ci, small_ci, thr))[0].verdict == want


def test_the_threshold_is_the_reference_brush_s():
    """Each brush has its own floor (3 pillars of N): the reference's decides."""
    by_n = _by_n((0.003, 0.0151))
    by_n[32][1.0].loss.threshold = 0.01            # the smaller brush's larger floor is not used
    by_n[64][1.0].loss.threshold = 0.002
    assert size_rows(by_n)[0].verdict == WITHIN
    by_n[64][1.0].loss.threshold = 0.0031
    assert size_rows(by_n)[0].verdict == AT_FLOOR


def test_the_headline_counts_the_rows_not_resolved():
    from fibril_hpc.campaign.analysis import headline as hl

    rows = [NS(n_side=32, rel=4.38, verdict=AT_FLOOR), NS(n_side=32, rel=0.9, verdict=DIFFERS),
            NS(n_side=64, rel=0.0, verdict=REFERENCE)]
    d = NS(n_sides=[32, 64], n_side=64, size=rows, size_loss={}, floor=0.0012)
    assert hl.size_line(d).endswith(
        "n_side = 32: +90.0 … +438 % (within the seed scatter in 0 of 1 (k̃, σ̃); not resolved "
        "in 1: the n_side = 64 plateau may be the 3-pillar floor).")
    d = NS(n_sides=[32, 64], n_side=64, size=rows[:1] + rows[2:], size_loss={}, floor=0.0012)
    assert hl.size_line(d).endswith(
        "n_side = 32: +438 … +438 % (not resolved in 1: the n_side = 64 plateau may be the "
        "3-pillar floor).")


def test_a_merged_file_reads_each_k_against_its_own_largest_size():
    """k~ = 1 ran 8-16 and k~ = 0.01 ran 8-20 (merged files): k~ = 1 is read against 16, not
    reported as having no plateau at 20."""
    by_n = {16: {1.0: _study([_group(0.6, 0.2, (0.15, 0.25))]),
                 0.01: _study([_group(1.0, 0.5, (0.4, 0.6))])},
            20: {0.01: _study([_group(1.0, 0.3, (0.25, 0.35))])},
            8: {1.0: _study([_group(0.6, 0.4, (0.3, 0.5))])}}
    rows = {(r.k_tilde, r.n_side): r for r in size_rows(by_n, 20)}
    assert rows[(1.0, 16)].verdict == REFERENCE and rows[(1.0, 16)].ref_n_side == 16
    assert rows[(1.0, 8)].ref_n_side == 16 and rows[(1.0, 8)].rel == pytest.approx(1.0)
    assert rows[(1.0, 8)].verdict == DIFFERS and not rows[(1.0, 8)].notes
    assert rows[(0.01, 16)].ref_n_side == 20 and rows[(0.01, 20)].verdict == REFERENCE
    assert {r.ref_n_side for r in size_rows(by_n)} == {16, 20}     # no reference given: alike
    assert {r.ref_n_side for r in size_rows(by_n, 16)} == {16}     # one both ran: it is used

    from fibril_hpc.campaign.analysis import headline as hl
    from fibril_hpc.campaign.analysis import tables

    d = NS(n_sides=[8, 16, 20], n_side=20, size=size_rows(by_n, 20), size_loss={}, floor=0.007)
    assert hl.size_line(d).endswith(
        "Plateau against each k̃'s largest n_side (16, 20): n_side = 8: +100 … +100 % (within "
        "the seed scatter in 0 of 1 (k̃, σ̃)); n_side = 16: +66.7 … +66.7 % (within the seed "
        "scatter in 0 of 1 (k̃, σ̃)).")
    t = tables.finite_size(d)
    assert t.page_rows[0][6] == ("change against the largest n_side of each k̃ (16, 20) [range of "
                                 "the seed CIs]")


def test_a_reference_interval_reaching_zero_leaves_the_change_open_above():
    """64 x 64, σ~ = 1 (k~ 0.01): 0.0064 [0, 0.0143]. 16 x 16 holds 0.506 [0.424, 0.629]: more
    than the reference can (+2 865 % at least), not 'no seed interval'; a smaller brush whose
    interval overlaps it is not resolved against that floor."""
    small, _ = size_rows(_by_n((0.0, 0.0143), (0.424, 0.629)))
    assert small.rel_ci[0] == pytest.approx(0.424 / 0.0143 - 1) and small.rel_ci[1] == math.inf
    assert small.verdict == DIFFERS
    small, _ = size_rows(_by_n((0.0, 0.0143), (0.010, 0.05)))
    assert small.rel_ci[1] == math.inf and small.verdict == AT_FLOOR
    small, _ = size_rows(_by_n((0.0, 0.0), (0.010, 0.05)))
    assert math.isnan(small.rel_ci[0]) and small.verdict == "no seed interval"
    from fibril_hpc.campaign.analysis import tables

    d = NS(n_sides=[32, 64], n_side=64, size=size_rows(_by_n((0.0, 0.0143), (0.424, 0.629))),
           size_loss={}, floor=0.0012)
    assert tables.finite_size(d).page_rows[1][6] == "+436 % [+2865, +inf] %"


def test_the_ratio_figure_names_each_k_s_own_reference(monkeypatch):
    """The merged 8-20 file's plateau_vs_n_side.png said 'ratio to n_side = 20' where two k~
    are ratios to 16."""
    from fibril_hpc.campaign.analysis import figures_size

    figs = []
    monkeypatch.setattr(figures_size, "save", lambda fig, out, name: figs.append(fig) or name)
    rows = [NS(k_tilde=k, sigma_tilde=0.5, n_side=n, plateau=p, plateau_ci=(p * 0.9, p * 1.1),
               state="reached", rel=r, rel_ci=(r - 0.1, r + 0.1), ref_n_side=ref)
            for k, n, p, r, ref in ((1.0, 8, 0.6, 0.2, 16), (1.0, 16, 0.5, 0.0, 16),
                                    (0.01, 8, 0.9, 0.5, 20), (0.01, 20, 0.6, 0.0, 20))]
    figures_size.plateau_vs_n_side(NS(size=rows, n_sides=[8, 16, 20]), "unused")
    assert figs[-1].axes[1].get_title().startswith("ratio to each k̃'s largest n_side (16, 20)")
    figures_size.plateau_vs_n_side(NS(size=rows[2:], n_sides=[8, 16, 20]), "unused")
    assert figs[-1].axes[1].get_title().startswith("ratio to n_side = 20 (")

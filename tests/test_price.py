"""The dry-run's price (issue 36, item 8): a term per FFT pair that does not grow with the grid
(it dominates small brushes), and the expected later rounds of an ``F_P: auto`` grid, which the
price of round 0 alone left out. benchmarks/price_check.py compares the prices with measured
runs (benchmarks/NOTES.md)."""

import pytest

from fibril_hpc import Scene
from fibril_hpc.campaign.plan import estimate


def test_a_task_costs_a_fixed_time_per_pair_beside_its_fft_time():
    sc = Scene(n_side=8, preset="fast", F_P=[0.001, 0.004, 0.016, 0.064, 0.25, 1, 4])
    pairs = estimate.task_pairs(sc, 25)
    assert estimate.task_seconds(sc, 0.0, 25) == pytest.approx(pairs * estimate.PAIR_FIXED_S)
    pair_s = 4e-4                                # an 8 x 8 `fast` grid's pair, measured here
    s = estimate.task_seconds(sc, pair_s, 25)
    assert s == pytest.approx(pairs * (estimate.OVERHEAD["fast"] * pair_s + estimate.PAIR_FIXED_S))
    # at 8 x 8 the fixed part is half the cost (FFT time alone was 2-3x low there)
    assert pairs * estimate.PAIR_FIXED_S > 0.4 * s


def test_later_auto_rounds_are_a_loading_path_each_with_one_preload():
    sc = Scene(n_side=8, preset="fast", F_P=[0.001, 0.004, 0.016, 0.064, 0.25, 1, 4])
    later = estimate.later_rounds_seconds(sc, 4e-4, 25)
    one = estimate.task_seconds(sc.replace(F_P=[estimate.AUTO_LATER_F_P]), 4e-4, 25)
    assert later == pytest.approx(estimate.AUTO_LATER_TASKS * one)
    assert 0.3 * estimate.task_seconds(sc, 4e-4, 25) < later < estimate.task_seconds(sc, 4e-4, 25)


def _grid(tmp_path, fp):
    g = tmp_path / "g.yaml"
    g.write_text(f"output: g.h5\nscene: {{n_side: 4, preset: fast}}\nk_tilde: [0.01]\n"
                 f"sigma_tilde: [0.5]\nF_P: {fp}\nseeds: 2\n")
    return str(g)


def test_the_dry_run_prices_the_later_rounds_of_an_auto_grid(tmp_path, capsys):
    from fibril_hpc.campaign.analysis.status import plan
    from fibril_hpc.campaign.plan.spec import load_spec
    from fibril_hpc.cli.campaign import main

    auto = plan(load_spec(_grid(tmp_path, "auto")))
    assert 0.3 * auto.estimate_s < auto.later_s < auto.estimate_s
    assert plan(load_spec(_grid(tmp_path, "[1, 4]"))).later_s == 0.0
    assert main([_grid(tmp_path, "auto"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "for round 0" in out and "with the later F_P auto rounds" in out
    assert main([_grid(tmp_path, "[1, 4]"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "round 0" not in out and "later" not in out

"""``seeds: auto`` on the report's page: a group that ran up to the maximum of seeds short of its
precision target is named with what is short; one meeting the target, or below the maximum, is
not. A grid whose ``seeds`` or ``sigma_tilde`` is a mapping ``{auto: {...}}`` is read by report,
status and export without a crash."""

import csv

import numpy as np
import pytest
import yaml

from fibril_hpc.campaign.analysis.verdict_text import ci_method
from fibril_hpc.campaign.analysis import seed_limits as sl
from fibril_hpc.campaign.analysis.data import CampaignData
from fibril_hpc.campaign.analysis.headline import seeds_line
from fibril_hpc.campaign.analysis.report_data import build

from synthetic_campaigns import FLOOR, Truth, group

AUTO = {"start": 3, "max": 5, "width": 0.2}
PRE = tuple(float(v) for v in np.geomspace(1.5 / 20 / 300, 12 / 20, 14))


def _meta(seeds, sigma=(0.2, 0.4, 0.6)):
    return {"campaign_yaml": yaml.safe_dump({
        "scene": {"n_side": 18, "phi": 0.16, "preset": "fast"}, "k_tilde": [1.0],
        "sigma_tilde": list(sigma) if isinstance(sigma, tuple) else sigma,
        "F_P": PRE, "seeds": seeds})}


def test_seeds_auto_is_read_from_the_grid_and_nothing_else_is():
    assert sl.seeds_auto(_meta({"auto": AUTO})) == AUTO
    from fibril_hpc.campaign.plan.search import AutoSeeds

    assert sl.seeds_auto(_meta({"auto": {"max": 8}})) == dict(AutoSeeds().to_dict(), max=8)
    assert sl.seeds_auto(_meta("auto")) == AutoSeeds().to_dict()     # the planner's defaults
    for seeds in (3, [0, 1, 2], {"auto": "many"}, {"auto": {"max": "x"}}):
        assert sl.seeds_auto(_meta(seeds)) is None
    assert sl.seeds_auto({"campaign_yaml": "{not yaml"}) is None and sl.seeds_auto({}) is None


def _points():
    """(k~, sigma~) -> points: 0.2 at the maximum and wide, 0.4 at the maximum and narrow, 0.6
    wide with fewer seeds than the maximum."""
    wide = Truth("sharp", 20.0, 1.5, c_sd=0.4, P_sd=0.3)
    narrow = Truth("sharp", 20.0, 1.5, c_sd=0.005, P_sd=0.005)
    return {(1.0, 0.2): group(wide, 5, PRE, rng=1), (1.0, 0.4): group(narrow, 5, PRE, rng=2),
            (1.0, 0.6): group(wide, 3, PRE, rng=3)}


def test_a_group_at_the_maximum_short_of_the_target_is_named_and_no_other():
    lim = sl.seed_limits(_points(), FLOOR, AUTO)
    assert [(x.k_tilde, x.sigma_tilde) for x in lim] == [(1.0, 0.2)]
    assert not lim[0].prec.met and "plateau" in lim[0].prec.short
    what = lim[0].what()
    assert what.startswith("stopped at the seeds: auto maximum (5 seeds) short of the target: ")
    assert "(target 20 %)" in what and "of seeds" not in what and " run)" not in what
    # a group holding more seeds than the maximum (a grid whose max was lowered) says both
    more = sl.SeedLimit(1.0, 0.2, 7, 5, lim[0].prec, lim[0].short)
    assert "(7 seeds; the maximum is 5)" in more.what()
    line = seeds_line(AUTO, lim)
    assert line.startswith("seeds: auto (from 3, at most 5 per (k̃, σ̃)")
    assert "1 (k̃, σ̃) stopped at the maximum short of the target" in line
    assert "k̃ = 1, σ̃ = 0.2" in line and "σ̃ = 0.4" not in line and "σ̃ = 0.6" not in line
    # what is short is said once, in the plateau table, not again here
    assert lim[0].short not in line
    assert seeds_line(AUTO, []).endswith("no (k̃, σ̃) stopped at the maximum short of the target.")
    assert sl.seed_limits(_points(), FLOOR, None) == [] and seeds_line(None, []) == ""


def _jobs(points):
    out = []
    for (k, s), (seed, pre, x, y) in points.items():
        for i, (sd, p, fp, fa) in enumerate(zip(seed, pre, x, y)):
            out.append({"key": f"{k}-{s}-{sd}-{i}", "status": "done", "k_tilde": k,
                        "sigma_tilde": s, "seed": int(sd), "preload": float(p),
                        "F_P": float(fp), "F_A": float(fa), "k_machine": float("inf")})
    return out


def test_the_page_says_which_group_hit_the_maximum():
    meta = _meta({"auto": AUTO}, sigma={"auto": {"start": [0.2, 0.6]}})
    d = build(CampaignData(meta, _jobs(_points())), "x.h5", n_boot=40)
    assert d.seeds_auto == AUTO and len(d.seed_limits) == 1
    line = [x for x in d.notes if x.startswith("seeds: auto")]
    assert len(line) == 1 and "k̃ = 1, σ̃ = 0.2" in line[0]
    assert "1 (k̃, σ̃) stopped at the maximum of seeds: auto" in d.headline[-1]
    from fibril_hpc.campaign.analysis import tables

    rows = {r[1]: r for r in tables.plateau(d).page_rows[1:]}
    assert "**stopped at the seeds: auto maximum (5 seeds)" in rows["0.2"][-1]
    assert "stopped at" not in rows["0.4"][-1] and "stopped at" not in rows["0.6"][-1]


@pytest.mark.slow
def test_report_status_and_export_read_a_grid_whose_seeds_and_sigma_are_auto(tmp_path):
    from fibril_hpc.campaign.plan.spec import spec_from_dict
    from fibril_hpc.campaign.storage import store
    from fibril_hpc.cli.campaign import main
    from fibril_hpc.inputs.config import scene_to_yaml

    grid = {"output": "auto.h5", "scene": {"n_side": 18, "preset": "fast"}, "k_tilde": [1],
            "sigma_tilde": [0.2, 0.4], "F_P": list(PRE), "seeds": 5}
    spec = spec_from_dict(grid, base_dir=str(tmp_path))
    pts = _points()
    fa = {(k, s, int(sd), float(p)): float(y) for (k, s), (seed, pre, _, ys) in pts.items()
          for sd, p, y in zip(seed, pre, ys)}
    recs = [{**j.inputs(), "status": "done", "message": "", "F_P": j.preload,
             "F_A": fa[(float(j.k_tilde), float(j.sigma_tilde), j.seed, float(j.preload))],
             "record_id": f"{j.index:032x}", "finished": store.now(), "group_size": len(PRE),
             "wall_s": 0.0, "scene_yaml": scene_to_yaml(spec.job_scene(j))} for j in spec.jobs]
    root = store.root_attrs_for(spec)
    g = yaml.safe_load(root["campaign_yaml"])
    g["seeds"] = {"auto": AUTO}
    g["sigma_tilde"] = {"auto": {"start": [0.2, 0.4]}}
    root["campaign_yaml"] = yaml.safe_dump(g)
    store.write_merged(spec.output, root, recs)
    out = tmp_path / "rep"
    assert main(["report", spec.output, "--out", str(out), "--n-boot", "30"]) == 0
    page = (out / "README.md").read_text()
    assert "seeds: auto (from 3, at most 5" in page and "k̃ = 1, σ̃ = 0.2" in page
    assert main(["status", spec.output]) == 0
    assert main(["export", spec.output, "--csv", str(tmp_path / "o.csv")]) == 0
    rows = list(csv.DictReader((tmp_path / "o.csv").read_text().splitlines()))
    assert len(rows) == len(recs)


def test_paired_resamples_draw_a_seed_once_for_every_group_that_holds_it():
    """A seed is the same brush at every sigma~: one resample is one multiset of labels from
    the union, and every group takes the drawn labels it holds, each as often as drawn (issue
    34: the labels were drawn per set, comonotone, not paired)."""
    from fibril_hpc.campaign.laws.intervals import paired_replicates

    sets = [list(range(10)), [0, 1, 2], [0, 1, 2, 3, 4]]
    seen = []

    def stat(picks):
        seen.append([np.asarray(p) for p in picks])
        return [0.0]

    assert paired_replicates(sets, stat, 2000, 0).shape == (1, 2000)
    redrawn = 0
    for r in seen:
        assert len(r[0]) == 10                      # the union's group: all ten draws
        for g in (1, 2):
            assert set(r[g].tolist()) <= set(sets[g]) and len(r[g]) >= 2
            held = np.isin(r[0], sets[g])
            if held.sum() >= 2:                     # paired: the same labels, as often
                assert sorted(r[g].tolist()) == sorted(r[0][held].tolist())
            else:                                   # redrawn within the group, its own size
                assert len(r[g]) == len(sets[g])
                redrawn += g == 1
    # P(fewer than 2 of 10 draws in a 3-set) = 0.149
    assert 0.11 < redrawn / len(seen) < 0.19
    for g, s in enumerate(sets):
        picks = np.concatenate([r[g] for r in seen])
        counts = np.bincount(picks, minlength=len(s))[:len(s)]
        assert np.all(np.abs(counts / counts.sum() - 1 / len(s)) < 0.02)   # uniform
        # the mean size is the group's own: E[1/size] close to 1/n
        assert np.mean([1 / len(r[g]) for r in seen]) == pytest.approx(1 / len(s), rel=0.15)
    assert paired_replicates([[0], [1]], stat, 10) is None
    # a group of one seed always takes it
    one = []
    paired_replicates([[0, 1, 2], [2]], lambda p: one.append(p[1].tolist()) or [0.0], 50)
    assert all(set(x) == {2} for x in one)


def test_paired_resamples_keep_the_correlation_of_groups_sharing_seeds():
    """issue 34: a 10-seed and a 3-seed group with the same per-seed values: resampled means
    correlated at 0.115 (comonotone labels); paired, they share the 3 seeds' draws (the design's
    correlation, sqrt(3/10) = 0.55, is the ceiling). Disjoint seed sets stay independent."""
    from fibril_hpc.campaign.laws.intervals import paired_replicates

    rng = np.random.default_rng(0)
    rho, rho_disjoint = [], []
    for t in range(10):
        v = rng.standard_normal(20)

        def stat(p, v=v):
            return [v[p[0]].mean(), v[p[1]].mean()]

        r = paired_replicates([range(10), range(3)], stat, 1000, t)
        rho.append(np.corrcoef(r)[0, 1])
        r = paired_replicates([range(10), range(10, 13)], stat, 1000, t)
        rho_disjoint.append(np.corrcoef(r)[0, 1])
    assert 0.25 < np.mean(rho) < 0.55, np.mean(rho)
    assert abs(np.mean(rho_disjoint)) < 0.05


def test_a_group_with_fewer_seeds_gets_an_interval_of_its_own_seeds_width():
    """seeds: auto leaves groups with 3 and 10 seeds under one k~: the report resamples seed
    labels paired across them (the sizes are checked by the test above), and the 3-seed group's
    plateau interval is close to the one the planner judged, a bootstrap of its 3 seeds alone."""
    from fibril_hpc.campaign.laws.precision import group_precision
    from fibril_hpc.campaign.laws.study import study_k

    t = Truth("sharp", 20.0, 1.5, c_sd=0.1, P_sd=0.1)
    pts = {0.2: group(t, 10, PRE, rng=5), 0.4: group(t, 3, PRE, rng=6)}
    st = study_k(1.0, pts, n_boot=400, floor=FLOOR)
    few = st.groups[1]
    assert few.n_seeds == 3 and "paired across sigma~" in ci_method(st)
    lo, hi = few.plateau_ci
    own = group_precision(*pts[0.4], floor=FLOOR, width=0.2, n_boot=400)
    w, w_own = hi - lo, own.plateau_ci[1] - own.plateau_ci[0]
    assert 0.7 < w / w_own < 1.4, (few.plateau_ci, own.plateau_ci)
